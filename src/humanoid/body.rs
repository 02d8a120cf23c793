use std::sync::{Arc, Mutex, Weak};

use crate::dynamics::JointType;
use crate::dynamics::forces::contact::LinkBox;
use crate::dynamics::{Body, Model, ModelError};
use crate::dynamics::{Inertia, SpatialTransform};
use crate::humanoid::anthropometry::*;
use crate::humanoid::{self, Figure, FigureJoint, JointKind};
use glam::{DMat3, DVec3};

/// A human ready to simulate.
///
/// A humanoid model as an articulated body: the joint tree, DOF names, axes and offsets of a
/// [`Figure`] ([`crate::humanoid::fall21`], [`crate::humanoid::humanoid24`], or any model
/// with the same link names), scaled to the subject's height, with segment masses, centres of
/// mass and inertias from **de Leva (1996)**, *Adjustments to Zatsiorsky–Seluyanov's segment
/// inertia parameters*, J. Biomech. 29(9):1223–1230, Table 4 (males: stature 1741 mm, 73.0 kg),
/// scaled to the subject's mass `M` (`m_i = μ_i M`). Segment lengths `ℓ_i` come from the figure's
/// own joint positions (the waist → hip line for the lower trunk, neck → waist for the upper and
/// middle trunk in de Leva's proportions, joint to joint along the limbs, the head's end site for
/// head + neck), so neighbouring segments meet at their joints and never overlap; only hand and
/// foot, whose end points are not joints, keep de Leva's lengths scaled by `H / 1.741`. Centres
/// of mass sit at the table's fraction of `ℓ_i`, inertias are `I = m (r ℓ)²` with the table's radii
/// of gyration about the sagittal, transverse and longitudinal axes (see `segment` for how
/// they map onto link axes).
///
/// Links by name (a `left_`/`right_` prefix is ignored): `pelvis` (de Leva's lower trunk),
/// `torso` or `chest` (upper + middle trunk), `head` (head + neck), `clavicle` (the shoulder
/// girdle, which de Leva counts in the upper trunk: see [`CLAVICLE_SHARE`]), and per side
/// `upper_arm`, `forearm`, `hand`, `thigh`, `shin`, `foot`. Joint types follow the model's
/// joints: free (the pelvis), ball, universal, pin, and fixed (humanoid24's neck, wrists and
/// ankles: the link is welded to its parent). Each link also carries a box for floor contact
/// (SPEC §3: "a box on each link").
///
/// fall21 (15 links, 21 DOF) is the falling paper's body ([`fall21_body`]); humanoid24 (17
/// links, 24 DOF, the motor-primitive model) gets a body the same way ([`humanoid24_body`]).
#[derive(Clone, Debug)]
pub struct HumanBody {
    /// The articulated body (bodies = the figure's joints/links in the same order; body 0 =
    /// pelvis), shared with the physics components that step it
    /// ([`crate::ecs::physics::PhysicsBody`]).
    pub model: Arc<Model>,
    /// The figure model it was built from, scaled to the subject's height.
    pub figure: Figure,
    /// Contact box of each link.
    pub boxes: Vec<LinkBox>,
    /// For each figure DOF (model order), its index in the velocity vector `v` (shared with the
    /// physics components as their actuated DOFs).
    pub dof_v: Arc<[usize]>,
    /// Link names in body order.
    pub link_names: Vec<String>,
}

