//! The metrics every dance reports, as the literature defines them.
//!
//! - **Beat alignment score** (AIST++ / FACT, Li et al. 2021, as its `calculate_beat_scores` and
//!   Bailando's evaluation compute it): the mean over the *motion* beats t_x of
//!   exp(−min_y (t_x − t_y)² / (2σ²)) against the music beats t_y, σ = 3 frames at their 60 fps
//!   ([`BAS_SIGMA_S`] = 0.05 s). Motion beats are the local minima of the kinematic speed
//!   v(f) = Σ_i |ẋ_i(f)| ([`super::segments::speed_curve`]) that are lower than every other
//!   frame within ±10 frames at 60 fps (scipy `argrelextrema(order=10)`; ±[`BEAT_ORDER_S`] at the
//!   dance's rate). 1 when every motion beat falls on a music beat, 0 without motion beats.
//! - **Seam jerk**: the angular jerk of the DOF angles, j(f) = (x_{f+2} − 3x_{f+1} + 3x_f −
//!   x_{f−1}) / dt³ per DOF (rad/s³, centred at f + ½), its magnitude the Euclidean norm over
//!   the DOFs; peak and mean over the samples whose stencil touches a seam window (the
//!   rewritten frames and the frame on each side), and the same over every other sample for
//!   scale ("inside").
//! - **Foot skating**: the mean horizontal speed (m/s) of the foot points (the ankles, heels and
//!   toes of [`crate::analysis::foot_points`]) over the frames each is in contact, a point being
//!   in contact as [`crate::analysis::ground_contacts`] finds it (within its threshold of the
//!   height it rests at above the dance's floor, so the mapped ankle that stands 8–12 cm up
//!   counts) and its vertical speed under [`CONTACT_VERTICAL_SPEED_M_S`] (not lifting or
//!   landing). A dance and its source segments all stand on the floor y = 0, so they are
//!   measured against it and against the rest heights of the model standing on it
//!   ([`foot_skating_on_floor`], [`crate::analysis::ground_contacts_against`]): estimated per
//!   motion, a floor found a few centimetres off or an ankle resting on tiptoe would change
//!   what counts as contact from one motion to the next.
//! - **Transition cost**: Σ C over the seams of the fill, and the mean S.
//! - **Foot penetration** (against the floor y = 0 the database stands on): the deepest foot
//!   point, the fraction of frames with a foot point under [`PENETRATION_M`], and in the
//!   frames where a foot is in contact (as for skating, against that floor) the largest
//!   |sole height| of that foot, a foot's sole height being the lowest of its points' heights
//!   less their heights in the model's rest pose standing on the floor
//!   ([`super::feet::rest_sole_heights`]: the toe's 0, the ankle's about 6 cm).
//! - **Intensity correlation**: Spearman's ρ between the music intensity of the bars and the
//!   motion intensity of their segments: the Pearson correlation of their ranks (ties sharing
//!   their mean rank), in [−1, 1].
//! - **Sources**: the same skating and beat alignment of the segments a dance uses, each played
//!   alone at its own timing in its clip (its bar of the clip, at the dance's frame rate, by the
//!   same sampling as the dance) against its own beat grid (the clip's counts: four to a bar),
//!   so that the dance is held against what its material does.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::dance::{Dance, DanceParams, assemble};
use super::database::Database;
use super::fill::Fill;
use super::music::Bar;
use super::segments::{BEATS_PER_BAR, speed_curve};
use crate::analysis::{
    ContactConfig, ContactReference, Contacts, clip_contacts_and_feet, ground_contacts_against,
    point_tracks,
};
use crate::humanoid::FigureClip;

/// σ of the beat alignment score: 3 frames at 60 fps, seconds.
pub const BAS_SIGMA_S: f64 = 3.0 / 60.0;

/// Half-width of the neighbourhood a motion beat is the minimum of: 10 frames at 60 fps, seconds.
pub const BEAT_ORDER_S: f64 = 10.0 / 60.0;

/// A foot point is in contact while its vertical speed is under this, m/s.
pub const CONTACT_VERTICAL_SPEED_M_S: f64 = 0.3;

