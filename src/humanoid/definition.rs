//! The two models of the papers, defined once as tables, from a reference body of height
//! H = 1.70 m.
//!
//! Segment proportions follow Winter's anthropometric table (Winter, *Biomechanics and Motor
//! Control of Human Movement*, 4th ed. 2009, Fig. 4.1: segment lengths as fractions of height):
//! hip centre at 0.530H, shoulder at 0.818H, knee at 0.285H, ankle at 0.039H, upper arm 0.186H,
//! forearm 0.146H, hand 0.108H, foot 0.152H long.

use glam::DVec3;

use super::{Dof, Figure, FigureJoint, JointKind};

/// Reference standing height of the model definitions, metres.
pub const REFERENCE_HEIGHT: f64 = 1.70;

const X: DVec3 = DVec3::X;
const NX: DVec3 = DVec3::NEG_X;
const Y: DVec3 = DVec3::Y;
const NY: DVec3 = DVec3::NEG_Y;
const Z: DVec3 = DVec3::Z;
const NZ: DVec3 = DVec3::NEG_Z;

/// One joint of a model table. Offsets and End Sites are fractions of the height, with x
/// toward the side the joint is on (a limb's x is mirrored for the right side); DOF axes are
/// the right side's (mirrored for the left as `(a.x, −a.y, −a.z)`); a DOF named `""` takes the
/// joint's name (`left_knee`).
struct Row {
    name: &'static str,
    link: &'static str,
    parent: Option<&'static str>,
    kind: JointKind,
    offset: [f64; 3],
    dofs: &'static [(&'static str, DVec3)],
    end_site: Option<[f64; 3]>,
}

/// A part of a model table: a joint on the mid-line, or a limb chain made twice, right then left.
enum Part<'a> {
    Centre(Row),
    Limb(&'a [Row]),
}

const fn row(
    name: &'static str,
    link: &'static str,
    parent: Option<&'static str>,
    kind: JointKind,
    offset: [f64; 3],
    dofs: &'static [(&'static str, DVec3)],
    end_site: Option<[f64; 3]>,
) -> Row {
    Row {
        name,
        link,
        parent,
        kind,
        offset,
        dofs,
        end_site,
    }
}

