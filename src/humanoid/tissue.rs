//! Effective floor-contact stiffness and damping of the body's regions: each fall21 link meets
//! the floor through a lumped spring–damper `f = k δ + c δ̇` (δ the compression), the model in
//! which impact biomechanics reports body-region stiffness. The values are not proportional to
//! link mass: a region's stiffness is what its tissue and bone give, whatever it weighs.
//!
//! Sources and values (whole region, one box face flat on the floor):
//! - **pelvis**: `k = 40 kN/m`, inside the range measured for the pelvis and trochanteric soft
//!   tissue in pelvis-release experiments on young adults: Robinovitch, Hayes & McMahon (1991),
//!   *Prediction of femoral impact forces in falls on the hip*, J. Biomech. Eng. 113:366–374;
//!   Choi, Park & Choi (2023), *Effects of hip joint kinematics on the effective pelvis stiffness
//!   and hip impact force during simulated sideways falls*, J. Biomech. 162:111885 (secant
//!   stiffness 24.6–35.6 kN/m by hip rotation); together roughly 25–70 kN/m.
//! - **torso**: `k = 26.3 kN/m`, `c = 520 N·s/m`, the thorax of Lobdell et al. (1973), *Impact
//!   response of the human thorax*, in Human Impact Response, Plenum, pp. 201–245 (the spring and
//!   damper in series with the sternal mass in their chest model).
//! - **head**: `k = 100 kN/m`: scalp over skull, stiffer than the trunk. No whole-head floor
//!   impact stiffness was found in the sources above; this value is this project's modelling
//!   choice (it gives a head peak force of a few kN at 3–4 m/s), not a measurement.
//! - **limbs** (upper arm, forearm, hand, thigh, shank): `k = 20 kN/m`, the soft-tissue order of
//!   the values above (muscle and fat over bone, softer than the pelvis's trochanteric padding
//!   with the pelvis ring behind it); a modelling choice by analogy, not a per-limb measurement.
//! - **feet**: `k = 100 kN/m`: the heel pad under a standing body; a modelling choice that keeps
//!   the standing sink to a few millimetres.
//!
//! Damping: besides Lobdell's thorax, no damping coefficient measured with the same protocol was
//! found for the other regions, so these are modelling choices. The pelvis's `c = 1.3 kN·s/m`
//! gives, about an effective mass of half the body (32 kg), a damping ratio of about 0.5, a
//! restitution of about 0.15: falls onto the hip rebound little (the unevolved elderly fall's
//! pelvis lifts off by 3.7 cm after touchdown), while 800 N·s/m (ζ ≈ 0.3) let it bounce 7 cm. Head, limbs and
//! feet have damping ratios of 0.3–0.8 about their own masses; light links (hand, foot) cannot
//! take more without an explicit-damping step bound below 0.5 ms.
//!
//! Penetration bound: a lumped spring develops its force by its compression, `δ = F/k` for a
//! face landing flat (four corners), twice that on an edge, so the depth is bounded by the
//! force. For the pelvis the published hip forces of standing-height falls, 2.6–5.6 kN, mean
//! 6.5–14 cm on 40 kN/m; equivalently a spring stops an effective mass `m` arriving at `v`
//! within `δ = v √(m/k)` (less with damping): 32 kg at 2–4 m/s gives 6–11 cm. Up to 14 cm at
//! the pelvis is therefore what the published stiffness implies at published forces: the depth
//! is the deflection of the whole-region spring (soft tissue, the pelvis ring and the body
//! behind them, which is what an effective stiffness lumps), part of the model and not an
//! overlap to be removed; a deeper pelvis would mean a force above the published range. The
//! contact boxes are the body's outline, so the depth is measured into that outline. The
//! unevolved elderly fall reaches 6.1 cm at the pelvis and 7.7 cm at the torso (tested under
//! 9 cm; random controller genes under 12 cm). Every fall reports the deepest penetration per
//! link.

use crate::dynamics::forces::contact::ContactGains;

/// One body region's effective contact stiffness `k` (N/m) and damping `c` (N·s/m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Region name (`pelvis`, `torso`, `head`, `limb`, `foot`).
    pub name: &'static str,
    /// Effective stiffness (N/m).
    pub stiffness_n_per_m: f64,
    /// Effective damping (N·s/m).
    pub damping_n_s_per_m: f64,
}

/// The pelvis (Robinovitch et al. 1991; Choi et al. 2023).
pub const PELVIS: Region = Region {
    name: "pelvis",
    stiffness_n_per_m: 40.0e3,
    damping_n_s_per_m: 1300.0,
};
/// The thorax (Lobdell et al. 1973).
pub const TORSO: Region = Region {
    name: "torso",
    stiffness_n_per_m: 26.3e3,
    damping_n_s_per_m: 520.0,
};
/// The head (modelling choice, see the module docs).
pub const HEAD: Region = Region {
    name: "head",
    stiffness_n_per_m: 100.0e3,
    damping_n_s_per_m: 450.0,
};
/// Upper arm, forearm, hand, thigh, shank (soft tissue over bone; modelling choice).
pub const LIMB: Region = Region {
    name: "limb",
    stiffness_n_per_m: 20.0e3,
    damping_n_s_per_m: 40.0,
};
/// The foot (heel pad; modelling choice).
pub const FOOT: Region = Region {
    name: "foot",
    stiffness_n_per_m: 100.0e3,
    damping_n_s_per_m: 150.0,
};

/// The region a fall21 link belongs to (`left_`/`right_` stripped); `None` for a name that is
/// not a fall21 link.
pub fn region(link: &str) -> Option<Region> {
    let l = link
        .strip_prefix("left_")
        .or_else(|| link.strip_prefix("right_"))
        .unwrap_or(link);
    Some(match l {
        "pelvis" => PELVIS,
        "torso" | "chest" | "clavicle" => TORSO,
        "head" => HEAD,
        "upper_arm" | "forearm" | "hand" | "thigh" | "shin" => LIMB,
        "foot" => FOOT,
        _ => return None,
    })
}

impl Region {
    /// The region as contact gains.
    pub fn gains(&self) -> ContactGains {
        ContactGains {
            stiffness_n_per_m: self.stiffness_n_per_m,
            damping_n_s_per_m: self.damping_n_s_per_m,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_fall21_link_has_a_region_and_the_pelvis_is_in_the_published_range() {
        for j in &crate::humanoid::fall21().joints {
            assert!(region(&j.link).is_some(), "{}", j.link);
        }
        let k = region("pelvis").unwrap().stiffness_n_per_m;
        assert!((25e3..=70e3).contains(&k));
        assert!(region("wing").is_none());
        // Not proportional to mass: the thigh (≈ 9 kg) and the hand (≈ 0.4 kg) share one value.
        assert_eq!(region("left_thigh"), region("right_hand"));
    }
}
