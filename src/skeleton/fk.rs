//! Forward kinematics: global joint transforms from local ones, parents first.

use glam::{DQuat, DVec3};

use super::Skeleton;

/// A rigid transform kept as rotation plus translation: `x ↦ rotation·x + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Orientation.
    pub rotation: DQuat,
    /// Position, metres.
    pub translation: DVec3,
}

impl Transform {
    /// The identity transform.
    pub const IDENTITY: Transform = Transform {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// `self ∘ local`: the child's global transform from its parent's (`self`) and its local one.
    #[inline]
    pub fn compose(&self, rotation: DQuat, translation: DVec3) -> Transform {
        Transform {
            rotation: self.rotation * rotation,
            translation: self.translation + self.rotation * translation,
        }
    }
}

/// Global transforms of every joint of one frame: `G_j = G_parent(j) ∘ (t_j, R_j)`, with the root's
/// local transform taken as global. `translations` and `rotations` are the local ones (one per
/// joint, e.g. one frame of a [`super::Clip`]); `out` gets one transform per joint.
#[inline]
pub fn forward_kinematics(
    skeleton: &Skeleton,
    translations: &[DVec3],
    rotations: &[DQuat],
    out: &mut [Transform],
) {
    let n = skeleton.joints.len();
    assert!(translations.len() >= n && rotations.len() >= n && out.len() >= n);
    for (j, joint) in skeleton.joints.iter().enumerate() {
        out[j] = match joint.parent {
            // Parents come first, so out[p] is final here.
            Some(p) => out[p].compose(rotations[j], translations[j]),
            None => Transform {
                rotation: rotations[j],
                translation: translations[j],
            },
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::Joint;

    fn chain() -> Skeleton {
        let j = |name: &str, parent, offset| Joint {
            name: name.into(),
            parent,
            offset,
            end_site: None,
        };
        Skeleton {
            joints: vec![
                j("root", None, DVec3::ZERO),
                j("a", Some(0), DVec3::new(0.0, 1.0, 0.0)),
                j("b", Some(1), DVec3::new(0.0, 1.0, 0.0)),
            ],
        }
    }

    #[test]
    fn rotations_compose_down_the_chain() {
        let s = chain();
        let t: Vec<DVec3> = s.joints.iter().map(|j| j.offset).collect();
        let q = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let r = vec![DQuat::IDENTITY, q, q];
        let mut g = vec![Transform::IDENTITY; 3];
        forward_kinematics(&s, &t, &r, &mut g);
        // a sits at (0,1,0); rotated 90° about z, b is at a + (-1,0,0).
        assert!((g[1].translation - DVec3::new(0.0, 1.0, 0.0)).length() < 1e-12);
        assert!((g[2].translation - DVec3::new(-1.0, 1.0, 0.0)).length() < 1e-12);
        // b's orientation is 180° about z.
        assert!((g[2].rotation * DVec3::X - DVec3::NEG_X).length() < 1e-12);
    }
}
