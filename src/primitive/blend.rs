//! Primitive blending (the paper's §3): two primitives A and B placed on the time line
//! (t_As, t_Ae, t_Bs, t_Be; B ends first, t_Be ≤ t_Ae; they overlap) are time-scaled to their
//! spans, rolled out, mixed on the overlap by
//! `θ_new(t) = γ(t′)θ_A(t) + (1 − γ(t′))θ_B(t)`,
//! `t′ = (t − max(t_As, t_Bs)) / (min(t_Ae, t_Be) − max(t_As, t_Bs))`,
//! taken from whichever of A or B is defined outside the overlap (θ_new lives on
//! [min(t_As, t_Bs), t_Ae]), and learned again as one primitive or as two split at t_Be.
//! A constant γ in [0, 1] interpolates, outside [0, 1] it extrapolates.

use serde::{Deserialize, Serialize};

use super::error::{PrimitiveError, Result, require_finite, require_positive};
use super::learn::LearnConfig;
use super::primitive::{Learned, Primitive};
use super::rollout::Samples;
use super::trajectory::Trajectory;

/// Times (seconds) closer than this count as equal when classifying an arrangement.
const TIME_EPS: f64 = 1e-9;

/// Where A and B sit on the time line, seconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlendPlacement {
    /// t_As.
    pub a_start: f64,
    /// t_Ae.
    pub a_end: f64,
    /// t_Bs.
    pub b_start: f64,
    /// t_Be (≤ t_Ae).
    pub b_end: f64,
}

/// The paper's six arrangements (Fig. 6): when B starts relative to A × whether it ends before A
/// or with A.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Arrangement {
    /// t_Bs < t_As, t_Be < t_Ae.
    StartsBeforeEndsBefore,
    /// t_Bs < t_As, t_Be = t_Ae.
    StartsBeforeEndsTogether,
    /// t_Bs = t_As, t_Be < t_Ae.
    StartsTogetherEndsBefore,
    /// t_Bs = t_As, t_Be = t_Ae (the high-jump extrapolation).
    StartsTogetherEndsTogether,
    /// t_Bs > t_As, t_Be < t_Ae (the jumping knee kick).
    StartsAfterEndsBefore,
    /// t_Bs > t_As, t_Be = t_Ae.
    StartsAfterEndsTogether,
}

impl Arrangement {
    /// True if B ends before A (the arrangements that can be split at t_Be).
    pub fn b_ends_first(self) -> bool {
        matches!(
            self,
            Arrangement::StartsBeforeEndsBefore
                | Arrangement::StartsTogetherEndsBefore
                | Arrangement::StartsAfterEndsBefore
        )
    }
}

impl BlendPlacement {
    /// Classifies the placement; errors if a span is empty, t_Be > t_Ae, or A and B do not
    /// overlap.
    pub fn arrangement(&self) -> Result<Arrangement> {
        require_finite(
            "placement",
            &[self.a_start, self.a_end, self.b_start, self.b_end],
        )?;
        if self.a_end - self.a_start <= TIME_EPS {
            return Err(PrimitiveError::InvalidPlacement {
                reason: format!("A's span [{}, {}] is empty", self.a_start, self.a_end),
            });
        }
        if self.b_end - self.b_start <= TIME_EPS {
            return Err(PrimitiveError::InvalidPlacement {
                reason: format!("B's span [{}, {}] is empty", self.b_start, self.b_end),
            });
        }
        if self.b_end > self.a_end + TIME_EPS {
            return Err(PrimitiveError::InvalidPlacement {
                reason: format!(
                    "B must not end after A (t_Be = {} > t_Ae = {}); swap A and B",
                    self.b_end, self.a_end
                ),
            });
        }
        let (o0, o1) = self.overlap();
        if o1 - o0 <= TIME_EPS {
            return Err(PrimitiveError::InvalidPlacement {
                reason: format!(
                    "A [{}, {}] and B [{}, {}] do not overlap",
                    self.a_start, self.a_end, self.b_start, self.b_end
                ),
            });
        }
        let ends_together = (self.b_end - self.a_end).abs() <= TIME_EPS;
        let ds = self.b_start - self.a_start;
        Ok(match (ds.abs() <= TIME_EPS, ds < 0.0, ends_together) {
            (true, _, false) => Arrangement::StartsTogetherEndsBefore,
            (true, _, true) => Arrangement::StartsTogetherEndsTogether,
            (false, true, false) => Arrangement::StartsBeforeEndsBefore,
            (false, true, true) => Arrangement::StartsBeforeEndsTogether,
            (false, false, false) => Arrangement::StartsAfterEndsBefore,
            (false, false, true) => Arrangement::StartsAfterEndsTogether,
        })
    }

