//! Strength: the maximal voluntary joint torque per DOF (fall21's and humanoid24's) and age group, the bound on what
//! PD control can ask of a joint (the dynamics clamps the PD torque to it, see
//! [`crate::dynamics::forces::pd`]; a genetic algorithm reads it to bound its gains).
//!
//! Source: **Harbo, Brincks & Andersen (2012)**, *Maximal isokinetic and isometric muscle
//! strength of major muscle groups related to age, body mass, height, and sex in 178 healthy
//! subjects*, Eur. J. Appl. Physiol. 112:267–275 (isometric maxima of the shoulder, elbow, wrist,
//! hip, knee and ankle flexors and extensors, ages 15–83). The values below are rounded
//! representative isometric maxima of men of about 70–75 kg: `Adult` for ages 20–40, `Elderly`
//! for ages 60–80, where the lower-limb extensors have lost the most (about 35–40 %), the upper
//! limb less (about 25 %). They were transcribed as orders of magnitude, not row by row from the
//! paper's regression tables: check them against it before relying on a single value. The knee
//! row was checked against the meta-analysis of Šarabon, Kozinc & Perman (2021), *Establishing
//! reference values for isometric knee extension and flexion strength*, Front. Physiol.
//! 12:767941 (411 studies): at mid-range knee angles its pooled 95 % intervals for men are
//! 2.92–3.45 N·m/kg (extension) and 1.15–1.62 N·m/kg (flexion) in adults, 1.74–2.16 and
//! 0.69–0.89 N·m/kg in older adults, i.e. 210–248, 83–117, 125–156 and 50–64 N·m at 72 kg: the
//! extension values below lie inside, adult flexion (120) just above and elderly flexion (75)
//! above its interval (see the unit test). Trunk and
//! neck are not in that study; their values (trunk flexion/extension about 150/200 N·m, neck
//! 25/40 N·m in young men) are this project's rounded reading of the dynamometry literature, with
//! the same age decline. The DOFs only humanoid24 has (waist lateral bend, the clavicle's
//! elevation and protraction, shoulder abduction and rotation about the long axis, forearm
//! pronation, hip rotation) are likewise the project's rounded reading of that literature (adult
//! young men; elderly about 30 % less), orders of magnitude to bound a PD controller, not data.
//!
//! Signs follow the DOFs' anatomical convention (positive = flexion, abduction, external
//! rotation, dorsiflexion, lateral bend to the right, turn to the left): a DOF's range is
//! `(−τ_negative, τ_positive)`, e.g. the knee `(−extension, +flexion)`.

use crate::humanoid::ranges::AgeGroup;

/// Maximal torques of one DOF (N·m, both ≥ 0): in its negative and positive directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strength {
    /// Side-less DOF name (`knee`, `hip_flexion`, …).
    pub dof: &'static str,
    /// Largest torque in the negative direction (N·m), young adults.
    pub adult_negative: f64,
    /// Largest torque in the positive direction (N·m), young adults.
    pub adult_positive: f64,
    /// Largest torque in the negative direction (N·m), older adults.
    pub elderly_negative: f64,
    /// Largest torque in the positive direction (N·m), older adults.
    pub elderly_positive: f64,
}

const fn s(dof: &'static str, an: f64, ap: f64, en: f64, ep: f64) -> Strength {
    Strength {
        dof,
        adult_negative: an,
        adult_positive: ap,
        elderly_negative: en,
        elderly_positive: ep,
    }
}

/// The table: per side-less fall21 DOF, (adult −, adult +, elderly −, elderly +) in N·m.
pub const TABLE: [Strength; 20] = [
    s("waist_flexion", 200.0, 150.0, 130.0, 100.0), // extension / flexion
    s("waist_rotation", 60.0, 60.0, 40.0, 40.0),
    s("neck_flexion", 40.0, 25.0, 28.0, 18.0), // extension / flexion
    s("neck_lateral", 30.0, 30.0, 20.0, 20.0),
    s("neck_rotation", 15.0, 15.0, 10.0, 10.0),
    s("shoulder_flexion", 70.0, 60.0, 52.0, 45.0), // extension / flexion
    s("shoulder_rotation", 35.0, 35.0, 26.0, 26.0),
    s("elbow", 50.0, 70.0, 38.0, 52.0), // extension / flexion
    s("wrist", 12.0, 12.0, 9.0, 9.0),
    s("hip_flexion", 200.0, 150.0, 130.0, 100.0), // extension / flexion
    s("hip_abduction", 110.0, 120.0, 75.0, 80.0), // adduction / abduction
    s("knee", 240.0, 120.0, 150.0, 75.0),         // extension / flexion
    s("ankle", 150.0, 40.0, 95.0, 28.0),          // plantar flexion / dorsiflexion
    // humanoid24 only
    s("waist_lateral", 120.0, 120.0, 80.0, 80.0),
    s("clavicle_elevation", 60.0, 60.0, 42.0, 42.0), // depression / elevation
    s("clavicle_protraction", 50.0, 50.0, 35.0, 35.0), // retraction / protraction
    s("shoulder_abduction", 70.0, 55.0, 52.0, 41.0), // adduction / abduction
    s("elbow_flexion", 50.0, 70.0, 38.0, 52.0),      // extension / flexion (fall21's elbow)
    s("elbow_pronation", 8.0, 8.0, 6.0, 6.0),        // supination / pronation
    s("hip_rotation", 50.0, 50.0, 33.0, 33.0),       // internal / external
];

