//! Which points of a skeleton are its feet, and their contact phases over a clip.

use glam::DVec3;

use super::contact::{Contacts, ground_contacts};
use crate::mapping::Mapping;
use crate::skeleton::{Clip, Side, Skeleton, side_from_name};

/// A point of a skeleton: a joint, or (`true`) that joint's End Site.
pub type PointRef = (usize, bool);

/// The foot points of each side, `[left, right]`: the ankle and toe landmarks of the skeleton's
/// detected mapping, else every joint named like a foot (`foot`, `toe`, `ankle`) on that side
/// (see [`side_from_name`]).
pub fn foot_points(skeleton: &Skeleton) -> [Vec<PointRef>; 2] {
    let side_points = |side: Side, prefix: &str| -> Vec<PointRef> {
        if let Ok(m) = Mapping::detect(skeleton) {
            return ["ankle", "toe"]
                .iter()
                .filter_map(|p| m.resolve(skeleton, &format!("{prefix}_{p}")).ok())
                .map(|l| (l.joint, l.end_site))
                .collect();
        }
        skeleton
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| {
                let n = j.name.to_lowercase();
                (n.contains("foot") || n.contains("toe") || n.contains("ankle"))
                    && side_from_name(&j.name) == side
            })
            .map(|(i, _)| (i, false))
            .collect()
    };
    [
        side_points(Side::Left, "left"),
        side_points(Side::Right, "right"),
    ]
}

/// Ground contact and flight of a clip's feet ([`foot_points`], [`ground_contacts`]); `None`
/// when a side has no foot point.
pub fn clip_contacts(clip: &Clip, threshold_m: f64, min_flight_s: f64) -> Option<Contacts> {
    let [lf, rf] = foot_points(&clip.skeleton);
    if lf.is_empty() || rf.is_empty() {
        return None;
    }
    let mut g = vec![];
    let (mut l, mut r) = (vec![], vec![]);
    for f in 0..clip.frame_count() {
        clip.globals(f, &mut g);
        let at = |idx: &[PointRef]| -> Vec<DVec3> {
            idx.iter()
                .map(|&(j, end)| {
                    let e = if end {
                        clip.skeleton.joints[j].end_site.unwrap_or_default()
                    } else {
                        DVec3::ZERO
                    };
                    g[j].translation + g[j].rotation * e
                })
                .collect()
        };
        l.push(at(&lf));
        r.push(at(&rf));
    }
    Some(ground_contacts(
        &l,
        &r,
        clip.frame_time,
        threshold_m,
        min_flight_s,
    ))
}
