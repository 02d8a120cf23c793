//! A figure's body as volumes, for pictures that show depth: boxes on the links of the
//! project's own models, capsules along the bones of any other skeleton.
//!
//! - **The project's models** (a figure whose point names and parents are those of
//!   [`crate::humanoid::fall21`] or [`crate::humanoid::humanoid24`]): each link's floor-contact
//!   box ([`crate::humanoid::human_body`]), for the model scaled to the figure's height
//!   (its bone lengths against the model's). A box lives in its link's frame; the frame's
//!   rotation R is fitted each frame from the points hanging from the link (their rest offsets
//!   o in the link frame against their offsets d in the frame drawn): with two or more
//!   children not in line, the rotation that takes the rest triad (ô₁, ô₁ × o₂) onto the drawn
//!   one (d̂₁, d̂₁ × d₂), child 1 the farthest at rest and child 2 the one least in line with it;
//!   with one child, the parent's rotation followed by the shortest arc from R_parent·o to d (no
//!   twist of its own); with none, the parent's rotation.
//! - **Any other skeleton**: a capsule (a cylinder with hemispherical ends) along each bone, of
//!   radius r by this proportion rule of the figure's height H (the largest vertical extent of
//!   its points over the motion) and the bone's length ℓ:
//!   - the head (a bone from a point named like `head`, to its end site or to the eyes): 0.055 H,
//!     coloured as the mid-line;
//!   - the neck (a bone to a point named like `neck` or `head`): 0.03 H;
//!   - the trunk (a bone between two mid-line points): 0.055 H;
//!   - a limb's girdle (the first bone of a limb longer than 0.02 H: hip, clavicle): 0.045 H;
//!   - the rest of a limb: 0.17 ℓ, kept within 0.012 H – 0.045 H (a thigh of 0.245 H gets
//!     0.042 H, a forearm of 0.146 H 0.025 H, fingers and toes 0.012 H).
//!
//!   A root that only stands in for the ground (see [`super::figure::ground_proxy`]) gets none.
//!
//! Every volume carries the side of its point ([`super::StickFigure::sides`]) for its colour
//! (but the head's).

use glam::{DMat3, DQuat, DVec3};

use super::figure::{Side, StickFigure, Track};
use crate::humanoid::{self, human_body};

/// One volume of a body, in the figure's terms.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A box fixed to the link of point `link`: centre and half-extents in the link frame (m),
    /// the frame's rotation fitted from the link's child points every frame.
    Cuboid {
        /// The point whose link carries the box.
        link: usize,
        /// Centre in the link frame (m).
        centre: DVec3,
        /// Half-extents along the link frame's axes (m).
        half: DVec3,
    },
    /// A capsule around the bone from point `from` to point `to`.
    Capsule {
        /// The bone's upper point (the parent).
        from: usize,
        /// The bone's lower point (the child).
        to: usize,
        /// Radius (m).
        radius: f64,
    },
}

/// A volume placed in the world for one frame (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solid {
    /// A box: its centre and its three half-extent vectors (edges' directions times half
    /// lengths).
    Cuboid {
        /// Centre (world).
        centre: DVec3,
        /// Half-extent vectors (world).
        axes: [DVec3; 3],
    },
    /// A capsule from `a` to `b` of radius `radius`.
    Capsule {
        /// One end of the axis (world).
        a: DVec3,
        /// The other end (world).
        b: DVec3,
        /// Radius (m).
        radius: f64,
    },
}

impl Solid {
    /// Its centre (world): the box's centre or the capsule axis' midpoint.
    pub fn centre(&self) -> DVec3 {
        match *self {
            Solid::Cuboid { centre, .. } => centre,
            Solid::Capsule { a, b, .. } => (a + b) * 0.5,
        }
    }

    /// Its lowest height above the floor (m).
    pub fn bottom(&self) -> f64 {
        match *self {
            Solid::Cuboid { centre, axes } => {
                centre.y - axes.iter().map(|v| v.y.abs()).sum::<f64>()
            }
            Solid::Capsule { a, b, radius } => a.y.min(b.y) - radius,
        }
    }
}

