//! Ballistic flight of the whole-body centre of mass. In the air only gravity acts on a body, so
//! its centre of mass follows `c(t) = c_a + v (t − a) + ½ g (t − a)²` (g = (0, −[`GRAVITY`], 0))
//! whatever the limbs do, while the pelvis moves against the limbs' swing. The centre of mass is
//! that of the articulated body the engine simulates ([`crate::humanoid::human_body`]:
//! links and masses from the anthropometric table), so a flight made ballistic here asks the
//! simulated body for no external force but gravity.

use glam::DVec3;

use super::GRAVITY;
use crate::dynamics::Data;
use crate::dynamics::kinematics;
use crate::humanoid::FigureClip;
use crate::humanoid::{HumanBody, HumanError, human_body};

/// Nominal mass of the body whose centre of mass is taken, kg (the centre of mass does not
/// depend on it: the table gives every link a fixed share of the mass).
const NOMINAL_MASS_KG: f64 = 65.0;

/// Standing height the body is built at, metres: the table scales every length with the height
/// and gives every link a fixed share of the mass, so the centre of mass of a figure of height
/// h is this body's scaled by h / [`REFERENCE_HEIGHT_M`] (any figure size a clip may have).
const REFERENCE_HEIGHT_M: f64 = 1.70;

/// Whole-body centre of mass of every frame of `clip` (world, metres):
/// `c = r + (h/h₀) Σ m_i (p_i + R_i c_i) / Σ m_i` over the links of the body of its model built
/// at height h₀ = [`REFERENCE_HEIGHT_M`] with its root at the origin, r the clip's root and h its
/// model's height. Fails only for a model whose root is not a free pelvis.
pub fn centre_of_mass_track(clip: &FigureClip) -> Result<Vec<DVec3>, HumanError> {
    let body: HumanBody = human_body(&clip.model, REFERENCE_HEIGHT_M, NOMINAL_MASS_KG, GRAVITY)?;
    let scale = clip.model.height / REFERENCE_HEIGHT_M;
    let mut data = Data::new(&body.model);
    let v = vec![0.0; body.model.nv()];
    let total = body.model.total_mass();
    Ok((0..clip.frame_count())
        .map(|f| {
            let q = body.configuration(clip.frame_angles(f), DVec3::ZERO, clip.root_rotation[f]);
            kinematics(&body.model, &mut data, &q, &v);
            let offset = body
                .model
                .bodies()
                .iter()
                .enumerate()
                .map(|(i, b)| b.inertia.mass * (data.pos[i] + data.rot[i] * b.inertia.com))
                .sum::<DVec3>()
                / total;
            clip.root_translation[f] + scale * offset
        })
        .collect())
}

/// Makes each flight `(take_off_s, landing_s)` of `clip` ballistic: between the frames nearest
/// take-off and landing the root is moved (the joint angles and orientation kept) so that the
/// centre of mass follows the parabola under gravity through its positions at those two frames,
/// `c(t) = c_a + (c_b − c_a)(t − a)/T + ½ g (t − a)(t − b)` with T = b − a (straight and uniform
/// horizontally). Returns the largest root displacement, metres.
pub fn make_flights_ballistic(
    clip: &mut FigureClip,
    flights: &[(f64, f64)],
) -> Result<f64, HumanError> {
    let com = centre_of_mass_track(clip)?;
    let n = com.len();
    let dt = clip.frame_time;
    let frame = |t: f64| ((t / dt).round().max(0.0) as usize).min(n.saturating_sub(1));
    let mut largest: f64 = 0.0;
    for &(a, b) in flights {
        let (fa, fb) = (frame(a), frame(b));
        if fb <= fa + 1 {
            continue;
        }
        let (ta, tb) = (fa as f64 * dt, fb as f64 * dt);
        let (ca, cb) = (com[fa], com[fb]);
        let root = &mut clip.root_translation[fa + 1..fb];
        for (k, (r, c)) in (fa + 1..).zip(root.iter_mut().zip(&com[fa + 1..fb])) {
            let t = k as f64 * dt;
            let u = (t - ta) / (tb - ta);
            let arc = ca.lerp(cb, u) + DVec3::new(0.0, -0.5 * GRAVITY * (t - ta) * (t - tb), 0.0);
            let shift = arc - *c;
            *r += shift;
            largest = largest.max(shift.length());
        }
    }
    Ok(largest)
}

/// The largest downward pull the centre-of-mass motion of `clip` needs, in body weights:
/// `max(−(c̈_y + g))/g` over the frames, `c̈` the centred second difference of
/// [`centre_of_mass_track`] (a floor only pushes up, so a motion a body can make has ≤ 0),
/// with the time (s) where it is largest.
pub fn max_downward_pull_bw(clip: &FigureClip) -> Result<(f64, f64), HumanError> {
    let com = centre_of_mass_track(clip)?;
    let dt = clip.frame_time;
    let mut worst = (f64::NEG_INFINITY, 0.0);
    for k in 1..com.len().saturating_sub(1) {
        let acc = (com[k + 1].y - 2.0 * com[k].y + com[k - 1].y) / (dt * dt);
        let pull = -(acc + GRAVITY) / GRAVITY;
        if pull > worst.0 {
            worst = (pull, k as f64 * dt);
        }
    }
    Ok(worst)
}
