//! A larger segment database made from a real one by mirror images and time offsets (for the
//! benches and the search experiment at the 2,000 segments), never from noise.
//!
//! - **Mirror image**: the dance reflected in the plane x = 0 (a reflection M = diag(−1, 1, 1)):
//!   the root position (x, y, z) → (−x, y, z), the root orientation M R M (quaternion
//!   (x, y, z, w) → (x, −y, −z, w)), and every DOF angle moved to its mirror partner's DOF
//!   (left ↔ right, [`super::features::mirror_partners`]) with the sign that maps its axis a onto
//!   the partner's axis b = ±(a.x, −a.y, −a.z) (M R(a, θ) M = R(−M a, θ)): on humanoid24 a limb's
//!   angles move to the other side unchanged, the waist's lateral bend changes sign. On the
//!   model's symmetric body this is exactly the mirrored motion (tested against
//!   [`super::features::mirror_motion`] of the joint positions).
//! - **Time offset**: the database keeps each bar's resampled frames, not its clip, but two
//!   consecutive bars of one take are contiguous (bar b ends where bar b + 1 starts, sampled on
//!   the same grid), so the last n − s frames of bar b followed by the first s of bar b + 1 are
//!   the take re-cut at a phase shifted by s/n of a bar: real dance, at the take's real timing,
//!   with no seam. Shifts by whole beats come first (the counts stay on beats), then by half
//!   beats, then by single frames, each tier in a seeded random order.
//!
//! Every segment of the result, the originals included, gets its Eros features and boundary
//! data recomputed from its motion by forward kinematics on the model's reference body
//! (`humanoid24` at 1.70 m; the database keeps no source body), so that an original and its
//! variants compare on equal terms. Its intensity is the time average of W(f) (eq. 2) recomputed
//! on those frames and scaled per source bar by the factor that gives the original bar its own
//! stored intensity (measured at the clip's native frame rate), so an unshifted original keeps
//! its intensity exactly. The database's Eros weights are recomputed over all segments. (Eros
//! compares principal axes rank by rank, so it is sensitive to the body: on the shared dance
//! clips an original's axes on the reference body and on its own can be as far apart as an Eros
//! of 0.46; keeping the stored features of the originals would make a variant differ from its
//! own source mostly by the body.) Segments are described in parallel; the result does not
//! depend on the number of threads.

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_pcg::Pcg64;
use rayon::prelude::*;

use super::database::Database;
use super::eros::{Pca, eros_weights, pca};
use super::features::{mirror_partners, motion_intensity, pose_rows};
use super::segments::{Segment, boundary, leading_axes};
use crate::humanoid::{Figure, FigureClip, humanoid24};

/// How a segment of an augmented database was made from a segment of the source database.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Variant {
    /// Index of the source segment (the bar the variant starts in).
    pub source: usize,
    /// Whether it is the mirror image.
    pub mirrored: bool,
    /// Frames the bar is shifted later by (0 for none; into the next bar of the take).
    pub shift_frames: usize,
}

/// An augmented database and how each of its segments was made.
#[derive(Debug, Clone)]
pub struct Augmented {
    /// The database.
    pub database: Database,
    /// One per segment of the database.
    pub variants: Vec<Variant>,
}

/// For every DOF of `model`, the DOF its angle goes to in the mirror image and the sign it takes
/// there (module docs).
pub fn mirror_dofs(model: &Figure) -> Vec<(usize, f64)> {
    let names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let partners = mirror_partners(&names);
    model
        .dofs
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let j = d.joint;
            let k = model.joints[j]
                .dofs
                .iter()
                .position(|&x| x == i)
                .unwrap_or(0);
            let to = model.joints[partners[j]].dofs.get(k).copied().unwrap_or(0);
            let a = d.axis;
            let image = glam::DVec3::new(a.x, -a.y, -a.z);
            let sign = if image.dot(model.dofs[to].axis) < 0.0 {
                -1.0
            } else {
                1.0
            };
            (to, sign)
        })
        .collect()
}

/// The mirror image of a motion on `clip.model` (module docs).
pub fn mirror_clip(clip: &FigureClip) -> FigureClip {
    let map = mirror_dofs(&clip.model);
    let d = clip.dof_count();
    let mut angles = vec![0.0; clip.angles.len()];
    for (f, row) in clip.angles.chunks_exact(d.max(1)).enumerate() {
        for (i, &(to, sign)) in map.iter().enumerate() {
            angles[f * d + to] = sign * row[i];
        }
    }
    FigureClip {
        model: clip.model.clone(),
        frame_time: clip.frame_time,
        root_translation: clip
            .root_translation
            .iter()
            .map(|t| glam::DVec3::new(-t.x, t.y, t.z))
            .collect(),
        root_rotation: clip
            .root_rotation
            .iter()
            .map(|q| glam::DQuat::from_xyzw(q.x, -q.y, -q.z, q.w))
            .collect(),
        angles,
    }
}