    /// The overlap [max(t_As, t_Bs), min(t_Ae, t_Be)].
    pub fn overlap(&self) -> (f64, f64) {
        (self.a_start.max(self.b_start), self.a_end.min(self.b_end))
    }

    /// The span of the blend, [min(t_As, t_Bs), t_Ae].
    pub fn span(&self) -> (f64, f64) {
        (self.a_start.min(self.b_start), self.a_end)
    }
}

/// The range every value of γ must lie in, `[GAMMA_MIN, GAMMA_MAX]` = [−2, 3]: interpolation
/// (γ ∈ [0, 1]) and extrapolation up to twice the difference between A and B beyond either of
/// them. Farther out the blend is dominated by the difference itself (γ = −2 already asks for
/// 3·B − 2·A: a 110° and a 70° crouch give 190°, past any knee), and a γ of 10⁶ gives DMP
/// weights a million times those of the demonstrations.
pub const GAMMA_MIN: f64 = -2.0;

/// See [`GAMMA_MIN`].
pub const GAMMA_MAX: f64 = 3.0;

/// The blend ratio γ(t′) over the normalised overlap time t′ ∈ [0, 1] (clamped outside).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Gamma {
    /// γ constant: in [0, 1] interpolation, outside extrapolation (the high jump uses −0.5).
    Constant(f64),
    /// γ = from + (to − from)·t′ (the jumping knee kick uses from 1 to 0: γ = 1 − t′).
    Ramp {
        /// γ(0).
        from: f64,
        /// γ(1).
        to: f64,
    },
    /// γ = from + (to − from)·(3t′² − 2t′³): a ramp with zero slope at both ends.
    Smoothstep {
        /// γ(0).
        from: f64,
        /// γ(1).
        to: f64,
    },
    /// Linear between (t′, γ) knots with strictly increasing t′, constant beyond the end knots.
    PiecewiseLinear(Vec<(f64, f64)>),
}

impl Gamma {
    /// Checks: finite values in [[`GAMMA_MIN`], [`GAMMA_MAX`]]; piecewise-linear knots non-empty
    /// with strictly increasing t′.
    pub fn validate(&self) -> Result<()> {
        let in_range = |field: &str, values: &[f64]| -> Result<()> {
            require_finite(field, values)?;
            match values
                .iter()
                .find(|g| !(GAMMA_MIN..=GAMMA_MAX).contains(*g))
            {
                Some(g) => Err(PrimitiveError::InvalidParameter {
                    field: field.into(),
                    reason: format!(
                        "γ = {g} is outside the allowed range [{GAMMA_MIN}, {GAMMA_MAX}] \
                         (interpolation is [0, 1]; extrapolation goes at most twice the \
                         difference between the two primitives beyond either)"
                    ),
                }),
                None => Ok(()),
            }
        };
        match self {
            Gamma::Constant(g) => in_range("gamma", &[*g]),
            Gamma::Ramp { from, to } | Gamma::Smoothstep { from, to } => {
                in_range("gamma", &[*from, *to])
            }
            Gamma::PiecewiseLinear(k) => {
                if k.is_empty() {
                    return Err(PrimitiveError::InvalidParameter {
                        field: "gamma".into(),
                        reason: "piecewise-linear γ needs at least one knot".into(),
                    });
                }
                for (i, (t, g)) in k.iter().enumerate() {
                    require_finite(&format!("gamma[{i}]"), &[*t])?;
                    in_range(&format!("gamma[{i}]"), &[*g])?;
                    if i > 0 && *t <= k[i - 1].0 {
                        return Err(PrimitiveError::InvalidParameter {
                            field: format!("gamma[{i}]"),
                            reason: format!("t′ = {t} must be greater than the previous knot's"),
                        });
                    }
                }
                Ok(())
            }
        }
    }

    /// A short label for pictures and reports: `γ = −0.5`, `γ = 1 → 0 (ramp)`,
    /// `γ = 0 → 1 (smoothstep)`, `γ piecewise (0, 1) (1, 0)`; minus signs as "−".
    pub fn label(&self) -> String {
        let n = |v: f64| format!("{v}").replace('-', "−");
        match self {
            Gamma::Constant(g) => format!("γ = {}", n(*g)),
            Gamma::Ramp { from, to } => format!("γ = {} → {} (ramp)", n(*from), n(*to)),
            Gamma::Smoothstep { from, to } => {
                format!("γ = {} → {} (smoothstep)", n(*from), n(*to))
            }
            Gamma::PiecewiseLinear(k) => {
                let knots: Vec<String> = k
                    .iter()
                    .map(|(t, g)| format!("({}, {})", n(*t), n(*g)))
                    .collect();
                format!("γ piecewise {}", knots.join(" "))
            }
        }
    }

