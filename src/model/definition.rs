//! The two models of the papers, defined once, from a reference body of height H = 1.70 m.
//!
//! Segment proportions follow Winter's anthropometric table (Winter, *Biomechanics and Motor
//! Control of Human Movement*, 4th ed. 2009, Fig. 4.1: segment lengths as fractions of height):
//! hip centre at 0.530H, shoulder at 0.818H, knee at 0.285H, ankle at 0.039H, upper arm 0.186H,
//! forearm 0.146H, hand 0.108H, foot 0.152H long.

use glam::DVec3;

use super::{Dof, JointKind, Model, ModelJoint};

/// Reference standing height of the model definitions, metres.
pub const REFERENCE_HEIGHT: f64 = 1.70;

/// Which side a limb joint is on; decides the axis mirroring.
#[derive(Clone, Copy, PartialEq)]
enum Side {
    Centre,
    Right,
    Left,
}

impl Side {
    /// Mirrors a right-side axis for the left side: `(a.x, −a.y, −a.z)`.
    fn axis(self, a: DVec3) -> DVec3 {
        match self {
            Side::Left => DVec3::new(a.x, -a.y, -a.z),
            _ => a,
        }
    }
    /// Mirrors a right-side position for the left side (x is the figure's left).
    fn lateral(self, x: f64) -> f64 {
        match self {
            Side::Left => x,
            Side::Right => -x,
            Side::Centre => 0.0,
        }
    }
    fn prefix(self) -> &'static str {
        match self {
            Side::Left => "left_",
            Side::Right => "right_",
            Side::Centre => "",
        }
    }
}

struct Builder {
    model: Model,
}

impl Builder {
    fn new(name: &str) -> Self {
        Builder {
            model: Model {
                name: name.into(),
                height: REFERENCE_HEIGHT,
                joints: vec![],
                dofs: vec![],
            },
        }
    }

