//! Automatic mapping of a skeleton never seen before: the chains found by structure
//! ([`structure`](super::structure)), the landmarks placed along each chain by names
//! ([`names`](super::names)) where they say something and by joint count and bone lengths where
//! they do not, and left and right told by geometry.
//!
//! **Placement.** Each chain (leg: pelvis → foot end; arm: chest hub → hand end; spine: pelvis
//! → head end) is a sequence of points. Its landmarks must sit on it in order (hip, knee, ankle,
//! toe; clavicle, shoulder, elbow, wrist, hand; waist ≤ chest hub ≤ neck, head). By structure:
//! the hip, knee and ankle start the two longest consecutive bones of the leg (thigh and shin),
//! the toe is the next point after the ankle; the shoulder is the first point of the arm 5 % of
//! `H` out from the chest hub (or the next one, when the two bones from there are longer: a long
//! clavicle), the clavicle the point before it, elbow, wrist and hand the next distinct points;
//! the waist is the first point above the pelvis, the neck the first above the chest hub, the
//! head the joint where the chain's end branches (eyes, face), else its end. Points within 0.1 %
//! of `H` of the point before are the same place (zero-length helper joints). The placement actually used is the order-keeping
//! assignment of maximum score (dynamic programming over the chain), a point scoring 1 for a name
//! that is a synonym of the landmark (0.9 if it sits on its parent: a zero-length helper) plus 0.2
//! where structure puts the landmark: names decide where they exist, structure fills the rest and
//! breaks ties, and one name may mean two landmarks ("Shoulder": the clavicle in Mixamo, the upper
//! arm in SMPL) with the order along the chain deciding. A head or hand named on a joint that
//! ends its chain takes that joint's End Site when it is not on the joint (the head top).
//!
//! **Sides.** Forward is where the feet point (toe − ankle, horizontal, summed over both feet);
//! the figure's left is `up × forward`; the leg (arm) whose hip (shoulder) lies farther along it
//! is the left one. Geometry wins over side words in the names when it is clear (feet at least 2 %
//! of `H` long, hips or shoulders at least 2 % of `H` apart across): the model must move the way
//! the figure moves, and a name can be wrong (a mirrored export) while the positions cannot.
//! Names decide only when geometry cannot.

use std::collections::BTreeMap;

use glam::DVec3;
use serde::Serialize;

use super::names::{NormalName, Synonyms};
use super::structure::{Chains, Tree, find_chains};
use super::{FORMAT_VERSION, LANDMARKS, Mapping, MappingError};
use crate::skeleton::{Side, Skeleton, Transform};

/// How one landmark was found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    /// The landmark (`left_knee`).
    pub landmark: String,
    /// The source point: a joint name, or `"<joint>:end"`.
    pub source: String,
    /// Confidence in 0..1: 1 when name and structure agree, 0.85 by name alone, 0.7 by
    /// structure alone, times the side's confidence for a sided landmark (1 when geometry and
    /// names agree, 0.9 by geometry alone, 0.75 by geometry against the names, 0.7 by names
    /// alone).
    pub confidence: f64,
    /// Why, in words.
    pub reason: String,
}

/// A mapping found automatically, with how each landmark was found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AutoMapping {
    /// The mapping (name `"automatic"`), usable as any mapping file.
    pub mapping: Mapping,
    /// One finding per landmark, in [`LANDMARKS`] order.
    pub findings: Vec<Finding>,
    /// What was found about the whole skeleton: limb ends, forward direction, sides.
    pub notes: Vec<String>,
}

/// Score of the point where structure puts a landmark, against 1 for a name: five structural
/// agreements weigh as much as one name, so names decide and structure breaks ties.
const STRUCTURE_BONUS: f64 = 0.2;

/// A landmark slot of a chain: its role, the chain indices allowed, where structure puts it and
/// in words why.
struct Slot {
    role: &'static str,
    lo: usize,
    hi: usize,
    structural: usize,
    rule: &'static str,
}

/// A placed landmark: chain index, whether a name matched, and the structural index.
#[derive(Clone, Copy)]
struct Placed {
    index: usize,
    by_name: bool,
    structural: usize,
}

/// Everything about one chain needed to place its landmarks.
struct ChainView<'a> {
    tree: &'a Tree,
    nodes: &'a [usize],
    names: Vec<Option<NormalName>>,
    eps: f64,
}