/// Errors building the human body.
#[derive(Debug, thiserror::Error)]
pub enum HumanError {
    /// Height or mass out of a plausible human range.
    #[error("subject {what} = {value} is outside the supported range {lo}..{hi}")]
    Subject {
        /// "height_m" or "mass_kg".
        what: &'static str,
        /// Value given.
        value: f64,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
    /// The figure model has a link this body has no anthropometric row for.
    #[error(
        "link '{0}' has no anthropometric data (expected pelvis, torso, chest, head, clavicle, \
         upper_arm, forearm, hand, thigh, shin or foot)"
    )]
    UnknownLink(String),
    /// The figure model is not a floating-base tree rooted at the pelvis.
    #[error("the figure's root joint '{0}' must be a free joint (the pelvis as floating base)")]
    Root(String),
    /// The assembled tree is invalid.
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// Inertia of a straight segment of length `len` (m) along `dir` (unit, from its proximal end
/// point `p0`) from a table row: mass `μ M`, centre of mass at the row's fraction of `len`, and
/// principal moments `m (r ℓ)²` with de Leva's radii of gyration assigned by his definitions:
/// the *sagittal* radius is about the sagittal (antero-posterior) axis, the *transverse* radius
/// about the transverse (medio-lateral) axis and the *longitudinal* radius about the segment's
/// long axis. In link axes (X left, Y up, Z forward) a vertical segment gets `X ← r_transverse`,
/// `Y ← r_longitudinal`, `Z ← r_sagittal`; the foot (long axis Z) gets `X ← r_transverse`,
/// `Y ← r_sagittal`, `Z ← r_longitudinal`. The shapes agree: the trunk is wider than deep, so its
/// sagittal radius (50.5 % for the upper trunk) exceeds its transverse one (32.0 %); the head is
/// deeper than wide and the order flips (37.6 % > 36.2 %).
fn segment(
    row: &SegmentRow,
    mass: f64,
    len: f64,
    p0: DVec3,
    dir: DVec3,
    long_axis: usize,
) -> Inertia {
    let m = row.mass_pct / 100.0 * mass;
    let com = p0 + dir * (row.com_pct / 100.0 * len);
    let i = |r_pct: f64| m * (r_pct / 100.0 * len).powi(2);
    let d = if long_axis == 1 {
        DVec3::new(
            i(row.r_transverse_pct),
            i(row.r_longitudinal_pct),
            i(row.r_sagittal_pct),
        )
    } else {
        DVec3::new(
            i(row.r_transverse_pct),
            i(row.r_sagittal_pct),
            i(row.r_longitudinal_pct),
        )
    };
    Inertia::new(m, com, DMat3::from_diagonal(d))
}

/// de Leva's length of `row` for a subject of height `h` (m).
fn table_length(row: &SegmentRow, h: f64) -> f64 {
    row.length_mm / 1000.0 * h / DE_LEVA_STATURE
}

/// Sum of rigid inertias expressed in one frame (parallel-axis theorem).
fn combine(a: Inertia, b: Inertia) -> Inertia {
    let m = a.mass + b.mass;
    let c = (a.com * a.mass + b.com * b.mass) / m;
    let shift = |x: &Inertia| {
        let d = x.com - c;
        x.inertia_com
            + (DMat3::IDENTITY * d.length_squared() - crate::dynamics::outer(d, d)) * x.mass
    };
    Inertia::new(m, c, shift(&a) + shift(&b))
}

/// Share of de Leva's upper trunk carried by each clavicle link (the shoulder girdle: clavicle,
/// scapula and the muscles between them and the trunk), 5 %: a modelling choice, since de Leva's
/// table has no girdle segment. The chest keeps the rest, so the masses still sum to `M`.
pub const CLAVICLE_SHARE: f64 = 0.05;

/// Inertia of a slender cylinder of mass `m` (kg), length `len` (m) and radius `r` (m) from `p0`
/// along the unit `dir`: `I = m(ℓ²/12 + r²/4)(1 − d dᵀ) + (m r²/2) d dᵀ` about its centre.
fn rod(m: f64, len: f64, r: f64, p0: DVec3, dir: DVec3) -> Inertia {
    let dd = crate::dynamics::outer(dir, dir);
    let perp = m * (len * len / 12.0 + r * r / 4.0);
    let axial = 0.5 * m * r * r;
    Inertia::new(
        m,
        p0 + dir * (0.5 * len),
        (DMat3::IDENTITY - dd) * perp + dd * axial,
    )
}