/// A figure's body as volumes (see the module doc for the two kinds and their rules): the
/// shapes with their sides, and how to place them on a frame.
#[derive(Debug, Clone)]
pub struct Volumes {
    /// Every volume with the side that colours it.
    pub shapes: Vec<(Shape, Side)>,
    /// What the volumes are, for captions: "fall21 contact boxes", "capsules".
    pub kind: String,
    /// Per point, the points hanging from it with their rest offsets in its link frame (m);
    /// empty for a body of capsules.
    children: Vec<Vec<(usize, DVec3)>>,
    /// Every point, parents before children.
    order: Vec<usize>,
    /// Each point's parent.
    parents: Vec<Option<usize>>,
}

/// Bodies of the models the project simulates: (name, model).
fn models() -> [(&'static str, humanoid::Figure); 2] {
    [
        ("fall21", humanoid::fall21()),
        ("humanoid24", humanoid::humanoid24()),
    ]
}

impl Volumes {
    /// The body of `track`'s figure: the model's contact boxes when the figure is one of the
    /// project's models and its height (bone lengths in the first frame against the model's)
    /// is one the model is built for (1.0–2.3 m), capsules otherwise.
    pub fn of(track: &Track) -> Volumes {
        let fig = track.figure;
        for (name, model) in models() {
            let skel = model.skeleton();
            if skel.point_names() != fig.names || skel.point_parents() != fig.parents {
                continue;
            }
            let rest = skel.rest_points();
            let Some(first) = track.frames.first() else {
                break;
            };
            let length = |pts: &[DVec3]| -> f64 {
                fig.parents
                    .iter()
                    .enumerate()
                    .filter_map(|(i, p)| p.map(|p| (pts[i] - pts[p]).length()))
                    .sum()
            };
            let height = model.height * length(first) / length(&rest).max(1e-9);
            if let Some(body) = Self::boxes(fig, &model, height, name) {
                return body;
            }
            break;
        }
        Self::capsules(track)
    }

    /// The contact boxes of `model` (whose figure `fig` is) at `height` m; `None` when the
    /// model cannot be built at that height.
    fn boxes(
        fig: &StickFigure,
        model: &humanoid::Figure,
        height: f64,
        name: &str,
    ) -> Option<Volumes> {
        // Mass and gravity do not change the boxes.
        let body = human_body(model, height, 70.0, 9.81).ok()?;
        let rest = body.figure.skeleton().rest_points();
        let sides = fig.sides();
        let n = fig.names.len();
        let mut children = vec![Vec::new(); n];
        for (c, p) in fig.parents.iter().enumerate() {
            if let Some(p) = *p {
                children[p].push((c, rest[c] - rest[p]));
            }
        }
        let shapes = body
            .boxes
            .iter()
            .enumerate()
            .map(|(link, b)| {
                (
                    Shape::Cuboid {
                        link,
                        centre: b.center,
                        half: b.half,
                    },
                    sides[link],
                )
            })
            .collect();
        Some(Volumes {
            shapes,
            kind: format!("{name} contact boxes"),
            children,
            order: parents_first(fig),
            parents: fig.parents.clone(),
        })
    }

    /// Capsules along the bones of `track`'s figure by the proportion rule of the module doc.
    fn capsules(track: &Track) -> Volumes {
        let fig = track.figure;
        let n = fig.names.len();
        let h = track
            .frames
            .iter()
            .map(|f| {
                let (lo, hi) = f
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                        (a.min(p.y), b.max(p.y))
                    });
                hi - lo
            })
            .filter(|h| h.is_finite())
            .fold(0.0, f64::max);
        let sides = fig.sides();
        let first = track.frames.first();
        let proxy = first.and_then(|f| super::figure::ground_proxy(fig, f));
        let len = |i: usize, p: usize| first.map_or(0.0, |f| (f[i] - f[p]).length());
        let named = |i: usize, w: &str| fig.names[i].to_lowercase().contains(w);
        // A limb's bone is its girdle when every bone above it in the limb is negligible.
        let girdle = |i: usize, p: usize| {
            let mut k = p;
            let mut steps = 0;
            while sides[k] != Side::Centre {
                let Some(q) = fig.parents[k] else { break };
                if len(k, q) > 0.02 * h || steps > n {
                    return false;
                }
                k = q;
                steps += 1;
            }
            len(i, p) > 0.02 * h
        };
        let shapes = (0..n)
            .filter_map(|i| {
                let p = fig.parents[i]?;
                if Some(p) == proxy {
                    return None;
                }
                // The head is the mid-line's whatever its bones point at (eyes, say).
                if named(p, "head") {
                    let shape = Shape::Capsule {
                        from: p,
                        to: i,
                        radius: 0.055 * h,
                    };
                    return Some((shape, Side::Centre));
                }
                let radius = if named(i, "neck") || named(i, "head") {
                    0.03 * h
                } else if sides[i] == Side::Centre && sides[p] == Side::Centre {
                    0.055 * h
                } else if girdle(i, p) {
                    0.045 * h
                } else {
                    (0.17 * len(i, p)).clamp(0.012 * h, 0.045 * h)
                };
                Some((
                    Shape::Capsule {
                        from: p,
                        to: i,
                        radius,
                    },
                    sides[i],
                ))
            })
            .collect();
        Volumes {
            shapes,
            kind: "capsules".into(),
            children: vec![Vec::new(); n],
            order: parents_first(fig),
            parents: fig.parents.clone(),
        }
    }

    /// The volumes placed for one frame's points (`pts`, one per figure point), with their
    /// sides.
    pub fn solids(&self, pts: &[DVec3]) -> Vec<(Solid, Side)> {
        let rotations = self.link_rotations(pts);
        self.shapes
            .iter()
            .filter_map(|(shape, side)| {
                let solid = match *shape {
                    Shape::Cuboid { link, centre, half } => {
                        let r = *rotations.get(link)?;
                        Solid::Cuboid {
                            centre: *pts.get(link)? + r * centre,
                            axes: [
                                r * DVec3::X * half.x,
                                r * DVec3::Y * half.y,
                                r * DVec3::Z * half.z,
                            ],
                        }
                    }
                    Shape::Capsule { from, to, radius } => Solid::Capsule {
                        a: *pts.get(from)?,
                        b: *pts.get(to)?,
                        radius,
                    },
                };
                Some((solid, *side))
            })
            .collect()
    }

    /// Every point's link rotation fitted from the points hanging from it (the module doc's
    /// rule); identity for a body of capsules.
    fn link_rotations(&self, pts: &[DVec3]) -> Vec<DQuat> {
        let mut rot = vec![DQuat::IDENTITY; self.children.len()];
        if self.children.iter().all(Vec::is_empty) {
            return rot;
        }
        for &j in &self.order {
            let parent = self.parents[j].map_or(DQuat::IDENTITY, |p| rot[p]);
            let kids = &self.children[j];
            let drawn = |c: usize| pts.get(c).zip(pts.get(j)).map(|(c, j)| *c - *j);
            rot[j] = match kids.as_slice() {
                [] => parent,
                [(c, o)] => drawn(*c).map_or(parent, |d| swing(parent, *o, d)),
                _ => triad(kids, &drawn).unwrap_or_else(|| {
                    let (c, o) = kids[0];
                    drawn(c).map_or(parent, |d| swing(parent, o, d))
                }),
            };
        }
        rot
    }
}