/// Frames `from..from + n` of `clip`.
fn frames(clip: &FigureClip, from: usize, n: usize) -> FigureClip {
    let d = clip.dof_count();
    FigureClip {
        model: clip.model.clone(),
        frame_time: clip.frame_time,
        root_translation: clip.root_translation[from..from + n].to_vec(),
        root_rotation: clip.root_rotation[from..from + n].to_vec(),
        angles: clip.angles[from * d..(from + n) * d].to_vec(),
    }
}

/// The per-frame W(f) of a clip with the weights `alpha` (missing count 1).
fn w_of(clip: &FigureClip, alpha: &[f64]) -> (Vec<f64>, Vec<Vec<glam::DVec3>>) {
    let points = clip.to_clip().point_frames();
    let a: Vec<f64> = (0..points.first().map_or(0, |p| p.len()))
        .map(|i| alpha.get(i).copied().unwrap_or(1.0))
        .collect();
    (motion_intensity(&points, 1.0 / clip.frame_time, &a), points)
}

/// Everything of a [`Segment`] that follows from its motion, recomputed for `clip` (one bar);
/// `scale[f]` multiplies W at frame f (module docs).
fn describe(
    clip: &FigureClip,
    like: &Segment,
    start_s: f64,
    scale: &[f64],
    alpha: &[f64],
    axes: usize,
) -> Segment {
    let (w, points) = w_of(clip, alpha);
    let n = w.len().max(1);
    let intensity = w.iter().zip(scale).map(|(w, c)| w * c).sum::<f64>() / n as f64;
    let parents = clip.model.skeleton().point_parents();
    let fps = 1.0 / clip.frame_time;
    let last = points.len() - 1;
    let (first_directions, first_velocities) =
        boundary(&points, &parents, clip.root_rotation[0], 0, fps);
    let (last_directions, last_velocities) =
        boundary(&points, &parents, clip.root_rotation[last], last, fps);
    Segment {
        clip: like.clip,
        bar: like.bar,
        start_s,
        end_s: start_s + (like.end_s - like.start_s),
        root_translation: clip.root_translation.clone(),
        root_rotation: clip.root_rotation.clone(),
        angles: clip.angles.clone(),
        intensity,
        eros: leading_axes(pca(&pose_rows(&points, 0)), axes),
        first_directions,
        last_directions,
        first_velocities,
        last_velocities,
    }
}

/// Whether segment `k + 1` of `db` continues segment `k` in the same take.
fn continues(db: &Database, k: usize) -> bool {
    let (Some(a), Some(b)) = (db.segments.get(k), db.segments.get(k + 1)) else {
        return false;
    };
    a.clip == b.clip
        && b.bar == a.bar + 1
        && a.frame_count() == b.frame_count()
        && a.frame_count() >= 2
        && (a.end_s - b.start_s).abs() <= 1e-9 * a.end_s.abs().max(1.0)
        && ((a.end_s - a.start_s) - (b.end_s - b.start_s)).abs() <= 1e-9
}

/// A database of `target_segments` segments from `db`'s (module docs): its originals (the first
/// `target_segments` of them when there are more), then mirror images and time offsets in an
/// order fixed by `seed`. When `db` cannot give that many distinct variants (2·n per bar
/// followed by another of its take, 2 per last bar), it gives them all.
pub fn augment(db: &Database, target_segments: usize, seed: u64) -> Database {
    augment_with_variants(db, target_segments, seed).database
}

/// [`augment`], also saying how each segment was made.
pub fn augment_with_variants(db: &Database, target_segments: usize, seed: u64) -> Augmented {
    let model = humanoid24();
    let factors = intensity_factors(db, &model);
    let variants = choose_variants(db, target_segments, seed);
    let segments: Vec<Segment> = variants
        .par_iter()
        .map(|v| variant_segment(db, &model, &factors, v))
        .collect();
    let pcas: Vec<&Pca> = segments.iter().map(|s| &s.eros).collect();
    let weights = eros_weights(&pcas);
    let mut sources = db.sources.clone();
    for (i, src) in sources.iter_mut().enumerate() {
        src.segments = segments.iter().filter(|s| s.clip == i).count();
    }
    Augmented {
        database: Database {
            format_version: db.format_version,
            model: db.model.clone(),
            params: db.params.clone(),
            sources,
            skipped: db.skipped.clone(),
            segments,
            eros_weights: weights,
        },
        variants,
    }
}

/// Each segment's factor from the W recomputed on `model` to its stored intensity.
fn intensity_factors(db: &Database, model: &Figure) -> Vec<f64> {
    let alpha = &db.params.alpha;
    db.segments
        .par_iter()
        .map(|s| {
            let (w, _) = w_of(&s.clip(model), alpha);
            let mean = w.iter().sum::<f64>() / w.len().max(1) as f64;
            if mean > 0.0 { s.intensity / mean } else { 1.0 }
        })
        .collect()
}