/// Builds a model from its table: joints in table order (limbs right then left), each
/// parent before its children.
fn build(name: &str, parts: &[Part<'_>]) -> Figure {
    let mut model = Figure {
        name: name.into(),
        height: REFERENCE_HEIGHT,
        joints: vec![],
        dofs: vec![],
    };
    let mut add = |r: &Row, side: &str| {
        let mirror = |v: [f64; 3]| {
            let x = match side {
                "right_" => -v[0],
                _ => v[0],
            };
            DVec3::new(x, v[1], v[2]) * REFERENCE_HEIGHT
        };
        let axis = |a: DVec3| {
            if side == "left_" {
                DVec3::new(a.x, -a.y, -a.z)
            } else {
                a
            }
        };
        let j = model.joints.len();
        let joint_name = format!("{side}{}", r.name);
        let parent = r.parent.map(|p| {
            let sided = format!("{side}{p}");
            model
                .joints
                .iter()
                .position(|q| q.name == sided || q.name == p)
                .expect("model tables list parents first")
        });
        assert_eq!(r.dofs.len(), r.kind.dof_count(), "joint {joint_name}");
        let mut dofs = vec![];
        for (suffix, a) in r.dofs {
            let dof_name = if suffix.is_empty() {
                joint_name.clone()
            } else {
                format!("{joint_name}_{suffix}")
            };
            dofs.push(model.dofs.len());
            model.dofs.push(Dof {
                name: dof_name,
                joint: j,
                axis: axis(*a),
            });
        }
        model.joints.push(FigureJoint {
            name: joint_name,
            link: format!("{side}{}", r.link),
            parent,
            kind: r.kind,
            offset: mirror(r.offset),
            dofs,
            end_site: r.end_site.map(mirror),
        });
    };
    for part in parts {
        match part {
            Part::Centre(r) => add(r, ""),
            Part::Limb(rows) => {
                for side in ["right_", "left_"] {
                    for r in *rows {
                        add(r, side);
                    }
                }
            }
        }
    }
    model
}

use JointKind::{Ball, Fixed, Free, Pin, Universal};

const TOE: Option<[f64; 3]> = Some([0.0, -0.039, 0.117]);
const HEAD_TOP: Option<[f64; 3]> = Some([0.0, 0.17, 0.0]);
const HAND_END: Option<[f64; 3]> = Some([0.0, -0.108, 0.0]);

/// The 24-DOF model of the motor-primitive paper: waist 2, each clavicle 2, each shoulder 3, each
/// elbow 2, each hip 3, each knee 1. Root motion (pelvis translation and orientation) is carried
/// apart from the 24 DOFs.
#[rustfmt::skip]
pub fn humanoid24() -> Figure {
    build("humanoid24", &[
        Part::Centre(row("pelvis", "pelvis", None, Free, [0.0, 0.530, 0.0], &[], None)),
        Part::Centre(row("waist", "chest", Some("pelvis"), Universal, [0.0, 0.07, 0.0], &[("flexion", X), ("lateral", Z)], None)),
        Part::Centre(row("neck", "head", Some("waist"), Fixed, [0.0, 0.23, 0.0], &[], HEAD_TOP)),
        Part::Limb(&[
            row("clavicle", "clavicle", Some("waist"), Universal, [0.02, 0.20, 0.0], &[("elevation", NZ), ("protraction", Y)], None),
            row("shoulder", "upper_arm", Some("clavicle"), Ball, [0.11, 0.018, 0.0], &[("flexion", NX), ("abduction", NZ), ("rotation", NY)], None),
            row("elbow", "forearm", Some("shoulder"), Universal, [0.0, -0.186, 0.0], &[("flexion", NX), ("pronation", Y)], None),
            row("wrist", "hand", Some("elbow"), Fixed, [0.0, -0.146, 0.0], &[], HAND_END),
        ]),
        Part::Limb(&[
            row("hip", "thigh", Some("pelvis"), Ball, [0.05, 0.0, 0.0], &[("flexion", NX), ("abduction", NZ), ("rotation", NY)], None),
            row("knee", "shin", Some("hip"), Pin, [0.0, -0.245, 0.0], &[("", X)], None),
            row("ankle", "foot", Some("knee"), Fixed, [0.0, -0.246, 0.0], &[], TOE),
        ]),
    ])
}

/// The 21-DOF, 15-link model of the falling paper: neck 3, each shoulder 2, each elbow 1, each
/// wrist 1, waist 2, each hip 2, each knee 1, each ankle 1; the pelvis is the floating base.
#[rustfmt::skip]
pub fn fall21() -> Figure {
    build("fall21", &[
        Part::Centre(row("pelvis", "pelvis", None, Free, [0.0, 0.530, 0.0], &[], None)),
        Part::Centre(row("waist", "torso", Some("pelvis"), Universal, [0.0, 0.07, 0.0], &[("flexion", X), ("rotation", Y)], None)),
        Part::Centre(row("neck", "head", Some("waist"), Ball, [0.0, 0.23, 0.0], &[("flexion", X), ("lateral", Z), ("rotation", Y)], HEAD_TOP)),
        Part::Limb(&[
            row("shoulder", "upper_arm", Some("waist"), Universal, [0.13, 0.218, 0.0], &[("flexion", NX), ("rotation", NY)], None),
            row("elbow", "forearm", Some("shoulder"), Pin, [0.0, -0.186, 0.0], &[("", NX)], None),
            row("wrist", "hand", Some("elbow"), Pin, [0.0, -0.146, 0.0], &[("", Z)], HAND_END),
        ]),
        Part::Limb(&[
            row("hip", "thigh", Some("pelvis"), Universal, [0.05, 0.0, 0.0], &[("flexion", NX), ("abduction", NZ)], None),
            row("knee", "shin", Some("hip"), Pin, [0.0, -0.245, 0.0], &[("", X)], None),
            row("ankle", "foot", Some("knee"), Pin, [0.0, -0.246, 0.0], &[("", NX)], TOE),
        ]),
    ])
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