/// `parent` followed by the shortest arc that takes `parent · o` onto `d`.
fn swing(parent: DQuat, o: DVec3, d: DVec3) -> DQuat {
    let from = (parent * o).normalize_or_zero();
    let to = d.normalize_or_zero();
    if from == DVec3::ZERO || to == DVec3::ZERO {
        return parent;
    }
    (DQuat::from_rotation_arc(from, to) * parent).normalize()
}

/// The rotation taking the rest triad of `kids` onto the drawn one (module doc), `None` when
/// the rest offsets or the drawn ones are in line.
fn triad(kids: &[(usize, DVec3)], drawn: &dyn Fn(usize) -> Option<DVec3>) -> Option<DQuat> {
    let (c1, o1) = *kids
        .iter()
        .max_by(|a, b| a.1.length_squared().total_cmp(&b.1.length_squared()))?;
    let u = o1.normalize_or_zero();
    let (c2, o2) = *kids.iter().filter(|(c, _)| *c != c1).min_by(|a, b| {
        let cos = |o: DVec3| o.normalize_or_zero().dot(u).abs();
        cos(a.1).total_cmp(&cos(b.1))
    })?;
    let frame = |a: DVec3, b: DVec3| -> Option<DMat3> {
        let e1 = a.try_normalize()?;
        let e2 = a.cross(b).try_normalize()?;
        Some(DMat3::from_cols(e1, e2, e1.cross(e2)))
    };
    let rest = frame(o1, o2)?;
    let now = frame(drawn(c1)?, drawn(c2)?)?;
    Some(DQuat::from_mat3(&(now * rest.transpose())).normalize())
}