impl ChainView<'_> {
    fn pos(&self, i: usize) -> DVec3 {
        self.tree.nodes[self.nodes[i]].pos
    }

    /// Chain indices of the distinct places, the first one always kept.
    fn distinct(&self) -> Vec<usize> {
        let mut out = vec![0];
        for i in 1..self.nodes.len() {
            if (self.pos(i) - self.pos(*out.last().expect("non-empty"))).length() >= self.eps {
                out.push(i);
            }
        }
        out
    }

    /// Name score of chain point `i` for `role`.
    fn name_score(&self, syn: &Synonyms, role: &str, i: usize) -> f64 {
        let Some(n) = &self.names[i] else { return 0.0 };
        if !syn.names(role, &n.base) {
            return 0.0;
        }
        let node = &self.tree.nodes[self.nodes[i]];
        let on_parent = node
            .parent
            .is_some_and(|p| (self.tree.nodes[p].pos - node.pos).length() < self.eps);
        if on_parent { 0.9 } else { 1.0 }
    }

    /// The order-keeping assignment of maximum score (see the module documentation).
    fn align(&self, syn: &Synonyms, slots: &[Slot], what: &str) -> Result<Vec<Placed>, String> {
        let n = self.nodes.len();
        let k = slots.len();
        let neg = f64::NEG_INFINITY;
        let mut best = vec![neg; k * n];
        let mut from = vec![usize::MAX; k * n];
        for (s, slot) in slots.iter().enumerate() {
            for i in slot.lo..=slot.hi.min(n.saturating_sub(1)) {
                let here = self.name_score(syn, slot.role, i)
                    + if i == slot.structural {
                        STRUCTURE_BONUS
                    } else {
                        0.0
                    };
                if s == 0 {
                    best[i] = here;
                    continue;
                }
                let mut prev = (neg, usize::MAX);
                for j in 0..i {
                    let b = best[(s - 1) * n + j];
                    if b > prev.0 {
                        prev = (b, j);
                    }
                }
                if prev.0 > neg {
                    best[s * n + i] = prev.0 + here;
                    from[s * n + i] = prev.1;
                }
            }
        }
        let last = (0..n)
            .filter(|&i| best[(k - 1) * n + i] > neg)
            .max_by(|&a, &b| {
                best[(k - 1) * n + a]
                    .total_cmp(&best[(k - 1) * n + b])
                    .then(b.cmp(&a))
            });
        let Some(mut i) = last else {
            return Err(format!(
                "the {what} chain has {n} points, too few for {}",
                slots.iter().map(|s| s.role).collect::<Vec<_>>().join(", ")
            ));
        };
        let mut out = vec![];
        for s in (0..k).rev() {
            out.push(Placed {
                index: i,
                by_name: self.name_score(syn, slots[s].role, i) > 0.0,
                structural: slots[s].structural,
            });
            i = from[s * n + i];
        }
        out.reverse();
        Ok(out)
    }

    /// Side named by the chain's joints after its first point (majority of side words).
    fn named_side(&self) -> Side {
        let (mut l, mut r) = (0, 0);
        for n in self.names.iter().skip(1).flatten() {
            match n.side {
                Side::Left => l += 1,
                Side::Right => r += 1,
                Side::Centre => {}
            }
        }
        match l.cmp(&r) {
            std::cmp::Ordering::Greater => Side::Left,
            std::cmp::Ordering::Less => Side::Right,
            std::cmp::Ordering::Equal => Side::Centre,
        }
    }
}

/// A landmark found on a chain, before sides are told.
struct Found {
    role: &'static str,
    node: usize,
    confidence: f64,
    reason: String,
}

fn view<'a>(
    tree: &'a Tree,
    skeleton: &Skeleton,
    nodes: &'a [usize],
    syn: &Synonyms,
) -> ChainView<'a> {
    ChainView {
        tree,
        nodes,
        names: nodes
            .iter()
            .map(|&n| {
                let node = &tree.nodes[n];
                (!node.end_site).then(|| syn.normalise(&skeleton.joints[node.joint].name))
            })
            .collect(),
        eps: 1e-3 * tree.height,
    }
}