/// Builds the fall21 human of standing height `height` (m) and mass `mass` (kg) under gravity
/// `(0, −g, 0)`.
pub fn fall21_body(height: f64, mass: f64, g: f64) -> Result<HumanBody, HumanError> {
    human_body(&humanoid::fall21(), height, mass, g)
}

/// The fall21 human of [`fall21_body`], shared: while any holder keeps it, every call with the
/// same `height` (m), `mass` (kg) and `g` returns that same body (equal parameters build equal
/// bodies), so characters built one by one share one body and its model, as the engine's step
/// needs to take their articulated-body algorithms together in vector lanes
/// ([`crate::ecs::physics::step_bodies`]).
pub fn shared_fall21_body(height: f64, mass: f64, g: f64) -> Result<Arc<HumanBody>, HumanError> {
    type Key = (u64, u64, u64);
    static SHARED: Mutex<Vec<(Key, Weak<HumanBody>)>> = Mutex::new(Vec::new());
    let key = (height.to_bits(), mass.to_bits(), g.to_bits());
    let mut shared = SHARED.lock().unwrap_or_else(|e| e.into_inner());
    shared.retain(|(_, w)| w.strong_count() > 0);
    if let Some(body) = shared
        .iter()
        .find(|(k, _)| *k == key)
        .and_then(|(_, w)| w.upgrade())
    {
        return Ok(body);
    }
    let body = Arc::new(fall21_body(height, mass, g)?);
    shared.push((key, Arc::downgrade(&body)));
    Ok(body)
}

/// Builds the humanoid24 human (the motor-primitive model) of standing height `height` (m) and
/// mass `mass` (kg) under gravity `(0, −g, 0)`.
pub fn humanoid24_body(height: f64, mass: f64, g: f64) -> Result<HumanBody, HumanError> {
    human_body(&humanoid::humanoid24(), height, mass, g)
}

/// Builds the articulated body of `model` (a figure whose root is a free pelvis and whose links
/// are named as in [`HumanBody`]'s doc) for a subject of standing height `height` (m) and mass `mass`
/// (kg) under gravity `(0, −g, 0)`.
pub fn human_body(model: &Figure, height: f64, mass: f64, g: f64) -> Result<HumanBody, HumanError> {
    check_subject(model, height, mass)?;
    let fig = model.scaled_to_height(height);
    // The girdle's mass comes out of the upper trunk (see [`CLAVICLE_SHARE`]).
    let clavicles = fig
        .joints
        .iter()
        .filter(|j| j.link.ends_with("clavicle"))
        .count() as f64;
    let subject = Subject {
        h: height,
        mass,
        clavicles,
    };
    let mut bodies = Vec::with_capacity(fig.joints.len());
    let mut boxes = Vec::with_capacity(fig.joints.len());
    for j in &fig.joints {
        let (inertia, bx) = link_inertia(&fig, j, &subject)?;
        let x_tree = if j.parent.is_some() {
            SpatialTransform::translation(j.offset)
        } else {
            SpatialTransform::IDENTITY
        };
        bodies.push(Body {
            name: j.link.clone(),
            joint_name: j.name.clone(),
            parent: j.parent,
            joint: joint_type(&fig, j),
            x_tree,
            inertia,
        });
        boxes.push(bx);
    }
    let model = Model::new(bodies, DVec3::new(0.0, -g, 0.0))?;
    let dof_v = dof_velocity_indices(&fig, &model).into();
    let link_names = fig.joints.iter().map(|j| j.link.clone()).collect();
    Ok(HumanBody {
        model: Arc::new(model),
        figure: fig,
        boxes,
        dof_v,
        link_names,
    })
}