/// Every point of `fig`, parents before children (roots first; a point in a cycle, which
/// [`StickFigure::validate`] rejects, is left out).
fn parents_first(fig: &StickFigure) -> Vec<usize> {
    let n = fig.parents.len();
    let mut out: Vec<usize> = (0..n).filter(|&i| fig.parents[i].is_none()).collect();
    let mut k = 0;
    while k < out.len() {
        let p = out[k];
        out.extend((0..n).filter(|&c| fig.parents[c] == Some(p)));
        k += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure_track(model: &humanoid::Figure, pts: &[Vec<DVec3>]) -> Volumes {
        let fig = StickFigure::of(&model.skeleton());
        let t = Track {
            figure: &fig,
            frames: pts,
            label: String::new(),
            frame_time: 0.1,
        };
        Volumes::of(&t)
    }

    #[test]
    fn fall21_gets_its_contact_boxes_at_its_height_and_they_follow_a_turned_body() {
        let model = humanoid::fall21().scaled_to_height(1.55);
        let rest = model.skeleton().rest_points();
        let body = figure_track(&model, std::slice::from_ref(&rest));
        assert_eq!(body.kind, "fall21 contact boxes");
        let want = human_body(&model, 1.55, 70.0, 9.81).unwrap().boxes;
        assert_eq!(body.shapes.len(), want.len());
        for ((shape, _), b) in body.shapes.iter().zip(&want) {
            match shape {
                Shape::Cuboid { centre, half, .. } => {
                    assert!((*centre - b.center).length() < 1e-9);
                    assert!((*half - b.half).length() < 1e-9);
                }
                other => panic!("expected a box, got {other:?}"),
            }
        }
        // At rest every link frame is the world's.
        for (s, _) in body.solids(&rest) {
            if let Solid::Cuboid { axes, .. } = s {
                for (k, a) in axes.iter().enumerate() {
                    let mut e = DVec3::ZERO;
                    e[k] = 1.0;
                    assert!(a.normalize().dot(e) > 1.0 - 1e-9, "{axes:?}");
                }
            }
        }
        // The whole body turned 90° about +Y and lifted: every box turns and moves with it.
        let q = DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let moved: Vec<DVec3> = rest.iter().map(|p| q * *p + DVec3::Y).collect();
        let at_rest = body.solids(&rest);
        for ((s, _), (r, _)) in body.solids(&moved).iter().zip(&at_rest) {
            let want = q * r.centre() + DVec3::Y;
            assert!((s.centre() - want).length() < 1e-9, "{s:?}");
        }
    }

    #[test]
    fn any_other_skeleton_gets_capsules_by_the_proportion_rule() {
        // Hips, a spine to the head, and a left leg of thigh and shin, 1.7 m tall.
        let fig = StickFigure {
            names: [
                "Hips",
                "Chest",
                "Head",
                "Head_end",
                "LeftUpLeg",
                "LeftLeg",
                "LeftFoot",
            ]
            .map(String::from)
            .to_vec(),
            parents: vec![None, Some(0), Some(1), Some(2), Some(0), Some(4), Some(5)],
        };
        let y = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let frames = vec![vec![
            y(0.0, 0.95),
            y(0.0, 1.35),
            y(0.0, 1.5),
            y(0.0, 1.7),
            y(0.1, 0.9),
            y(0.1, 0.48),
            y(0.1, 0.0),
        ]];
        let t = Track {
            figure: &fig,
            frames: &frames,
            label: String::new(),
            frame_time: 0.1,
        };
        let body = Volumes::of(&t);
        assert_eq!(body.kind, "capsules");
        let radius = |to: usize| {
            body.shapes
                .iter()
                .find_map(|(s, _)| match *s {
                    Shape::Capsule { to: t, radius, .. } if t == to => Some(radius),
                    _ => None,
                })
                .unwrap()
        };
        let h = 1.7;
        assert!((radius(1) - 0.055 * h).abs() < 1e-12, "trunk");
        assert!((radius(2) - 0.03 * h).abs() < 1e-12, "neck");
        assert!((radius(3) - 0.055 * h).abs() < 1e-12, "head");
        assert!((radius(4) - 0.045 * h).abs() < 1e-12, "girdle");
        assert!((radius(5) - 0.17 * 0.42).abs() < 1e-12, "thigh");
        assert!((radius(6) - 0.045 * h).abs() < 1e-12, "shin, capped");
        let (_, side) = body.shapes[body.shapes.len() - 1];
        assert_eq!(side, Side::Left);
    }
}