/// Findings of placed slots: node, confidence and reason.
fn found(v: &ChainView, skeleton: &Skeleton, slots: &[Slot], placed: &[Placed]) -> Vec<Found> {
    slots
        .iter()
        .zip(placed)
        .map(|(slot, p)| {
            let mut node = v.nodes[p.index];
            let name = v.tree.name(skeleton, node);
            let mut end_note = "";
            // A head or hand named on the joint that ends its chain: that joint's far end.
            if p.by_name && matches!(slot.role, "head" | "hand") {
                let n = &v.tree.nodes[node];
                let j = &skeleton.joints[n.joint];
                let leaf_joint = !skeleton.joints.iter().any(|c| c.parent == Some(n.joint));
                if leaf_joint
                    && let Some(e) = j.end_site
                    && e.length() >= v.eps
                    && let Some(&end) = n.children.iter().find(|&&c| v.tree.nodes[c].end_site)
                {
                    node = end;
                    end_note = "; its End Site, the far end";
                }
            }
            let structural = v.nodes[p.structural];
            let agrees = node == structural
                || v.nodes[p.index] == structural
                || (v.tree.nodes[node].pos - v.tree.nodes[structural].pos).length() < v.eps;
            let (confidence, reason) = match (p.by_name, agrees) {
                (true, true) => (
                    1.0,
                    format!(
                        "name '{name}'{end_note} and structure ({}) agree",
                        slot.rule
                    ),
                ),
                (true, false) => (
                    0.85,
                    format!(
                        "name '{name}'{end_note}; structure ({}) would say '{}'",
                        slot.rule,
                        v.tree.name(skeleton, structural)
                    ),
                ),
                (false, _) => (0.7, format!("structure: {}", slot.rule)),
            };
            Found {
                role: slot.role,
                node,
                confidence,
                reason,
            }
        })
        .collect()
}

/// Places the landmarks of one chain: its view, the placement, the findings.
fn place<'a>(
    tree: &'a Tree,
    skeleton: &Skeleton,
    nodes: &'a [usize],
    syn: &Synonyms,
    what: &str,
    slots: impl Fn(&ChainView) -> Result<Vec<Slot>, String>,
) -> Result<(ChainView<'a>, Vec<Placed>, Vec<Found>), String> {
    let v = view(tree, skeleton, nodes, syn);
    let slots = slots(&v)?;
    let placed = v.align(syn, &slots, what)?;
    let f = found(&v, skeleton, &slots, &placed);
    Ok((v, placed, f))
}

/// Horizontal distance of `a` from `b` (perpendicular to `up`).
fn horizontal(a: DVec3, b: DVec3, up: DVec3) -> f64 {
    let d = a - b;
    (d - up * d.dot(up)).length()
}

fn leg_slots(v: &ChainView) -> Result<Vec<Slot>, String> {
    let d = v.distinct();
    let n = v.nodes.len();
    if d.len() < 5 {
        return Err(format!(
            "a leg chain has {} distinct points, a leg needs five (pelvis, hip, knee, ankle, toe)",
            d.len()
        ));
    }
    let seg = |a: usize, b: usize| (v.pos(d[a]) - v.pos(d[b])).length();
    let j = (1..d.len() - 2)
        .max_by(|&a, &b| {
            (seg(a, a + 1) + seg(a + 1, a + 2)).total_cmp(&(seg(b, b + 1) + seg(b + 1, b + 2)))
        })
        .expect("at least one pair");
    let toe = d.get(j + 3).copied().unwrap_or(n - 1);
    let thigh = "the two longest consecutive bones of the leg are thigh and shin";
    Ok(vec![
        Slot {
            role: "hip",
            lo: 1,
            hi: n - 1,
            structural: d[j],
            rule: thigh,
        },
        Slot {
            role: "knee",
            lo: 1,
            hi: n - 1,
            structural: d[j + 1],
            rule: thigh,
        },
        Slot {
            role: "ankle",
            lo: 1,
            hi: n - 1,
            structural: d[j + 2],
            rule: thigh,
        },
        Slot {
            role: "toe",
            lo: 1,
            hi: n - 1,
            structural: toe,
            rule: "the next point after the ankle",
        },
    ])
}