    /// γ(t′), with t′ clamped to [0, 1].
    pub fn at(&self, t: f64) -> f64 {
        let t = t.clamp(0.0, 1.0);
        match self {
            Gamma::Constant(g) => *g,
            Gamma::Ramp { from, to } => from + (to - from) * t,
            Gamma::Smoothstep { from, to } => from + (to - from) * t * t * (3.0 - 2.0 * t),
            Gamma::PiecewiseLinear(k) => {
                let i = k.partition_point(|(kt, _)| *kt <= t);
                if i == 0 {
                    k[0].1
                } else if i == k.len() {
                    k[k.len() - 1].1
                } else {
                    let (t0, g0) = k[i - 1];
                    let (t1, g1) = k[i];
                    g0 + (g1 - g0) * (t - t0) / (t1 - t0)
                }
            }
        }
    }
}

/// How the blended trajectory is learned again (step 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Relearn {
    /// Keep only the blended trajectory.
    No,
    /// One primitive for the whole span.
    Whole,
    /// Two primitives split at t_Be (only when B ends before A): B's end pose stays adjustable
    /// through the first one's goal; the second is learned from A's course after t_Be (its first
    /// frame is A's pose at t_Be, the right limit of θ_new) and is meant to be connected.
    SplitAtBEnd,
}

/// The result of a blend.
#[derive(Clone, Debug, PartialEq)]
pub struct BlendResult {
    /// Which of the six arrangements the placement is.
    pub arrangement: Arrangement,
    /// Time of the blended trajectory's frame 0 on the blend's time line: min(t_As, t_Bs).
    pub start_time: f64,
    /// θ_new on [min(t_As, t_Bs), t_Ae], uniform frames (dt adjusted so the last frame is t_Ae).
    pub trajectory: Trajectory,
    /// Frame of `trajectory` nearest t_Be.
    pub b_end_frame: usize,
    /// The re-learned primitive(s): none, one, or two (before and after t_Be).
    pub primitives: Vec<Learned>,
}

/// Blends A and B (steps 1–4 of the paper). `dt` is the requested sample step of θ_new (it is
/// shrunk so that the span is a whole number of steps). Errors on different DOF sets, bad
/// placements (see [`BlendPlacement::arrangement`]), a bad γ, or a split where B does not end
/// before A.
pub fn blend(
    a: &Primitive,
    b: &Primitive,
    placement: &BlendPlacement,
    gamma: &Gamma,
    dt: f64,
    relearn: Relearn,
    config: &LearnConfig,
) -> Result<BlendResult> {
    same_dofs(a, b)?;
    require_positive("dt", dt)?;
    gamma.validate()?;
    let arrangement = placement.arrangement()?;
    if relearn == Relearn::SplitAtBEnd && !arrangement.b_ends_first() {
        return Err(PrimitiveError::InvalidPlacement {
            reason: format!("split at t_Be needs B to end before A; {arrangement:?} ends together"),
        });
    }
    // Step 1: place and time-scale.
    let pa = a.with_duration(placement.a_end - placement.a_start)?;
    let pb = b.with_duration(placement.b_end - placement.b_start)?;
    let (t0, t1) = placement.span();
    let n = ((t1 - t0) / dt - 1e-9).ceil().max(1.0) as usize;
    let step = (t1 - t0) / n as f64;
    let times: Vec<f64> = (0..=n)
        .map(|k| t0 + (t1 - t0) * k as f64 / n as f64)
        .collect();

    // Step 2: roll out each over its own span (local times clamped into [0, τ]).
    let ra = RolledOut::roll_out(&pa, &times, placement.a_start, placement.a_end)?;
    let rb = RolledOut::roll_out(&pb, &times, placement.b_start, placement.b_end)?;

    // Step 3: mix on the overlap, copy outside it.
    let values = mix(&times, placement.overlap(), gamma, &ra, &rb);
    let trajectory = Trajectory::new(step, a.names(), values)?;
    let b_end_frame = (((placement.b_end - t0) / step).round() as usize).min(n);

    // Step 4: learn again.
    let name = format!("{}+{}", a.name, b.name);
    let primitives = match relearn {
        Relearn::No => Vec::new(),
        Relearn::Whole => vec![Primitive::learn(&name, &trajectory, config)?],
        Relearn::SplitAtBEnd => split_at_b_end(&name, &trajectory, b_end_frame, n, &ra, config)?,
    };
    Ok(BlendResult {
        arrangement,
        start_time: t0,
        trajectory,
        b_end_frame,
        primitives,
    })
}