/// Peak and mean of the angular jerk over a set of samples.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Jerk {
    /// The largest jerk magnitude, rad/s³.
    pub peak_rad_s3: f64,
    /// The mean jerk magnitude, rad/s³.
    pub mean_rad_s3: f64,
    /// The samples it is taken over.
    pub samples: usize,
}

impl Jerk {
    /// Peak and mean of `values` (zeros for none).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Jerk {
        let (mut peak, mut sum, mut n) = (0.0f64, 0.0, 0usize);
        for v in values {
            peak = peak.max(v);
            sum += v;
            n += 1;
        }
        Jerk {
            peak_rad_s3: peak,
            mean_rad_s3: if n > 0 { sum / n as f64 } else { 0.0 },
            samples: n,
        }
    }
}

/// The metrics of a dance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DanceMetrics {
    /// Beat alignment score (AIST++), in [0, 1].
    pub beat_alignment_score: f64,
    /// Motion beats found (kinematic speed minima).
    pub motion_beats: usize,
    /// Music beats within the dance.
    pub music_beats: usize,
    /// Angular jerk around the seams.
    pub seam_jerk: Jerk,
    /// Angular jerk inside the segments, away from the seams.
    pub inside_jerk: Jerk,
    /// Mean horizontal foot speed while in contact, m/s.
    pub foot_skating_m_s: f64,
    /// Fraction of foot-point samples in contact.
    pub foot_contact_fraction: f64,
    /// How far the feet go into the floor.
    pub foot_penetration: FootPenetration,
    /// Σ C over the seams.
    pub transition_cost: f64,
    /// Mean connection score S over the seams (0 without seams).
    pub mean_connection_s: f64,
}

/// A foot point under this height counts as in the floor, metres (−1 cm).
pub const PENETRATION_M: f64 = -0.01;

/// How far a motion's feet go into the floor y = 0 (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct FootPenetration {
    /// The lowest height of a foot point over the motion, metres (negative: in the floor).
    pub deepest_m: f64,
    /// Fraction of frames in which some foot point is under [`PENETRATION_M`].
    pub frames_below_fraction: f64,
    /// The largest |sole height| of a foot in contact, metres.
    pub contact_sole_max_m: f64,
    /// Frames × feet in contact.
    pub contact_foot_frames: usize,
    /// Fraction of the frames × feet in contact whose sole height is within ±1 cm
    /// (|[`PENETRATION_M`]|) of the floor (1 without contact).
    pub contact_within_1cm_fraction: f64,
}

/// The foot penetration of a clip against the floor y = 0 (module docs); zeros for a clip
/// without feet.
pub fn foot_penetration(clip: &FigureClip) -> FootPenetration {
    let n = clip.frame_count();
    let Some((contacts, feet)) = floor_contacts(clip) else {
        return FootPenetration::default();
    };
    if n == 0 {
        return FootPenetration::default();
    }
    let rest = super::feet::rest_sole_heights(clip);
    let mut out = FootPenetration {
        deepest_m: f64::INFINITY,
        ..FootPenetration::default()
    };
    let (mut below, mut within) = (0usize, 0usize);
    for (f, (left, right)) in feet[0].iter().zip(&feet[1]).enumerate().take(n) {
        let mut lowest = f64::INFINITY;
        for (side, spans) in [&contacts.left, &contacts.right].into_iter().enumerate() {
            let pts = if side == 0 { left } else { right };
            lowest = pts.iter().map(|p| p.y).fold(lowest, f64::min);
            let t = f as f64 * clip.frame_time;
            if spans
                .iter()
                .any(|s| t >= s.start_s - 1e-9 && t < s.end_s - 1e-9)
            {
                let sole = pts
                    .iter()
                    .zip(&rest[side])
                    .map(|(p, r)| p.y - r)
                    .fold(f64::INFINITY, f64::min);
                out.contact_sole_max_m = out.contact_sole_max_m.max(sole.abs());
                out.contact_foot_frames += 1;
                if sole.abs() <= -PENETRATION_M {
                    within += 1;
                }
            }
        }
        out.deepest_m = out.deepest_m.min(lowest);
        if lowest < PENETRATION_M {
            below += 1;
        }
    }
    out.frames_below_fraction = below as f64 / n as f64;
    out.contact_within_1cm_fraction = if out.contact_foot_frames == 0 {
        1.0
    } else {
        within as f64 / out.contact_foot_frames as f64
    };
    out
}