fn arm_slots(v: &ChainView) -> Result<Vec<Slot>, String> {
    let d = v.distinct();
    let n = v.nodes.len();
    if d.len() < 5 {
        return Err(format!(
            "an arm chain has {} distinct points, an arm needs five (chest, shoulder, elbow, wrist, \
             hand)",
            d.len()
        ));
    }
    let out = 0.05 * v.tree.height;
    let k0 = (1..d.len() - 3)
        .find(|&k| horizontal(v.pos(d[k]), v.pos(0), v.tree.up) >= out)
        .unwrap_or(1);
    // A long clavicle reaches that far out itself: then the upper arm and forearm (the two
    // longest consecutive bones) start one point later.
    let seg = |a: usize| (v.pos(d[a]) - v.pos(d[a + 1])).length();
    let k = if k0 + 3 < d.len() && seg(k0 + 1) + seg(k0 + 2) > seg(k0) + seg(k0 + 1) {
        k0 + 1
    } else {
        k0
    };
    let hand = d.get(k + 3).copied().unwrap_or(n - 1);
    Ok(vec![
        Slot {
            role: "clavicle",
            lo: 0,
            hi: n - 1,
            structural: d[k] - 1,
            rule: "the point before the shoulder",
        },
        Slot {
            role: "shoulder",
            lo: 1,
            hi: n - 1,
            structural: d[k],
            rule: "the first point of the arm 5 % of the height out from the chest, or the next \
                   one when that starts the two longest bones (upper arm, forearm)",
        },
        Slot {
            role: "elbow",
            lo: 1,
            hi: n - 1,
            structural: d[k + 1],
            rule: "the next point of the arm",
        },
        Slot {
            role: "wrist",
            lo: 1,
            hi: n - 1,
            structural: d[k + 2],
            rule: "the next point of the arm",
        },
        Slot {
            role: "hand",
            lo: 1,
            hi: n - 1,
            structural: hand,
            rule: "the next point after the wrist",
        },
    ])
}

fn spine_slots(v: &ChainView, chest: usize) -> Result<Vec<Slot>, String> {
    let n = v.nodes.len();
    let c = v
        .nodes
        .iter()
        .position(|&x| x == chest)
        .expect("the chest hub is on the spine");
    if n < 4 || c + 1 >= n {
        return Err(format!(
            "the spine chain has {n} points, too few for pelvis, waist, neck and head"
        ));
    }
    let d = v.distinct();
    let waist = d.get(1).copied().unwrap_or(c).min(c);
    let neck = (c + 1..n - 1)
        .find(|&i| (v.pos(i) - v.pos(c)).length() >= v.eps)
        .unwrap_or(c);
    // The head: where the chain's end branches (eyes, jaw, face), else the chain's end.
    let head = (neck + 1..n)
        .rev()
        .find(|&i| v.tree.nodes[v.nodes[i]].children.len() >= 2)
        .unwrap_or(n - 1);
    Ok(vec![
        Slot {
            role: "waist",
            lo: 1,
            hi: c,
            structural: waist,
            rule: "the first point above the pelvis",
        },
        Slot {
            role: "neck",
            lo: c,
            hi: n - 2,
            structural: neck,
            rule: "the first point above the chest hub",
        },
        Slot {
            role: "head",
            lo: 1,
            hi: n - 1,
            structural: head,
            rule: "where the head chain's end branches (eyes, face), else its end",
        },
    ])
}

/// How the sides of a pair of chains were told: (first chain is left, confidence, note).
fn tell_sides(
    what: &str,
    geometric: Option<bool>,
    named: (Side, Side),
) -> Result<(bool, f64, String), String> {
    let by_name = match named {
        (Side::Left, Side::Right) | (Side::Left, Side::Centre) | (Side::Centre, Side::Right) => {
            Some(true)
        }
        (Side::Right, Side::Left) | (Side::Right, Side::Centre) | (Side::Centre, Side::Left) => {
            Some(false)
        }
        _ => None,
    };
    match (geometric, by_name) {
        (Some(g), Some(n)) if g == n => Ok((g, 1.0, format!("{what}: geometry and names agree"))),
        (Some(g), Some(_)) => Ok((
            g,
            0.75,
            format!(
                "{what}: the names say the opposite of the geometry; geometry wins (a name can be \
                 wrong, the positions are what the model must follow)"
            ),
        )),
        (Some(g), None) => Ok((
            g,
            0.9,
            format!("{what}: by geometry (the names carry no side)"),
        )),
        (None, Some(n)) => Ok((n, 0.7, format!("{what}: by names (geometry undecided)"))),
        (None, None) => Err(format!(
            "cannot tell the left {what} from the right: the feet give no forward direction or the \
             {what} are not apart across it, and the names carry no side"
        )),
    }
}