/// The strength row of a fall21 DOF (full or side-less name).
pub fn strength(dof: &str) -> Option<&'static Strength> {
    let d = dof
        .strip_prefix("left_")
        .or_else(|| dof.strip_prefix("right_"))
        .unwrap_or(dof);
    TABLE.iter().find(|r| r.dof == d)
}

/// A DOF of a model without a row in [`TABLE`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("DOF '{0}' has no strength row (see humanoid::strength::TABLE)")]
pub struct NoStrength(pub String);

/// The torque range `(τ_min, τ_max)` (N·m) of every DOF of `model` in model order for `group`.
pub fn torque_limits_for(
    model: &crate::humanoid::Model,
    group: AgeGroup,
) -> Result<Vec<(f64, f64)>, NoStrength> {
    model
        .dofs
        .iter()
        .map(|d| {
            let r = strength(&d.name).ok_or_else(|| NoStrength(d.name.clone()))?;
            Ok(match group {
                AgeGroup::Adult => (-r.adult_negative, r.adult_positive),
                AgeGroup::Elderly => (-r.elderly_negative, r.elderly_positive),
            })
        })
        .collect()
}

/// The torque range `(τ_min, τ_max)` (N·m) of every fall21 DOF in model order for `group`.
pub fn torque_limits(group: AgeGroup) -> Vec<(f64, f64)> {
    crate::humanoid::fall21()
        .dof_names()
        .iter()
        .map(|n| {
            let r = strength(n).unwrap_or_else(|| unreachable!("fall21 DOF {n} has a row"));
            match group {
                AgeGroup::Adult => (-r.adult_negative, r.adult_positive),
                AgeGroup::Elderly => (-r.elderly_negative, r.elderly_positive),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_dof_has_a_limit_and_older_adults_are_weaker() {
        let a = torque_limits(AgeGroup::Adult);
        let e = torque_limits(AgeGroup::Elderly);
        assert_eq!(a.len(), 21);
        for (x, y) in a.iter().zip(&e) {
            assert!(x.0 < 0.0 && x.1 > 0.0);
            assert!(y.0 > x.0 && y.1 < x.1);
        }
        // Knee extension (negative) is the strongest lower-limb action.
        let k = crate::humanoid::fall21().dof_index("left_knee").unwrap();
        assert_eq!(a[k], (-240.0, 120.0));
    }

    /// The knee row against Šarabon, Kozinc & Perman (2021) at 72 kg (module docs): extension
    /// inside the pooled 95 % intervals; flexion, which the table puts higher, within 20 % of
    /// the intervals' upper ends.
    #[test]
    fn the_knee_row_agrees_with_the_meta_analysis() {
        let knee = strength("left_knee").unwrap();
        let at = |lo: f64, hi: f64| (lo * 72.0, hi * 72.0);
        let inside = |v: f64, (lo, hi): (f64, f64)| (lo..=hi).contains(&v);
        assert!(inside(knee.adult_negative, at(2.92, 3.45)), "{knee:?}");
        assert!(inside(knee.elderly_negative, at(1.74, 2.16)), "{knee:?}");
        assert!(knee.adult_positive <= 1.2 * at(1.15, 1.62).1, "{knee:?}");
        assert!(knee.elderly_positive <= 1.2 * at(0.69, 0.89).1, "{knee:?}");
    }

    #[test]
    fn every_humanoid24_dof_has_a_limit_and_fall21_keeps_its_own() {
        let m = crate::humanoid::humanoid24();
        let a = torque_limits_for(&m, AgeGroup::Adult).unwrap();
        let e = torque_limits_for(&m, AgeGroup::Elderly).unwrap();
        assert_eq!(a.len(), 24);
        for (x, y) in a.iter().zip(&e) {
            assert!(x.0 < 0.0 && x.1 > 0.0 && y.0 > x.0 && y.1 < x.1);
        }
        let f = crate::humanoid::fall21();
        assert_eq!(
            torque_limits_for(&f, AgeGroup::Elderly).unwrap(),
            torque_limits(AgeGroup::Elderly)
        );
        let mut bad = m.clone();
        bad.dofs[0].name = "tail".into();
        assert!(torque_limits_for(&bad, AgeGroup::Adult).is_err());
    }
}