/// The subject's height (m) and mass (kg) within the ranges the tables cover, and a figure
/// whose root is free.
fn check_subject(model: &Figure, height: f64, mass: f64) -> Result<(), HumanError> {
    if !(1.0..=2.3).contains(&height) {
        return Err(HumanError::Subject {
            what: "height_m",
            value: height,
            lo: 1.0,
            hi: 2.3,
        });
    }
    if !(20.0..=200.0).contains(&mass) {
        return Err(HumanError::Subject {
            what: "mass_kg",
            value: mass,
            lo: 20.0,
            hi: 200.0,
        });
    }
    if let Some(root) = model.joints.first()
        && root.kind != JointKind::Free
    {
        return Err(HumanError::Root(root.name.clone()));
    }
    Ok(())
}

/// What the segments' inertias are scaled to: standing height `h` (m), mass (kg) and the
/// number of clavicles (whose mass comes out of the upper trunk).
struct Subject {
    h: f64,
    mass: f64,
    clavicles: f64,
}

/// The offset of the child of joint `j` whose joint name ends with `name`.
fn child_offset(fig: &Figure, j: &FigureJoint, name: &str) -> Option<DVec3> {
    fig.joints
        .iter()
        .find(|c| c.parent.is_some_and(|p| fig.joints[p].name == j.name) && c.name.ends_with(name))
        .map(|c| c.offset)
}

/// The inertia (de Leva's segment tables) and contact box of the link of joint `j`, by body
/// part (the link name without its side).
fn link_inertia(
    fig: &Figure,
    j: &FigureJoint,
    subject: &Subject,
) -> Result<(Inertia, LinkBox), HumanError> {
    let link = j
        .link
        .trim_start_matches("left_")
        .trim_start_matches("right_");
    Ok(match link {
        "pelvis" => pelvis_link(fig, j, subject),
        "torso" | "chest" => trunk_link(fig, j, subject),
        "head" => head_link(j, subject),
        "clavicle" => clavicle_link(fig, j, subject),
        "upper_arm" | "forearm" | "thigh" | "shin" => limb_link(fig, j, link, subject),
        "hand" => hand_link(j, subject),
        "foot" => foot_link(j, subject),
        _ => return Err(HumanError::UnknownLink(j.link.clone())),
    })
}

/// De Leva's lower trunk runs from the omphalion down to the hip-joint centres: here from the
/// waist joint down to the hip line (the pelvis origin), so that pelvis and torso meet at the
/// waist without overlapping.
fn pelvis_link(
    fig: &Figure,
    j: &FigureJoint,
    &Subject { h, mass, .. }: &Subject,
) -> (Inertia, LinkBox) {
    let top = child_offset(fig, j, "waist").unwrap_or(DVec3::new(0.0, 0.07 * h, 0.0));
    (
        segment(&DE_LEVA_LOWER_TRUNK, mass, top.y, top, DOWN, 1),
        LinkBox {
            center: DVec3::new(0.0, 0.02 * h, 0.0),
            half: DVec3::new(0.095, 0.05, 0.06) * h,
        },
    )
}

/// Upper trunk (cervicale → xiphion) over middle trunk (xiphion → omphalion), filling the
/// waist → neck span in de Leva's proportions.
fn trunk_link(
    fig: &Figure,
    j: &FigureJoint,
    &Subject { h, mass, clavicles }: &Subject,
) -> (Inertia, LinkBox) {
    let neck = child_offset(fig, j, "neck").unwrap_or(DVec3::new(0.0, 0.23 * h, 0.0));
    let (lu, lm) = (
        table_length(&DE_LEVA_UPPER_TRUNK, h),
        table_length(&DE_LEVA_MIDDLE_TRUNK, h),
    );
    let scale = neck.y / (lu + lm);
    let mut upt = segment(&DE_LEVA_UPPER_TRUNK, mass, lu * scale, neck, DOWN, 1);
    if clavicles > 0.0 {
        let keep = 1.0 - CLAVICLE_SHARE * clavicles;
        upt = Inertia::new(upt.mass * keep, upt.com, upt.inertia_com * keep);
    }
    let mpt = segment(
        &DE_LEVA_MIDDLE_TRUNK,
        mass,
        lm * scale,
        neck + DOWN * (lu * scale),
        DOWN,
        1,
    );
    (
        combine(upt, mpt),
        LinkBox {
            center: neck * 0.5,
            half: DVec3::new(0.10 * h, neck.y * 0.5, 0.06 * h),
        },
    )
}