/// Finds the mapping of a skeleton posed by `globals` (one transform per joint; the first frame
/// of a clip, or the rest pose): the chains by structure, the landmarks by names and structure,
/// the sides by geometry. Errors name what could not be found when the skeleton is not a
/// humanoid.
pub fn detect_automatic(
    skeleton: &Skeleton,
    globals: &[Transform],
    synonyms: &Synonyms,
) -> Result<AutoMapping, MappingError> {
    let root = skeleton
        .joints
        .first()
        .map(|j| j.name.clone())
        .unwrap_or_default();
    detect_inner(skeleton, globals, synonyms)
        .map_err(|reason| MappingError::NotHumanoid { root, reason })
}

fn detect_inner(
    skeleton: &Skeleton,
    globals: &[Transform],
    syn: &Synonyms,
) -> Result<AutoMapping, String> {
    if skeleton.joints.is_empty() || globals.len() != skeleton.joints.len() {
        return Err("the skeleton has no joints".into());
    }
    let tree = Tree::new(skeleton, globals);
    let chains = find_chains(&tree, skeleton)?;
    let mut notes = vec![chains_note(&tree, skeleton, &chains)];

    // Spine: waist, neck, head.
    let (_, _, spine_found) = place(&tree, skeleton, &chains.spine, syn, "spine", |v| {
        spine_slots(v, chains.chest)
    })?;
    let neck_node = spine_found[1].node;

    // Legs and arms, sides not yet told.
    let legs = place_pair(&tree, skeleton, &chains.legs, syn, "leg", leg_slots)?;
    let mut arms = place_pair(&tree, skeleton, &chains.arms, syn, "arm", arm_slots)?;
    stand_in_clavicles(&mut arms, neck_node);
    let [(legs_first_left, leg_conf), (arms_first_left, arm_conf)] =
        tell_limb_sides(&tree, &legs, &arms, &mut notes)?;

    // Assemble.
    let mut by_landmark: BTreeMap<String, (usize, f64, String)> = BTreeMap::new();
    by_landmark.insert(
        "pelvis".into(),
        pelvis_landmark(&tree, skeleton, syn, chains.pelvis),
    );
    for f in spine_found {
        by_landmark.insert(f.role.into(), (f.node, f.confidence, f.reason));
    }
    let sided = [
        (legs.found, legs_first_left, leg_conf),
        (arms.found, arms_first_left, arm_conf),
    ];
    for (found, first_left, conf) in sided {
        insert_sided(&mut by_landmark, found, first_left, conf);
    }
    let mut landmarks = BTreeMap::new();
    let mut findings = vec![];
    for l in LANDMARKS {
        let (node, confidence, reason) = by_landmark.remove(l).expect("every landmark placed");
        let source = tree.name(skeleton, node);
        landmarks.insert(l.to_string(), source.clone());
        findings.push(Finding {
            landmark: l.into(),
            source,
            confidence,
            reason,
        });
    }
    let detect = detect_joints(&landmarks);
    Ok(AutoMapping {
        mapping: Mapping {
            format_version: FORMAT_VERSION,
            name: "automatic".into(),
            detect,
            landmarks,
        },
        findings,
        notes,
    })
}

/// The note naming the chains found by structure: the pelvis, the chest hub, the four limb
/// ends and the head.
fn chains_note(tree: &Tree, skeleton: &Skeleton, chains: &Chains) -> String {
    let Chains {
        pelvis,
        chest,
        spine,
        legs,
        arms,
    } = chains;
    let h = tree.height;
    format!(
        "chains by structure (first frame, height {h:.3} m): pelvis '{}', chest hub '{}', limb ends \
         '{}', '{}', '{}', '{}', head '{}'",
        tree.name(skeleton, *pelvis),
        tree.name(skeleton, *chest),
        tree.name(skeleton, *legs[0].last().expect("path")),
        tree.name(skeleton, *legs[1].last().expect("path")),
        tree.name(skeleton, *arms[0].last().expect("path")),
        tree.name(skeleton, *arms[1].last().expect("path")),
        tree.name(skeleton, *spine.last().expect("path")),
    )
}