/// Errors unless `a` and `b` drive the same DOFs.
fn same_dofs(a: &Primitive, b: &Primitive) -> Result<()> {
    if a.names() != b.names() {
        return Err(PrimitiveError::DofMismatch {
            what: format!(
                "cannot blend `{}` ({} DOFs: {:?}) with `{}` ({} DOFs: {:?}): the DOF sets (models) differ",
                a.name,
                a.dofs.len(),
                a.names(),
                b.name,
                b.dofs.len(),
                b.names()
            ),
        });
    }
    Ok(())
}

/// Whether time `t` lies in the span [s, e] (within [`TIME_EPS`]).
fn in_span(t: f64, s: f64, e: f64) -> bool {
    t >= s - TIME_EPS && t <= e + TIME_EPS
}

/// A primitive rolled out over its span [start, end] of the blend's sample times.
struct RolledOut {
    /// The samples at the blend's times inside the span.
    samples: Samples,
    /// The first of the blend's times inside the span.
    first: usize,
    start: f64,
    end: f64,
    /// DOFs.
    dofs: usize,
}

impl RolledOut {
    /// `p` rolled out at those of `times` in [start, end], local times clamped into [0, τ].
    fn roll_out(p: &Primitive, times: &[f64], start: f64, end: f64) -> Result<RolledOut> {
        let local: Vec<f64> = times
            .iter()
            .filter(|t| in_span(**t, start, end))
            .map(|t| (t - start).clamp(0.0, p.duration))
            .collect();
        let samples = p.sample(&local, None)?;
        let first = times
            .iter()
            .position(|t| in_span(*t, start, end))
            .unwrap_or(0);
        Ok(RolledOut {
            samples,
            first,
            start,
            end,
            dofs: p.dofs.len(),
        })
    }

    /// Whether time `t` lies in the span.
    fn covers(&self, t: f64) -> bool {
        in_span(t, self.start, self.end)
    }

    /// The row of the blend's sample `k` in the samples.
    fn row(&self, k: usize) -> usize {
        k.wrapping_sub(self.first)
    }

    /// The angles at the blend's sample `k`.
    fn frame(&self, k: usize) -> &[f64] {
        let (i, d) = (self.row(k), self.dofs);
        &self.samples.values[i * d..(i + 1) * d]
    }
}

/// θ_new at `times`: γ·A + (1 − γ)·B on the overlap (o0, o1), A or B alone outside it.
fn mix(
    times: &[f64],
    (o0, o1): (f64, f64),
    gamma: &Gamma,
    ra: &RolledOut,
    rb: &RolledOut,
) -> Vec<f64> {
    let d = ra.dofs;
    let mut values = Vec::with_capacity(times.len() * d);
    for (k, t) in times.iter().enumerate() {
        let have_a = ra.covers(*t);
        let have_b = rb.covers(*t);
        let (ia, ib) = (ra.row(k), rb.row(k));
        if have_a && have_b && in_span(*t, o0, o1) {
            let g = gamma.at((t - o0) / (o1 - o0));
            for j in 0..d {
                values.push(g * ra.samples.value(ia, j) + (1.0 - g) * rb.samples.value(ib, j));
            }
        } else if have_a {
            values.extend_from_slice(ra.frame(k));
        } else {
            values.extend_from_slice(rb.frame(k));
        }
    }
    values
}