/// Head + neck from the vertex (the head's end site) down to the neck joint.
fn head_link(j: &FigureJoint, &Subject { h, mass, .. }: &Subject) -> (Inertia, LinkBox) {
    let top = j
        .end_site
        .unwrap_or(DVec3::new(0.0, table_length(&DE_LEVA_HEAD, h), 0.0));
    (
        segment(&DE_LEVA_HEAD, mass, top.y, top, DOWN, 1),
        LinkBox {
            center: DVec3::new(0.0, top.y * 0.5, 0.01 * h),
            half: DVec3::new(0.045 * h, top.y * 0.5, 0.055 * h),
        },
    )
}

/// A slender rod from the sterno-clavicular joint to the shoulder, as thick as the upper arm's
/// box.
fn clavicle_link(
    fig: &Figure,
    j: &FigureJoint,
    &Subject { h, mass, .. }: &Subject,
) -> (Inertia, LinkBox) {
    let end = child_offset(fig, j, "shoulder").unwrap_or(DVec3::new(0.11 * h, 0.0, 0.0));
    let len = end.length();
    let m = CLAVICLE_SHARE * DE_LEVA_UPPER_TRUNK.mass_pct / 100.0 * mass;
    (
        rod(m, len, 0.025 * h, DVec3::ZERO, end / len),
        LinkBox {
            center: end * 0.5,
            half: DVec3::new(end.x.abs() * 0.5, 0.025 * h, 0.025 * h),
        },
    )
}

/// A long bone of arm or leg (`link` without its side): from this joint to the next one down
/// the limb.
fn limb_link(
    fig: &Figure,
    j: &FigureJoint,
    link: &str,
    &Subject { h, mass, .. }: &Subject,
) -> (Inertia, LinkBox) {
    let (row, width, child) = match link {
        "upper_arm" => (&DE_LEVA_UPPER_ARM, 0.05, "elbow"),
        "forearm" => (&DE_LEVA_FOREARM, 0.04, "wrist"),
        "thigh" => (&DE_LEVA_THIGH, 0.08, "knee"),
        _ => (&DE_LEVA_SHANK, 0.06, "ankle"),
    };
    let end = child_offset(fig, j, child).unwrap_or(DVec3::new(0.0, -0.2 * h, 0.0));
    let len = end.length();
    (
        segment(row, mass, len, DVec3::ZERO, end / len, 1),
        LinkBox {
            center: end * 0.5,
            half: DVec3::new(width * h * 0.5, len * 0.5, width * h * 0.5),
        },
    )
}

/// Wrist → third metacarpale (de Leva's length) inside the box to the fingertips.
fn hand_link(j: &FigureJoint, &Subject { h, mass, .. }: &Subject) -> (Inertia, LinkBox) {
    let end = j.end_site.unwrap_or(DVec3::new(0.0, -0.108 * h, 0.0));
    (
        segment(
            &DE_LEVA_HAND,
            mass,
            table_length(&DE_LEVA_HAND, h),
            DVec3::ZERO,
            DOWN,
            1,
        ),
        LinkBox {
            center: end * 0.5,
            half: DVec3::new(0.01 * h, end.length() * 0.5, 0.025 * h),
        },
    )
}

/// Heel → toe tip, de Leva's length ending at the toe end site.
fn foot_link(j: &FigureJoint, &Subject { h, mass, .. }: &Subject) -> (Inertia, LinkBox) {
    let toe = j.end_site.unwrap_or(DVec3::new(0.0, -0.039 * h, 0.117 * h));
    let l = table_length(&DE_LEVA_FOOT, h);
    let heel = DVec3::new(0.0, toe.y * 0.5, toe.z - l);
    let fwd = DVec3::Z;
    (
        segment(&DE_LEVA_FOOT, mass, l, heel, fwd, 2),
        LinkBox {
            center: DVec3::new(0.0, toe.y * 0.5, toe.z - l * 0.5),
            half: DVec3::new(0.03 * h, -toe.y * 0.5, l * 0.5),
        },
    )
}