/// A pair of limbs placed, sides not yet told.
struct LimbPair {
    /// Each limb's landmarks.
    found: Vec<Vec<Found>>,
    /// Where each limb's slots were placed.
    placed: Vec<Vec<Placed>>,
    /// The side each limb's names carry.
    named: (Side, Side),
}

/// Places the landmarks of a pair of limb chains, `what` ("leg", "arm"), by their `slots`.
fn place_pair(
    tree: &Tree,
    skeleton: &Skeleton,
    chains: &[Vec<usize>; 2],
    syn: &Synonyms,
    what: &str,
    slots: impl Fn(&ChainView) -> Result<Vec<Slot>, String>,
) -> Result<LimbPair, String> {
    let mut found = vec![];
    let mut placed = vec![];
    let mut named = vec![];
    for chain in chains {
        let (v, p, f) = place(tree, skeleton, chain, syn, what, &slots)?;
        found.push(f);
        placed.push(p);
        named.push(v.named_side());
    }
    Ok(LimbPair {
        found,
        placed,
        named: (named[0], named[1]),
    })
}

/// An arm without a clavicle joint (it starts at the chest hub) gets the neck base `neck_node`
/// as its clavicle's inner end, as in the engine's own fall21 skeleton.
fn stand_in_clavicles(arms: &mut LimbPair, neck_node: usize) {
    for (placed, f) in arms.placed.iter().zip(&mut arms.found) {
        if placed[0].index == 0 && !placed[0].by_name {
            f[0].node = neck_node;
            f[0].confidence = 0.6;
            f[0].reason = "no clavicle joint: the neck base stands in for its inner end".into();
        }
    }
}

/// Whether the first leg and the first arm are the left ones and how sure that is: by geometry
/// (forward from the feet, left = up × forward), else by the sides the names carry; the notes
/// say how.
fn tell_limb_sides(
    tree: &Tree,
    legs: &LimbPair,
    arms: &LimbPair,
    notes: &mut Vec<String>,
) -> Result<[(bool, f64); 2], String> {
    let (up, h) = (tree.up, tree.height);
    let (leg_found, arm_found) = (&legs.found, &arms.found);
    let pos = |f: &[Found], role: &str| -> DVec3 {
        tree.nodes[f.iter().find(|x| x.role == role).expect("role placed").node].pos
    };
    let mut forward = DVec3::ZERO;
    for f in leg_found {
        let d = pos(f, "toe") - pos(f, "ankle");
        forward += d - up * d.dot(up);
    }
    let clear_forward = forward.length() >= 0.02 * h;
    let left_axis = up.cross(forward.normalize_or_zero());
    let geometric = |a: DVec3, b: DVec3| -> Option<bool> {
        let s = (a - b).dot(left_axis);
        (clear_forward && s.abs() >= 0.02 * h).then_some(s > 0.0)
    };
    if clear_forward {
        notes.push(format!(
            "forward (where the feet point): ({:.2}, {:.2}, {:.2}); left = up × forward",
            forward.normalize().x,
            forward.normalize().y,
            forward.normalize().z
        ));
    }
    let (legs_first_left, leg_conf, leg_note) = tell_sides(
        "legs",
        geometric(pos(&leg_found[0], "hip"), pos(&leg_found[1], "hip")),
        legs.named,
    )?;
    let (arms_first_left, arm_conf, arm_note) = tell_sides(
        "arms",
        geometric(
            pos(&arm_found[0], "shoulder"),
            pos(&arm_found[1], "shoulder"),
        ),
        arms.named,
    )?;
    notes.push(leg_note);
    notes.push(arm_note);
    Ok([(legs_first_left, leg_conf), (arms_first_left, arm_conf)])
}

/// Inserts the landmarks of a pair of limbs `found` under their sides (the first is the left
/// one when `first_left`), their confidences scaled by the sides' `conf`.
fn insert_sided(
    by_landmark: &mut BTreeMap<String, (usize, f64, String)>,
    found: Vec<Vec<Found>>,
    first_left: bool,
    conf: f64,
) {
    for (k, chain) in found.into_iter().enumerate() {
        let side = if (k == 0) == first_left {
            "left"
        } else {
            "right"
        };
        for f in chain {
            by_landmark.insert(
                format!("{side}_{}", f.role),
                (
                    f.node,
                    f.confidence * conf,
                    format!("{}; {side} side ({})", f.reason, side_word(conf)),
                ),
            );
        }
    }
}