    /// Adds a joint; `dofs` are (name suffix, right-side axis); returns its index.
    #[allow(clippy::too_many_arguments)]
    fn joint(
        &mut self,
        side: Side,
        name: &str,
        link: &str,
        parent: Option<usize>,
        kind: JointKind,
        offset: DVec3,
        dofs: &[(&str, DVec3)],
        end_site: Option<DVec3>,
    ) -> usize {
        let h = REFERENCE_HEIGHT;
        let j = self.model.joints.len();
        let mut dof_ids = vec![];
        assert_eq!(dofs.len(), kind.dof_count(), "joint {name}");
        for (suffix, axis) in dofs {
            let dof_name = if suffix.is_empty() {
                format!("{}{}", side.prefix(), name)
            } else {
                format!("{}{}_{}", side.prefix(), name, suffix)
            };
            dof_ids.push(self.model.dofs.len());
            self.model.dofs.push(Dof {
                name: dof_name,
                joint: j,
                axis: side.axis(*axis),
            });
        }
        let place = |v: DVec3| DVec3::new(side.lateral(v.x), v.y, v.z) * h;
        self.model.joints.push(ModelJoint {
            name: format!("{}{}", side.prefix(), name),
            link: format!("{}{}", side.prefix(), link),
            parent,
            kind,
            offset: place(offset),
            dofs: dof_ids,
            end_site: end_site.map(place),
        });
        j
    }
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

const X: DVec3 = DVec3::X;
const NX: DVec3 = DVec3::NEG_X;
const Y: DVec3 = DVec3::Y;
const NY: DVec3 = DVec3::NEG_Y;
const Z: DVec3 = DVec3::Z;
const NZ: DVec3 = DVec3::NEG_Z;

/// Adds a leg (hip, knee, ankle) to `b`; the hip is a ball joint for humanoid24 and a universal
/// joint for fall21; the ankle is fixed for humanoid24 and a pin for fall21.
fn leg(b: &mut Builder, side: Side, pelvis: usize, fall: bool) {
    let hip = if fall {
        b.joint(
            side,
            "hip",
            "thigh",
            Some(pelvis),
            JointKind::Universal,
            v(0.05, 0.0, 0.0),
            &[("flexion", NX), ("abduction", NZ)],
            None,
        )
    } else {
        b.joint(
            side,
            "hip",
            "thigh",
            Some(pelvis),
            JointKind::Ball,
            v(0.05, 0.0, 0.0),
            &[("flexion", NX), ("abduction", NZ), ("rotation", NY)],
            None,
        )
    };
    let knee = b.joint(
        side,
        "knee",
        "shin",
        Some(hip),
        JointKind::Pin,
        v(0.0, -0.245, 0.0),
        &[("", X)],
        None,
    );
    let toe = Some(v(0.0, -0.039, 0.117));
    if fall {
        b.joint(
            side,
            "ankle",
            "foot",
            Some(knee),
            JointKind::Pin,
            v(0.0, -0.246, 0.0),
            &[("", NX)],
            toe,
        );
    } else {
        b.joint(
            side,
            "ankle",
            "foot",
            Some(knee),
            JointKind::Fixed,
            v(0.0, -0.246, 0.0),
            &[],
            toe,
        );
    }
}

/// The 24-DOF model of the motor-primitive paper: waist 2, each clavicle 2, each shoulder 3, each
/// elbow 2, each hip 3, each knee 1. Root motion (pelvis translation and orientation) is carried
/// apart from the 24 DOFs.
pub fn humanoid24() -> Model {
    let mut b = Builder::new("humanoid24");
    let c = Side::Centre;
    let pelvis = b.joint(
        c,
        "pelvis",
        "pelvis",
        None,
        JointKind::Free,
        v(0.0, 0.530, 0.0),
        &[],
        None,
    );
    let waist = b.joint(
        c,
        "waist",
        "chest",
        Some(pelvis),
        JointKind::Universal,
        v(0.0, 0.07, 0.0),
        &[("flexion", X), ("lateral", Z)],
        None,
    );
    b.joint(
        c,
        "neck",
        "head",
        Some(waist),
        JointKind::Fixed,
        v(0.0, 0.23, 0.0),
        &[],
        Some(v(0.0, 0.17, 0.0)),
    );
    for side in [Side::Right, Side::Left] {
        let clav = b.joint(
            side,
            "clavicle",
            "clavicle",
            Some(waist),
            JointKind::Universal,
            v(0.02, 0.20, 0.0),
            &[("elevation", NZ), ("protraction", Y)],
            None,
        );
        let sh = b.joint(
            side,
            "shoulder",
            "upper_arm",
            Some(clav),
            JointKind::Ball,
            v(0.11, 0.018, 0.0),
            &[("flexion", NX), ("abduction", NZ), ("rotation", NY)],
            None,
        );
        let el = b.joint(
            side,
            "elbow",
            "forearm",
            Some(sh),
            JointKind::Universal,
            v(0.0, -0.186, 0.0),
            &[("flexion", NX), ("pronation", Y)],
            None,
        );
        b.joint(
            side,
            "wrist",
            "hand",
            Some(el),
            JointKind::Fixed,
            v(0.0, -0.146, 0.0),
            &[],
            Some(v(0.0, -0.108, 0.0)),
        );
    }
    for side in [Side::Right, Side::Left] {
        leg(&mut b, side, pelvis, false);
    }
    b.model
}

/// The 21-DOF, 15-link model of the falling paper: neck 3, each shoulder 2, each elbow 1, each
/// wrist 1, waist 2, each hip 2, each knee 1, each ankle 1; the pelvis is the floating base.
pub fn fall21() -> Model {
    let mut b = Builder::new("fall21");
    let c = Side::Centre;
    let pelvis = b.joint(
        c,
        "pelvis",
        "pelvis",
        None,
        JointKind::Free,
        v(0.0, 0.530, 0.0),
        &[],
        None,
    );
    let waist = b.joint(
        c,
        "waist",
        "torso",
        Some(pelvis),
        JointKind::Universal,
        v(0.0, 0.07, 0.0),
        &[("flexion", X), ("rotation", Y)],
        None,
    );
    b.joint(
        c,
        "neck",
        "head",
        Some(waist),
        JointKind::Ball,
        v(0.0, 0.23, 0.0),
        &[("flexion", X), ("lateral", Z), ("rotation", Y)],
        Some(v(0.0, 0.17, 0.0)),
    );
    for side in [Side::Right, Side::Left] {
        let sh = b.joint(
            side,
            "shoulder",
            "upper_arm",
            Some(waist),
            JointKind::Universal,
            v(0.13, 0.218, 0.0),
            &[("flexion", NX), ("rotation", NY)],
            None,
        );
        let el = b.joint(
            side,
            "elbow",
            "forearm",
            Some(sh),
            JointKind::Pin,
            v(0.0, -0.186, 0.0),
            &[("", NX)],
            None,
        );
        b.joint(
            side,
            "wrist",
            "hand",
            Some(el),
            JointKind::Pin,
            v(0.0, -0.146, 0.0),
            &[("", Z)],
            Some(v(0.0, -0.108, 0.0)),
        );
    }
    for side in [Side::Right, Side::Left] {
        leg(&mut b, side, pelvis, true);
    }
    b.model
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn humanoid24_has_the_papers_24_dofs() {
        let m = humanoid24();
        assert_eq!(m.dofs.len(), 24);
        let count = |prefix: &str| m.dofs.iter().filter(|d| d.name.starts_with(prefix)).count();
        assert_eq!(count("waist"), 2);
        assert_eq!(count("left_clavicle"), 2);
        assert_eq!(count("right_shoulder"), 3);
        assert_eq!(count("left_elbow"), 2);
        assert_eq!(count("right_hip"), 3);
        assert_eq!(count("left_knee"), 1);
        assert!(m.dof_index("left_knee").is_some() && m.dof_index("right_knee").is_some());
    }

    #[test]
    fn fall21_has_15_links_14_joints_21_dofs() {
        let m = fall21();
        assert_eq!(m.joints.len(), 15);
        assert_eq!(m.joints.iter().filter(|j| j.parent.is_some()).count(), 14);
        assert_eq!(m.dofs.len(), 21);
        assert_eq!(
            m.joints
                .iter()
                .filter(|j| j.kind == JointKind::Ball)
                .count(),
            1
        );
    }

    #[test]
    fn parents_come_first_and_dofs_follow_joint_order() {
        for m in [humanoid24(), fall21()] {
            for (i, j) in m.joints.iter().enumerate() {
                if let Some(p) = j.parent {
                    assert!(p < i);
                }
            }
            let mut last = 0;
            for d in &m.dofs {
                assert!(d.joint >= last);
                last = d.joint;
                assert!((d.axis.length() - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn left_is_plus_x_and_axes_mirror() {
        let m = humanoid24();
        let lh = &m.joints[m.joint_index("left_hip").unwrap()];
        let rh = &m.joints[m.joint_index("right_hip").unwrap()];
        assert!(lh.offset.x > 0.0 && rh.offset.x < 0.0);
        let la = m.dofs[m.dof_index("left_hip_abduction").unwrap()].axis;
        let ra = m.dofs[m.dof_index("right_hip_abduction").unwrap()].axis;
        assert_eq!(la, -ra);
        // Positive knee flexion moves the foot backward (−Z), on both sides.
        for name in ["left_knee", "right_knee"] {
            let ax = m.dofs[m.dof_index(name).unwrap()].axis;
            let foot = glam::DQuat::from_axis_angle(ax, 0.5) * DVec3::NEG_Y;
            assert!(foot.z < 0.0, "{name}");
        }
        // Positive hip abduction moves the foot away from the midline.
        for (name, sign) in [("left_hip_abduction", 1.0), ("right_hip_abduction", -1.0)] {
            let ax = m.dofs[m.dof_index(name).unwrap()].axis;
            let foot = glam::DQuat::from_axis_angle(ax, 0.5) * DVec3::NEG_Y;
            assert!(foot.x * sign > 0.0, "{name}");
        }
    }

    #[test]
    fn standing_height_is_the_reference_height() {
        for m in [humanoid24(), fall21()] {
            let sk = m.skeleton();
            let pts = sk.rest_points();
            let top = pts.iter().map(|p| p.y).fold(f64::MIN, f64::max);
            let bottom = pts.iter().map(|p| p.y).fold(f64::MAX, f64::min);
            assert!(
                ((top - bottom) - REFERENCE_HEIGHT).abs() < 0.02,
                "{}: {}",
                m.name,
                top - bottom
            );
        }
    }
}