/// Spearman's rank correlation of `a` and `b` (module docs); 0 when either is constant or
/// they hold fewer than two pairs.
pub fn spearman(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n < 2 {
        return 0.0;
    }
    let (ra, rb) = (
        super::relevance::percentile_ranks(&a[..n]),
        super::relevance::percentile_ranks(&b[..n]),
    );
    let mean = |r: &[f64]| r.iter().sum::<f64>() / n as f64;
    let (ma, mb) = (mean(&ra), mean(&rb));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in ra.iter().zip(&rb) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa <= 0.0 || sbb <= 0.0 {
        0.0
    } else {
        sab / (saa * sbb).sqrt()
    }
}

/// What the segments of a dance do alone (module docs): skating and beat alignment.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SourceMetrics {
    /// Mean horizontal speed of the foot points in contact, over every segment's contact
    /// samples, m/s.
    pub foot_skating_m_s: f64,
    /// Mean over the segments of their beat alignment score against their own counts.
    pub beat_alignment_score: f64,
    /// Fraction of every segment's frames × feet in contact whose sole is within ±1 cm of the
    /// floor ([`FootPenetration::contact_within_1cm_fraction`], as assembled, feet not
    /// planted).
    pub contact_within_1cm_fraction: f64,
    /// Segments measured.
    pub segments: usize,
}

/// The metrics of database segments `segments` each played alone at its own timing at `fps`
/// frames per second (module docs); a segment too short to assemble at that rate is left out.
pub fn source_metrics(db: &Database, segments: &[usize], fps: f64) -> SourceMetrics {
    let params = DanceParams {
        fps,
        seam_frames: 0,
        beat_warp: false,
        seam: super::dance::Seam::Spline,
    };
    let (mut skate_sum, mut skate_n, mut bas_sum, mut count) = (0.0, 0.0, 0.0, 0usize);
    let (mut within, mut contact_frames) = (0.0, 0usize);
    for &s in segments {
        let Some(seg) = db.segments.get(s) else {
            continue;
        };
        let len = seg.end_s - seg.start_s;
        let bar = Bar {
            start_s: 0.0,
            end_s: len,
            rms: 0.0,
            rms_db: f64::NEG_INFINITY,
        };
        let Ok(alone) = assemble(db, &[s], std::slice::from_ref(&bar), &[], &params) else {
            continue;
        };
        let (skating, contact) = foot_skating_on_floor(&alone.clip);
        let samples = contact * alone.clip.frame_count() as f64;
        skate_sum += skating * samples;
        skate_n += samples;
        let pen = foot_penetration(&alone.clip);
        within += pen.contact_within_1cm_fraction * pen.contact_foot_frames as f64;
        contact_frames += pen.contact_foot_frames;
        // Its own counts: four to the bar, the first at its start.
        let counts = super::segments::Beat {
            tempo_bpm: 60.0 * BEATS_PER_BAR as f64 / len,
            first_beat_s: 0.0,
            source: super::segments::TempoSource::Manifest,
        };
        bas_sum += source_beat_alignment(&alone.clip, &counts);
        count += 1;
    }
    SourceMetrics {
        foot_skating_m_s: if skate_n > 0.0 {
            skate_sum / skate_n
        } else {
            0.0
        },
        beat_alignment_score: if count > 0 {
            bas_sum / count as f64
        } else {
            0.0
        },
        contact_within_1cm_fraction: if contact_frames > 0 {
            within / contact_frames as f64
        } else {
            1.0
        },
        segments: count,
    }
}

