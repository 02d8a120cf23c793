//! Which points of a skeleton are its feet, and the contact phases of a clip.

use glam::DVec3;

use super::contact::{
    ContactConfig, ContactReference, Contacts, ground_contacts, ground_contacts_against,
};
use crate::mapping::Mapping;
use crate::skeleton::{Clip, Side, Skeleton, side_from_name};

/// A point of a skeleton: a joint, or (`true`) that joint's End Site.
pub type PointRef = (usize, bool);

/// The joints of the foot below (and including) each of `roots`: the ankle, heel and toe joints.
fn below(skeleton: &Skeleton, roots: &[usize]) -> Vec<usize> {
    let mut inside = vec![false; skeleton.joints.len()];
    for (i, j) in skeleton.joints.iter().enumerate() {
        // Parents come first, so one pass marks every descendant.
        inside[i] = roots.contains(&i) || j.parent.is_some_and(|p| inside[p]);
    }
    (0..inside.len()).filter(|&i| inside[i]).collect()
}

/// The foot points of each side, `[left, right]`: every joint and End Site from the ankle down
/// (ankle, heel, toes, toe End Sites). The ankle is the skeleton's detected mapping's ankle
/// landmark, else every joint named like a foot (`foot`, `toe`, `ankle`, `heel`) on that side
/// (see [`side_from_name`]).
pub fn foot_points(skeleton: &Skeleton) -> [Vec<PointRef>; 2] {
    let mapping = Mapping::detect(skeleton).ok();
    let side_points = |side: Side, prefix: &str| -> Vec<PointRef> {
        let roots: Vec<usize> = match &mapping {
            Some(m) => m
                .resolve(skeleton, &format!("{prefix}_ankle"))
                .map(|l| vec![l.joint])
                .unwrap_or_default(),
            None => skeleton
                .joints
                .iter()
                .enumerate()
                .filter(|(_, j)| {
                    let n = j.name.to_lowercase();
                    ["foot", "toe", "ankle", "heel"]
                        .iter()
                        .any(|w| n.contains(w))
                        && side_from_name(&j.name) == side
                })
                .map(|(i, _)| i)
                .collect(),
        };
        let mut pts = vec![];
        for j in below(skeleton, &roots) {
            pts.push((j, false));
            if skeleton.joints[j].end_site.is_some() {
                pts.push((j, true));
            }
        }
        pts
    };
    [
        side_points(Side::Left, "left"),
        side_points(Side::Right, "right"),
    ]
}

/// Ground contact and flight of a clip with [`ContactConfig::default`] but for the contact
/// threshold and the shortest flight ([`clip_contacts_with`]).
pub fn clip_contacts(clip: &Clip, threshold_m: f64, min_flight_s: f64) -> Option<Contacts> {
    clip_contacts_with(
        clip,
        &ContactConfig {
            threshold_m,
            min_flight_s,
            ..ContactConfig::default()
        },
    )
}

/// Ground contact and flight of a clip: its feet ([`foot_points`]) and every other point of the
/// body but a ground-proxy root ([`Skeleton::ground_proxy_root`], [`ground_contacts`]); `None` when a side has no foot point.
pub fn clip_contacts_with(clip: &Clip, config: &ContactConfig) -> Option<Contacts> {
    clip_contacts_and_feet(clip, config).map(|(c, _)| c)
}

/// [`clip_contacts_with`] and the foot points' tracks it was found from, `[left, right]`, each
/// frame-major in [`foot_points`] order (as [`point_tracks`]), so a caller measuring the feet
/// does not run the clip's forward kinematics again.
pub fn clip_contacts_and_feet(
    clip: &Clip,
    config: &ContactConfig,
) -> Option<(Contacts, [Vec<Vec<DVec3>>; 2])> {
    let (l, r, b) = clip_points(clip)?;
    let c = ground_contacts(&l, &r, &b, clip.frame_time, config);
    Some((c, [l, r]))
}

/// [`clip_contacts_with`] against the floor and rest heights of another clip of the same
/// skeleton ([`Contacts::reference`], [`ground_contacts_against`]); `None` when a side has no
/// foot point.
pub fn clip_contacts_against(
    clip: &Clip,
    config: &ContactConfig,
    reference: &ContactReference,
) -> Option<Contacts> {
    let (l, r, b) = clip_points(clip)?;
    Some(ground_contacts_against(
        &l,
        &r,
        &b,
        clip.frame_time,
        config,
        reference,
    ))
}

/// Every frame's left-foot, right-foot and other points of `clip` (see [`clip_contacts_with`]);
/// `None` when a side has no foot point.
#[allow(clippy::type_complexity)]
fn clip_points(clip: &Clip) -> Option<(Vec<Vec<DVec3>>, Vec<Vec<DVec3>>, Vec<Vec<DVec3>>)> {
    let [lf, rf] = foot_points(&clip.skeleton);
    if lf.is_empty() || rf.is_empty() {
        return None;
    }
    let joints = &clip.skeleton.joints;
    let proxy = clip.skeleton.ground_proxy_root();
    let is_foot = |p: &PointRef| lf.contains(p) || rf.contains(p) || Some(p.0) == proxy;
    let others: Vec<PointRef> = (0..joints.len())
        .flat_map(|j| std::iter::once((j, false)).chain(joints[j].end_site.map(|_| (j, true))))
        .filter(|p| !is_foot(p))
        .collect();
    Some((
        point_tracks(clip, &lf),
        point_tracks(clip, &rf),
        point_tracks(clip, &others),
    ))
}

/// The global positions of `points` at every frame of `clip`, frame-major: `out[f][i]` is point
/// `points[i]` at frame f, metres.
pub fn point_tracks(clip: &Clip, points: &[PointRef]) -> Vec<Vec<DVec3>> {
    let joints = &clip.skeleton.joints;
    let mut g = vec![];
    (0..clip.frame_count())
        .map(|f| {
            clip.globals(f, &mut g);
            points
                .iter()
                .map(|&(j, end)| {
                    let e = if end {
                        joints[j].end_site.unwrap_or_default()
                    } else {
                        DVec3::ZERO
                    };
                    g[j].translation + g[j].rotation * e
                })
                .collect()
        })
        .collect()
}