/// The joints the mapping's `detect` lists: those of the pelvis, hips and shoulders, each once.
fn detect_joints(landmarks: &BTreeMap<String, String>) -> Vec<String> {
    let mut detect: Vec<String> = vec![];
    for l in [
        "pelvis",
        "left_hip",
        "right_hip",
        "left_shoulder",
        "right_shoulder",
    ] {
        let j = landmarks[l].trim_end_matches(":end").to_string();
        if !detect.contains(&j) {
            detect.push(j);
        }
    }
    detect
}

/// The pelvis: where the legs and the head chain part (`part`), or the nearest joint at or
/// above it named as a pelvis within 10 % of the height (Biped hangs the legs from a spine joint
/// just above `Bip01 Pelvis`).
fn pelvis_landmark(
    tree: &Tree,
    skeleton: &Skeleton,
    syn: &Synonyms,
    part: usize,
) -> (usize, f64, String) {
    let rule = "where the legs and the head chain part";
    let mut n = Some(part);
    while let Some(j) = n {
        let node = &tree.nodes[j];
        if (node.pos - tree.nodes[part].pos).length() > 0.1 * tree.height {
            break;
        }
        if syn.names(
            "pelvis",
            &syn.normalise(&skeleton.joints[node.joint].name).base,
        ) {
            let name = tree.name(skeleton, j);
            return if j == part {
                (
                    j,
                    1.0,
                    format!("name '{name}' and structure ({rule}) agree"),
                )
            } else {
                (
                    j,
                    0.85,
                    format!(
                        "name '{name}', just above '{}' ({rule})",
                        tree.name(skeleton, part)
                    ),
                )
            };
        }
        n = node.parent;
    }
    (part, 0.7, format!("structure: {rule}"))
}

fn side_word(conf: f64) -> &'static str {
    if conf >= 1.0 {
        "geometry and names agree"
    } else if conf >= 0.9 {
        "by geometry"
    } else if conf >= 0.75 {
        "by geometry, against the names"
    } else {
        "by names"
    }
}

impl AutoMapping {
    /// The mapping as an editable RON file: the [`Mapping`] format, each landmark line followed
    /// by a comment with its confidence and reason, and the notes at the top.
    pub fn to_ron(&self, title: &str) -> String {
        let mut s = format!(
            "// Mapping of {title} onto the engine's models, found automatically (names and \
             structure).\n// Each landmark names a source joint or \"<joint>:end\" (its End \
             Site); edit and pass it with --mapping (or as a dance manifest clip's `mapping:`).\n"
        );
        for n in &self.notes {
            s.push_str(&format!("// {n}\n"));
        }
        let q = |x: &str| format!("{x:?}");
        s.push_str(&format!(
            "(\n    format_version: {},\n    name: {},\n    detect: [{}],\n    landmarks: {{\n",
            self.mapping.format_version,
            q(&self.mapping.name),
            self.mapping
                .detect
                .iter()
                .map(|d| q(d))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        for f in &self.findings {
            s.push_str(&format!(
                "        {}: {}, // {:.2}: {}\n",
                q(&f.landmark),
                q(&f.source),
                f.confidence,
                f.reason.replace('\n', " ")
            ));
        }
        s.push_str("    },\n)\n");
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometry_tells_the_sides_names_only_when_it_cannot() {
        use Side::{Centre, Left, Right};
        // Agreement, and geometry against the names: geometry wins with a note.
        assert_eq!(
            tell_sides("legs", Some(true), (Left, Right)).unwrap().1,
            1.0
        );
        let (first_left, conf, note) = tell_sides("legs", Some(false), (Left, Right)).unwrap();
        assert!(!first_left && conf < 1.0 && note.contains("geometry wins"));
        // Geometry undecided: the names decide; one side word is enough.
        let (first_left, conf, _) = tell_sides("arms", None, (Centre, Left)).unwrap();
        assert!(!first_left && conf < 0.9);
        // Neither: a clear refusal.
        let e = tell_sides("arms", None, (Centre, Centre)).unwrap_err();
        assert!(
            e.contains("cannot tell the left arms from the right"),
            "{e}"
        );
    }
}