/// The motion beats of a clip (module docs), seconds from its first frame.
pub fn motion_beats(clip: &FigureClip) -> Vec<f64> {
    let fps = 1.0 / clip.frame_time;
    let v = speed_curve(&clip.to_clip().point_frames(), fps);
    let order = ((BEAT_ORDER_S * fps).round() as usize).max(1);
    (0..v.len())
        .filter(|&f| {
            let lo = f.saturating_sub(order);
            let hi = (f + order).min(v.len() - 1);
            f >= order && f + order < v.len() && (lo..=hi).all(|g| g == f || v[f] < v[g])
        })
        .map(|f| f as f64 * clip.frame_time)
        .collect()
}

/// The beat alignment score of AIST++: mean over `motion_s` of exp(−min (t − t_music)² / 2σ²)
/// (module docs); 0 without motion or music beats.
pub fn beat_alignment_score(motion_s: &[f64], music_s: &[f64], sigma_s: f64) -> f64 {
    if motion_s.is_empty() || music_s.is_empty() {
        return 0.0;
    }
    let sum: f64 = motion_s
        .iter()
        .map(|t| {
            let d = music_s
                .iter()
                .map(|m| (t - m).abs())
                .fold(f64::INFINITY, f64::min);
            (-d * d / (2.0 * sigma_s * sigma_s)).exp()
        })
        .sum();
    sum / motion_s.len() as f64
}

/// The angular jerk magnitude of every sample f = 1 .. frames − 2 (index f − 1), rad/s³.
pub fn angular_jerk(clip: &FigureClip) -> Vec<f64> {
    let n = clip.frame_count();
    let dt3 = clip.frame_time.powi(3);
    if n < 4 {
        return vec![];
    }
    (1..n - 2)
        .map(|f| {
            let (a, b, c, d) = (
                clip.frame_angles(f - 1),
                clip.frame_angles(f),
                clip.frame_angles(f + 1),
                clip.frame_angles(f + 2),
            );
            let s: f64 = (0..a.len())
                .map(|j| {
                    let x = (d[j] - 3.0 * c[j] + 3.0 * b[j] - a[j]) / dt3;
                    x * x
                })
                .sum();
            s.sqrt()
        })
        .collect()
}

/// Seam and inside jerk of a dance (module docs).
pub fn seam_jerk(dance: &Dance) -> (Jerk, Jerk) {
    let j = angular_jerk(&dance.clip);
    let w = dance.seam_frames;
    // Frames touched by a seam: the window [s − w, s + w) and the frame on each side.
    let near = |f: usize| -> bool {
        dance
            .seam_frame_indices()
            .iter()
            .any(|&s| f + w + 1 >= s && f <= s + w)
    };
    let (mut seam, mut inside) = (vec![], vec![]);
    for (i, &v) in j.iter().enumerate() {
        let f = i + 1; // stencil f − 1 ..= f + 2
        if (f - 1..=f + 2).any(near) {
            seam.push(v);
        } else {
            inside.push(v);
        }
    }
    (Jerk::of(seam), Jerk::of(inside))
}

/// Foot skating of a clip: (mean horizontal speed in contact m/s, contact fraction of the
/// foot points' frames) (module docs), the floor and rest heights estimated from the clip.
pub fn foot_skating(clip: &FigureClip) -> (f64, f64) {
    let c = clip.to_clip();
    match clip_contacts_and_feet(&c, &ContactConfig::default()) {
        Some((contacts, feet)) => skating(clip, &contacts, &feet),
        None => (0.0, 0.0),
    }
}

/// [`foot_skating`] against the floor y = 0 and the rest heights of the model standing on it
/// ([`super::feet::rest_sole_heights`]): the measure of a dance and of its source segments,
/// which all stand on that floor, so that one floor and one standard judge them all.
pub fn foot_skating_on_floor(clip: &FigureClip) -> (f64, f64) {
    match floor_contacts(clip) {
        Some((contacts, feet)) => skating(clip, &contacts, &feet),
        None => (0.0, 0.0),
    }
}