/// The `target_segments` variants (module docs): the originals first, then mirror images and
/// time offsets tier by tier (quarter-bar offsets and mirror images, eighth-bar offsets, the
/// rest), each tier shuffled by `seed`.
fn choose_variants(db: &Database, target_segments: usize, seed: u64) -> Vec<Variant> {
    let mut variants: Vec<Variant> = (0..db.segments.len().min(target_segments))
        .map(|source| Variant {
            source,
            mirrored: false,
            shift_frames: 0,
        })
        .collect();
    if target_segments > variants.len() {
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut tiers: [Vec<Variant>; 4] = Default::default();
        for (k, s) in db.segments.iter().enumerate() {
            let n = s.frame_count();
            tiers[0].push(Variant {
                source: k,
                mirrored: true,
                shift_frames: 0,
            });
            if !continues(db, k) {
                continue;
            }
            for shift in 1..n {
                let tier = if (shift * 4) % n == 0 {
                    0
                } else if (shift * 8) % n == 0 {
                    1
                } else {
                    2
                };
                for mirrored in [false, true] {
                    tiers[tier].push(Variant {
                        source: k,
                        mirrored,
                        shift_frames: shift,
                    });
                }
            }
        }
        for t in &mut tiers {
            t.shuffle(&mut rng);
            let room = target_segments - variants.len();
            variants.extend(t.iter().take(room));
        }
    }
    variants
}

/// The segment of variant `v`: its source bar (continued into the next bar by its offset,
/// mirrored if it is), described afresh with the sources' intensity `factors`.
fn variant_segment(db: &Database, model: &Figure, factors: &[f64], v: &Variant) -> Segment {
    let (alpha, axes) = (&db.params.alpha, db.params.eros_axes);
    let s = &db.segments[v.source];
    let n = s.frame_count();
    let bar_s = s.end_s - s.start_s;
    let mut clip = s.clip(model);
    let mut scale = vec![factors[v.source]; n];
    if v.shift_frames > 0 {
        let next = db.segments[v.source + 1].clip(model);
        clip.root_translation.extend(next.root_translation);
        clip.root_rotation.extend(next.root_rotation);
        clip.angles.extend(next.angles);
        clip = frames(&clip, v.shift_frames, n);
        for c in &mut scale[n - v.shift_frames..] {
            *c = factors[v.source + 1];
        }
    }
    if v.mirrored {
        clip = mirror_clip(&clip);
    }
    let start_s = s.start_s + bar_s * v.shift_frames as f64 / n as f64;
    describe(&clip, s, start_s, &scale, alpha, axes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::choreo::features::mirror_motion;
    use glam::{DQuat, DVec3};

    #[test]
    fn humanoid24_limbs_swap_sides_and_the_waist_bend_flips() {
        let m = humanoid24();
        let map = mirror_dofs(&m);
        let idx = |n: &str| m.dof_index(n).unwrap();
        assert_eq!(map[idx("left_knee")], (idx("right_knee"), 1.0));
        assert_eq!(
            map[idx("right_shoulder_rotation")],
            (idx("left_shoulder_rotation"), 1.0)
        );
        assert_eq!(map[idx("waist_flexion")], (idx("waist_flexion"), 1.0));
        assert_eq!(map[idx("waist_lateral")], (idx("waist_lateral"), -1.0));
        // Every axis maps onto its partner's exactly (up to the sign).
        for (i, &(to, sign)) in map.iter().enumerate() {
            let a = m.dofs[i].axis;
            let image = DVec3::new(a.x, -a.y, -a.z) * sign;
            assert!(
                (image - m.dofs[to].axis).length() < 1e-12,
                "{}",
                m.dofs[i].name
            );
        }
    }

    #[test]
    fn the_mirrored_clip_is_the_mirrored_motion() {
        let model = humanoid24();
        let d = model.dofs.len();
        let n = 12;
        let mut angles = vec![0.0; n * d];
        for f in 0..n {
            for i in 0..d {
                angles[f * d + i] = 0.3 * ((f * 7 + i * 3) as f64 * 0.37).sin();
            }
        }
        let clip = FigureClip {
            model: model.clone(),
            frame_time: 1.0 / 30.0,
            root_translation: (0..n)
                .map(|f| DVec3::new(0.3 + 0.05 * f as f64, 0.9, -0.2 * f as f64))
                .collect(),
            root_rotation: (0..n)
                .map(|f| {
                    DQuat::from_rotation_y(0.4 + 0.1 * f as f64)
                        * DQuat::from_rotation_x(0.2)
                        * DQuat::from_rotation_z(-0.15 * f as f64)
                })
                .collect(),
            angles,
        };
        let skel = model.skeleton();
        let partners = mirror_partners(&skel.point_names());
        let want = mirror_motion(&clip.to_clip().point_frames(), &partners);
        let got = mirror_clip(&clip).to_clip().point_frames();
        for (a, b) in want.iter().zip(&got) {
            for (p, q) in a.iter().zip(b) {
                assert!((*p - *q).length() < 1e-9, "{p} {q}");
            }
        }
        // Twice is the clip itself.
        let back = mirror_clip(&mirror_clip(&clip));
        assert_eq!(back.angles, clip.angles);
    }
}