/// The blend `trajectory` (frames 0 … `n`) learned again as two primitives, up to B's end
/// (frame `b_end_frame`) and after it, the second starting from A's side (`ra`).
fn split_at_b_end(
    name: &str,
    trajectory: &Trajectory,
    b_end_frame: usize,
    n: usize,
    ra: &RolledOut,
    config: &LearnConfig,
) -> Result<Vec<Learned>> {
    if b_end_frame < 3 || n - b_end_frame < 3 {
        return Err(PrimitiveError::InvalidPlacement {
            reason: format!(
                "splitting at t_Be leaves {} and {} frames; each part needs at least 4 (use a smaller dt)",
                b_end_frame + 1,
                n - b_end_frame + 1
            ),
        });
    }
    let d = ra.dofs;
    let first = trajectory.slice_frames(0, b_end_frame)?;
    let mut second = trajectory.slice_frames(b_end_frame, n)?;
    // At t_Be itself θ_new is B's end pose; after it, A alone. The second primitive starts
    // from A's side (the right limit), so it learns A's continuous course; connecting it to
    // the first (see `connect`) pulls B's end state smoothly onto that course.
    second.values[..d].copy_from_slice(ra.frame(b_end_frame));
    Ok(vec![
        Primitive::learn(&format!("{name} (to B's end)"), &first, config)?,
        Primitive::learn(&format!("{name} (after B's end)"), &second, config)?,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_curves_hit_their_ends() {
        assert_eq!(Gamma::Constant(-0.5).at(0.3), -0.5);
        let r = Gamma::Ramp { from: 1.0, to: 0.0 };
        assert!((r.at(0.25) - 0.75).abs() < 1e-15);
        let s = Gamma::Smoothstep { from: 0.0, to: 1.0 };
        assert_eq!((s.at(0.0), s.at(0.5), s.at(1.0)), (0.0, 0.5, 1.0));
        let p = Gamma::PiecewiseLinear(vec![(0.0, 1.0), (0.5, 0.2), (1.0, 0.0)]);
        p.validate().unwrap();
        assert!((p.at(0.25) - 0.6).abs() < 1e-15);
        assert_eq!(p.at(2.0), 0.0);
        assert!(
            Gamma::PiecewiseLinear(vec![(0.5, 1.0), (0.5, 0.0)])
                .validate()
                .is_err()
        );
        assert!(Gamma::PiecewiseLinear(vec![]).validate().is_err());
    }

    #[test]
    fn gamma_outside_its_range_is_refused_with_the_range() {
        for g in [
            Gamma::Constant(1e6),
            Gamma::Constant(-2.5),
            Gamma::Ramp { from: 1.0, to: 4.0 },
            Gamma::PiecewiseLinear(vec![(0.0, 0.0), (1.0, -3.0)]),
        ] {
            let e = g.validate().unwrap_err().to_string();
            assert!(e.contains("[-2, 3]"), "{g:?}: {e}");
        }
        for g in [GAMMA_MIN, GAMMA_MAX, 0.5] {
            Gamma::Constant(g).validate().unwrap();
        }
        assert_eq!(Gamma::Constant(-0.5).label(), "γ = −0.5");
        assert_eq!(
            Gamma::Ramp { from: 1.0, to: 0.0 }.label(),
            "γ = 1 → 0 (ramp)"
        );
    }

    #[test]
    fn gamma_round_trips_through_ron() {
        for g in [
            Gamma::Constant(-0.5),
            Gamma::Ramp { from: 1.0, to: 0.0 },
            Gamma::Smoothstep { from: 0.2, to: 0.9 },
            Gamma::PiecewiseLinear(vec![(0.0, 1.0), (1.0, 0.0)]),
        ] {
            let s = ron::to_string(&g).unwrap();
            let back: Gamma = ron::from_str(&s).unwrap();
            assert_eq!(back, g, "{s}");
        }
    }

    #[test]
    fn placements_are_classified_into_the_six_arrangements() {
        let p = |bs, be| BlendPlacement {
            a_start: 1.0,
            a_end: 3.0,
            b_start: bs,
            b_end: be,
        };
        use Arrangement::*;
        assert_eq!(p(0.5, 2.0).arrangement().unwrap(), StartsBeforeEndsBefore);
        assert_eq!(p(0.5, 3.0).arrangement().unwrap(), StartsBeforeEndsTogether);
        assert_eq!(p(1.0, 2.0).arrangement().unwrap(), StartsTogetherEndsBefore);
        assert_eq!(
            p(1.0, 3.0).arrangement().unwrap(),
            StartsTogetherEndsTogether
        );
        assert_eq!(p(1.5, 2.0).arrangement().unwrap(), StartsAfterEndsBefore);
        assert_eq!(p(1.5, 3.0).arrangement().unwrap(), StartsAfterEndsTogether);
        assert!(p(1.5, 3.5).arrangement().is_err(), "t_Be > t_Ae");
        assert!(p(0.0, 0.9).arrangement().is_err(), "no overlap");
        assert!(
            p(0.0, 1.0).arrangement().is_err(),
            "touching is not overlapping"
        );
        assert!(p(2.0, 2.0).arrangement().is_err(), "empty B");
    }
}