/// The contacts of `clip`'s feet against the floor y = 0 and the model's standing rest heights
/// ([`ground_contacts_against`]), and the foot points' tracks; `None` without feet.
pub fn floor_contacts(clip: &FigureClip) -> Option<(Contacts, [Vec<Vec<DVec3>>; 2])> {
    let c = clip.to_clip();
    let [lf, rf] = crate::analysis::foot_points(&c.skeleton);
    if lf.is_empty() || rf.is_empty() {
        return None;
    }
    let feet = [point_tracks(&c, &lf), point_tracks(&c, &rf)];
    let reference = ContactReference {
        floor_y_m: 0.0,
        rest_heights_m: super::feet::rest_sole_heights(clip)
            .map(|v| v.into_iter().map(Some).collect()),
    };
    let contacts = ground_contacts_against(
        &feet[0],
        &feet[1],
        &[],
        clip.frame_time,
        &ContactConfig::default(),
        &reference,
    );
    Some((contacts, feet))
}

/// Skating of the foot tracks `feet` under `contacts` (module docs).
fn skating(clip: &FigureClip, contacts: &Contacts, feet: &[Vec<Vec<DVec3>>; 2]) -> (f64, f64) {
    let n = clip.frame_count();
    if n < 2 {
        return (0.0, 0.0);
    }
    let fps = 1.0 / clip.frame_time;
    let (mut sum, mut contact, mut total) = (0.0, 0usize, 0usize);
    for (track, rests) in feet.iter().zip(&contacts.rest_heights_m) {
        for (i, rest) in rests.iter().enumerate() {
            for f in 0..n {
                total += 1;
                let Some(rest) = rest else { continue };
                let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
                let v: DVec3 = (track[b][i] - track[a][i]) * (fps / (b - a) as f64);
                let height = track[f][i].y - contacts.floor_y_m;
                if height < rest + contacts.threshold_m && v.y.abs() < CONTACT_VERTICAL_SPEED_M_S {
                    contact += 1;
                    sum += DVec3::new(v.x, 0.0, v.z).length();
                }
            }
        }
    }
    let skating = if contact > 0 {
        sum / contact as f64
    } else {
        0.0
    };
    (skating, contact as f64 / total.max(1) as f64)
}

/// Every metric of a dance against the song's beats `beats_s` (song time, seconds) and the fill
/// it was assembled from.
pub fn dance_metrics(dance: &Dance, beats_s: &[f64], fill: &Fill) -> DanceMetrics {
    let duration = dance.clip.frame_count() as f64 * dance.clip.frame_time;
    let music: Vec<f64> = beats_s
        .iter()
        .map(|t| t - dance.start_s)
        .filter(|t| (0.0..=duration).contains(t))
        .collect();
    let motion = motion_beats(&dance.clip);
    let (seam, inside) = seam_jerk(dance);
    let (skating, contact) = foot_skating_on_floor(&dance.clip);
    let seams = fill.connections.len();
    DanceMetrics {
        beat_alignment_score: beat_alignment_score(&motion, &music, BAS_SIGMA_S),
        motion_beats: motion.len(),
        music_beats: music.len(),
        seam_jerk: seam,
        inside_jerk: inside,
        foot_skating_m_s: skating,
        foot_contact_fraction: contact,
        foot_penetration: foot_penetration(&dance.clip),
        transition_cost: fill.total_cost,
        mean_connection_s: if seams > 0 {
            fill.connections.iter().map(|c| c.s).sum::<f64>() / seams as f64
        } else {
            0.0
        },
    }
}