/// Downward in the figure's rest frame, `−y` (the bits of `-DVec3::Y`, zeros negative too):
/// the long axis of trunk, head and hand.
const DOWN: DVec3 = DVec3::new(-0.0, -1.0, -0.0);

/// The dynamics joint of the figure's joint `j`, with its DOF axes.
fn joint_type(fig: &Figure, j: &FigureJoint) -> JointType {
    let axes: Vec<DVec3> = j.dofs.iter().map(|&d| fig.dofs[d].axis).collect();
    match j.kind {
        JointKind::Free => JointType::Free,
        JointKind::Ball => JointType::Ball {
            axes: DMat3::from_cols(axes[0], axes[1], axes[2]),
        },
        JointKind::Universal => JointType::Universal {
            axis1: axes[0],
            axis2: axes[1],
        },
        JointKind::Pin => JointType::Pin { axis: axes[0] },
        JointKind::Fixed => JointType::Fixed,
    }
}

/// Each figure DOF's index in the model's velocity vector.
fn dof_velocity_indices(fig: &Figure, model: &Model) -> Vec<usize> {
    fig.dofs
        .iter()
        .map(|d| {
            let j = d.joint;
            let k = fig.joints[j]
                .dofs
                .iter()
                .position(|&x| fig.dofs[x].name == d.name)
                .unwrap_or(0);
            model.v_offset(j) + k
        })
        .collect()
}

impl HumanBody {
    /// A configuration `q` with the DOF angles `angles` (rad, fall21 model order) and the pelvis
    /// at `root_pos` with orientation `root_rot`.
    pub fn configuration(
        &self,
        angles: &[f64],
        root_pos: DVec3,
        root_rot: glam::DQuat,
    ) -> Vec<f64> {
        let mut q = self.model.neutral();
        q[0..3].copy_from_slice(&root_pos.to_array());
        let r = root_rot.normalize();
        q[3..7].copy_from_slice(&[r.x, r.y, r.z, r.w]);
        for (j, joint) in self.figure.joints.iter().enumerate() {
            let b = &self.model.bodies()[j];
            let n = joint.dofs.len();
            if n == 0 {
                continue;
            }
            let mut a = [0.0; 3];
            for (k, &d) in joint.dofs.iter().enumerate() {
                a[k] = angles[d];
            }
            let iq = self.model.q_offset(j);
            b.joint.set_angles(&a[..n], &mut q[iq..iq + b.joint.nq()]);
        }
        q
    }