/// The beat alignment score of a source clip on its own beat: [`beat_alignment_score`] of its
/// [`motion_beats`] against its kinematic beat grid t_k = first_beat_s + k · 60 / tempo_bpm (every
/// k with t_k within the clip, k < 0 included), σ = [`BAS_SIGMA_S`]; what the dance's own score is
/// measured against. 0 for a tempo that is not a positive number of BPM, a beat shorter than a
/// frame, or a clip without motion beats.
pub fn source_beat_alignment(clip: &FigureClip, beat: &super::segments::Beat) -> f64 {
    let period = 60.0 / beat.tempo_bpm;
    if !(period.is_finite() && period >= clip.frame_time && beat.first_beat_s.is_finite()) {
        return 0.0;
    }
    let duration = clip.frame_count() as f64 * clip.frame_time;
    let k0 = -(beat.first_beat_s / period).floor();
    let grid: Vec<f64> = (0..=clip.frame_count())
        .map(|k| beat.first_beat_s + (k0 + k as f64) * period)
        .take_while(|&t| t <= duration)
        .filter(|&t| t >= 0.0)
        .collect();
    beat_alignment_score(&motion_beats(clip), &grid, BAS_SIGMA_S)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beats_on_the_music_score_one_and_off_beat_less() {
        let music: Vec<f64> = (0..16).map(|k| 0.5 * k as f64).collect();
        assert!((beat_alignment_score(&music, &music, BAS_SIGMA_S) - 1.0).abs() < 1e-12);
        let late: Vec<f64> = music.iter().map(|t| t + 0.05).collect();
        let s = beat_alignment_score(&late, &music, BAS_SIGMA_S);
        assert!((s - (-0.5f64).exp()).abs() < 1e-9, "{s}");
        assert_eq!(beat_alignment_score(&[], &music, BAS_SIGMA_S), 0.0);
    }

    /// humanoid24 standing still (angles 0) for 2 s at 60 fps, its pelvis at `y` and gliding
    /// along x at `speed` m/s.
    fn gliding(y: f64, speed: f64) -> FigureClip {
        let model = crate::humanoid::humanoid24();
        let d = model.dofs.len();
        let n = 120;
        FigureClip {
            model,
            frame_time: 1.0 / 60.0,
            root_translation: (0..n)
                .map(|f| DVec3::new(speed * f as f64 / 60.0, y, 0.0))
                .collect(),
            root_rotation: vec![glam::DQuat::IDENTITY; n],
            angles: vec![0.0; n * d],
        }
    }

    #[test]
    fn foot_skating_is_the_speed_of_planted_feet_wherever_the_floor_is() {
        for y in [0.95, 0.6, 1.4] {
            let (still, contact) = foot_skating(&gliding(y, 0.0));
            assert!(still.abs() < 1e-12, "standing still skates {still} m/s");
            assert!(
                (contact - 1.0).abs() < 1e-12,
                "every foot point touches: {contact}"
            );
            let (glide, contact) = foot_skating(&gliding(y, 0.2));
            assert!((glide - 0.2).abs() < 1e-9, "pelvis at {y} m: {glide} m/s");
            assert!((contact - 1.0).abs() < 1e-12, "{contact}");
        }
    }

    #[test]
    fn feet_in_contact_count_as_on_the_floor_within_a_centimetre_only() {
        // The pelvis height at which the soles stand on y = 0.
        let standing = -foot_penetration(&gliding(0.0, 0.0)).deepest_m;
        let on = foot_penetration(&gliding(standing, 0.0));
        assert!(
            on.contact_foot_frames > 0 && on.deepest_m.abs() < 1e-9,
            "{on:?}"
        );
        assert_eq!(on.contact_within_1cm_fraction, 1.0);
        // 2 cm up: still in contact (within the analysis's 3 cm), not within 1 cm.
        let hovering = foot_penetration(&gliding(standing + 0.02, 0.0));
        assert_eq!(hovering.contact_foot_frames, on.contact_foot_frames);
        assert_eq!(hovering.contact_within_1cm_fraction, 0.0);
        assert!((hovering.contact_sole_max_m - 0.02).abs() < 1e-9);
    }

    #[test]
    fn jerk_of_a_cubic_is_its_third_derivative() {
        let model = crate::humanoid::humanoid24();
        let d = model.dofs.len();
        let fps = 100.0;
        let n = 50;
        let mut angles = vec![0.0; n * d];
        for f in 0..n {
            let t = f as f64 / fps;
            angles[f * d] = 2.0 * t * t * t; // x''' = 12
        }
        let clip = FigureClip {
            model,
            frame_time: 1.0 / fps,
            root_translation: vec![DVec3::ZERO; n],
            root_rotation: vec![glam::DQuat::IDENTITY; n],
            angles,
        };
        for j in angular_jerk(&clip) {
            assert!((j - 12.0).abs() < 1e-6, "{j}");
        }
    }
}