    /// Index of the link named `name`.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.link_names.iter().position(|n| n == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn de_leva_masses_sum_to_the_body_mass() {
        let b = fall21_body(1.70, 65.0, 9.81).unwrap();
        assert_eq!(b.model.nbodies(), 15);
        assert_eq!(b.model.nv(), 27);
        assert_eq!(b.model.nq(), 29);
        assert!(
            (b.model.total_mass() - 65.0).abs() < 1e-9,
            "{}",
            b.model.total_mass()
        );
    }

    #[test]
    fn standing_centre_of_mass_is_at_the_anthropometric_height() {
        // Whole-body centre of mass of an upright adult: about 0.55–0.57 of stature (Winter,
        // Biomechanics and Motor Control of Human Movement).
        let h = 1.70;
        let b = fall21_body(h, 65.0, 9.81).unwrap();
        let mut q = b.configuration(
            &[0.0; 21],
            DVec3::new(0.0, 0.530 * h, 0.0),
            glam::DQuat::IDENTITY,
        );
        q[1] = 0.530 * h;
        let mut data = crate::dynamics::Data::new(&b.model);
        crate::dynamics::kinematics(&b.model, &mut data, &q, &[0.0; 27]);
        let mut c = DVec3::ZERO;
        for (i, body) in b.model.bodies().iter().enumerate() {
            c += (data.pos[i] + data.rot[i] * body.inertia.com) * body.inertia.mass;
        }
        let c = c / b.model.total_mass();
        let ratio = c.y / h;
        println!("COM at {ratio:.4} of stature");
        assert!((0.54..0.58).contains(&ratio), "COM at {ratio} of stature");
        assert!(c.x.abs() < 1e-9, "left-right symmetric: {}", c.x);
    }

    /// Principal moments of a uniform box of half extents `a` about its X, Y, Z axes (up to the
    /// common factor m/3).
    fn box_moments(a: DVec3) -> DVec3 {
        DVec3::new(
            a.y * a.y + a.z * a.z,
            a.x * a.x + a.z * a.z,
            a.x * a.x + a.y * a.y,
        )
    }

    #[test]
    fn de_leva_axes_follow_the_segment_shapes() {
        // The sagittal radius is about the antero-posterior axis (Z), the transverse one about
        // the medio-lateral axis (X): the trunk, wider than deep, has more inertia about Z than
        // about X; the head, deeper than wide, the other way round; the foot, wider than high,
        // more about Y than about X. Each matches the order of its contact box's moments.
        let b = fall21_body(1.70, 65.0, 9.81).unwrap();
        for (link, (ax, bx)) in [
            ("torso", (2usize, 0usize)),
            ("pelvis", (2, 0)),
            ("head", (0, 2)),
            ("right_foot", (1, 0)),
        ] {
            let i = b.link_index(link).unwrap();
            let ic = b.model.bodies()[i].inertia.inertia_com;
            let d = [ic.x_axis.x, ic.y_axis.y, ic.z_axis.z];
            let boxm = box_moments(b.boxes[i].half).to_array();
            assert!(d[ax] > d[bx], "{link}: I = {d:?}");
            assert!(boxm[ax] > boxm[bx], "{link} box: {boxm:?}");
        }
        // The torso's flexion inertia (about X) from de Leva's transverse radii.
        let torso = b.link_index("torso").unwrap();
        let flex = b.model.bodies()[torso].inertia.inertia_com.x_axis.x;
        let lat = b.model.bodies()[torso].inertia.inertia_com.z_axis.z;
        println!("torso flexion inertia {flex:.3} kg·m², lateral {lat:.3} kg·m²");
        assert!(flex < lat);
    }

    #[test]
    fn trunk_segments_meet_at_the_waist_without_overlap() {
        // The pelvis's centre of mass lies between the hip line and the waist, the torso's
        // between the waist and the neck: each inside its own span, none across the joint.
        let b = fall21_body(1.70, 65.0, 9.81).unwrap();
        let torso = b.link_index("torso").unwrap();
        let pelvis = b.link_index("pelvis").unwrap();
        let waist_y = b.figure.joints[torso].offset.y;
        let neck_y = b.figure.joints[b.link_index("head").unwrap()].offset.y;
        let pc = b.model.bodies()[pelvis].inertia.com.y;
        let tc = b.model.bodies()[torso].inertia.com.y;
        assert!(
            pc > 0.0 && pc < waist_y,
            "pelvis COM {pc} vs waist {waist_y}"
        );
        assert!(
            tc > 0.0 && tc < neck_y,
            "torso COM {tc} (torso frame) vs neck {neck_y}"
        );
        // The pelvis box ends at the waist, the torso box starts there.
        let top = b.boxes[pelvis].center.y + b.boxes[pelvis].half.y;
        let bottom = b.boxes[torso].center.y - b.boxes[torso].half.y;
        assert!(
            (top - waist_y).abs() < 1e-9 && bottom.abs() < 1e-9,
            "{top} {bottom}"
        );
    }

    #[test]
    fn dof_map_follows_the_figure_model() {
        let b = fall21_body(1.70, 65.0, 9.81).unwrap();
        assert_eq!(b.dof_v.len(), 21);
        let knee = b.figure.dof_index("right_knee").unwrap();
        let shin = b.link_index("right_shin").unwrap();
        assert_eq!(b.dof_v[knee], b.model.v_offset(shin));
        // Every velocity DOF past the root is hit exactly once.
        let mut seen = b.dof_v.to_vec();
        seen.sort();
        assert_eq!(seen, (6..27).collect::<Vec<_>>());
    }

    #[test]
    fn humanoid24_gets_a_body_like_fall21() {
        let b = humanoid24_body(1.70, 65.0, 9.81).unwrap();
        // 17 links: the fixed neck, wrists and ankles weld head, hands and feet to their parents.
        assert_eq!(b.model.nbodies(), 17);
        assert_eq!(b.model.nv(), 6 + 24);
        assert_eq!(b.dof_v.len(), 24);
        assert!(
            (b.model.total_mass() - 65.0).abs() < 1e-9,
            "{}",
            b.model.total_mass()
        );
        for link in ["head", "left_hand", "right_foot"] {
            let i = b.link_index(link).unwrap();
            assert_eq!(b.model.bodies()[i].joint, JointType::Fixed, "{link}");
        }
        // Every velocity DOF past the root is one humanoid24 DOF, exactly once.
        let mut seen = b.dof_v.to_vec();
        seen.sort();
        assert_eq!(seen, (6..30).collect::<Vec<_>>());
        // The limbs are de Leva's, as on fall21: the same segment masses and inertias.
        let f = fall21_body(1.70, 65.0, 9.81).unwrap();
        for link in [
            "pelvis",
            "head",
            "right_thigh",
            "left_shin",
            "right_foot",
            "left_hand",
        ] {
            let (x, y) = (
                &b.model.bodies()[b.link_index(link).unwrap()].inertia,
                &f.model.bodies()[f.link_index(link).unwrap()].inertia,
            );
            assert!((x.mass - y.mass).abs() < 1e-12, "{link}");
            assert!(
                (x.inertia_com - y.inertia_com).abs_diff_eq(DMat3::ZERO, 1e-12),
                "{link}"
            );
        }
        // The chest gives the girdle its share: chest + 2 clavicles = fall21's torso.
        let chest = b.model.bodies()[b.link_index("chest").unwrap()]
            .inertia
            .mass;
        let clav = b.model.bodies()[b.link_index("left_clavicle").unwrap()]
            .inertia
            .mass;
        let torso = f.model.bodies()[f.link_index("torso").unwrap()]
            .inertia
            .mass;
        assert!((chest + 2.0 * clav - torso).abs() < 1e-9);
        assert!(clav > 0.0 && clav < 0.02 * 65.0);
    }

    #[test]
    fn humanoid24_inertia_axes_follow_de_leva() {
        // Same axis assignment as fall21: the chest (trunk) has more inertia about Z (its
        // sagittal radius) than about X; the thigh's longitudinal moment (Y) is the smallest.
        let b = humanoid24_body(1.70, 65.0, 9.81).unwrap();
        let d = |link: &str| {
            let ic = b.model.bodies()[b.link_index(link).unwrap()]
                .inertia
                .inertia_com;
            [ic.x_axis.x, ic.y_axis.y, ic.z_axis.z]
        };
        let chest = d("chest");
        assert!(chest[2] > chest[0], "{chest:?}");
        let thigh = d("right_thigh");
        assert!(thigh[1] < thigh[0] && thigh[1] < thigh[2], "{thigh:?}");
        // The clavicle rod lies along X: least inertia about its own axis.
        let c = d("right_clavicle");
        assert!(c[0] < c[1] && c[0] < c[2], "{c:?}");
    }

    #[test]
    fn a_figure_without_a_free_root_is_refused() {
        let mut m = humanoid::humanoid24();
        m.joints[0].kind = JointKind::Fixed;
        assert!(matches!(
            human_body(&m, 1.7, 65.0, 9.81),
            Err(HumanError::Root(_))
        ));
    }
}
