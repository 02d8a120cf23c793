//! Landmarks by structure: the five chains of a humanoid (two legs, two arms, the head) found
//! from the joint tree and one posed frame, without reading a single name.
//!
//! The tree's points are the joints and their End Sites, placed by the frame's forward
//! kinematics. Its *limb ends* are found like the extremities of a shape: first the two leaves
//! farthest apart along the tree, then, one at a time, the leaf that sticks out farthest from the
//! tree already spanned (path length to it at least 10 % of the figure's height `H`, and not lying
//! on a spanned bone, which a twist or helper bone does); fingers, toes and eyes stick out less and
//! stay part of their limb. A humanoid has five: the two lowest are the feet (and no third limb end
//! may be near the floor: a quadruped or a three-legged figure is refused there), of the three
//! others the head is the one nearest (along the tree) to where they part, the other two are the
//! hands. The pelvis is where the feet and the head part, the chest hub where the hands part.

use glam::DVec3;

use crate::skeleton::{Skeleton, Transform};

/// One point of the tree: a joint, or a joint's End Site.
#[derive(Clone, Debug)]
pub(crate) struct Node {
    /// Joint index in the skeleton.
    pub joint: usize,
    /// True for the joint's End Site.
    pub end_site: bool,
    /// Parent node.
    pub parent: Option<usize>,
    /// Child nodes.
    pub children: Vec<usize>,
    /// Position in the frame used, metres.
    pub pos: DVec3,
    depth: usize,
    /// Path length from the root along the bones, metres.
    root_dist: f64,
}

/// The skeleton's points as a tree, posed by one frame.
#[derive(Clone, Debug)]
pub(crate) struct Tree {
    /// Joints first (same indices as the skeleton), then End Sites.
    pub nodes: Vec<Node>,
    /// Vertical extent of the frame (`H`), metres.
    pub height: f64,
    /// Up axis (the engine's +Y).
    pub up: DVec3,
}

impl Tree {
    /// The tree of `skeleton`'s points at the pose given by `globals` (one per joint).
    pub fn new(skeleton: &Skeleton, globals: &[Transform]) -> Tree {
        let mut nodes: Vec<Node> = skeleton
            .joints
            .iter()
            .zip(globals)
            .enumerate()
            .map(|(i, (j, g))| Node {
                joint: i,
                end_site: false,
                parent: j.parent,
                children: vec![],
                pos: g.translation,
                depth: 0,
                root_dist: 0.0,
            })
            .collect();
        for (i, (j, g)) in skeleton.joints.iter().zip(globals).enumerate() {
            if let Some(e) = j.end_site {
                nodes.push(Node {
                    joint: i,
                    end_site: true,
                    parent: Some(i),
                    children: vec![],
                    pos: g.translation + g.rotation * e,
                    depth: 0,
                    root_dist: 0.0,
                });
            }
        }
        // Parents come first (joints are parents first, End Sites after all joints).
        for i in 0..nodes.len() {
            if let Some(p) = nodes[i].parent {
                nodes[p].children.push(i);
                nodes[i].depth = nodes[p].depth + 1;
                nodes[i].root_dist = nodes[p].root_dist + (nodes[i].pos - nodes[p].pos).length();
            }
        }
        let up = DVec3::Y;
        let hs = nodes.iter().map(|n| n.pos.dot(up));
        let (lo, hi) = hs.fold((f64::MAX, f64::MIN), |(a, b), h| (a.min(h), b.max(h)));
        Tree {
            nodes,
            height: (hi - lo).max(0.0),
            up,
        }
    }

    /// Lowest common ancestor of two nodes.
    pub fn lca(&self, mut a: usize, mut b: usize) -> usize {
        while self.nodes[a].depth > self.nodes[b].depth {
            a = self.nodes[a].parent.expect("deeper node has a parent");
        }
        while self.nodes[b].depth > self.nodes[a].depth {
            b = self.nodes[b].parent.expect("deeper node has a parent");
        }
        while a != b {
            match (self.nodes[a].parent, self.nodes[b].parent) {
                (Some(p), Some(q)) => (a, b) = (p, q),
                // Two roots: not one tree (a skeleton has one root).
                _ => return a,
            }
        }
        a
    }

    /// Path length between two nodes along the bones, metres.
    pub fn dist(&self, a: usize, b: usize) -> f64 {
        let c = self.lca(a, b);
        self.nodes[a].root_dist + self.nodes[b].root_dist - 2.0 * self.nodes[c].root_dist
    }

    /// Whether `a` is `b` or one of its ancestors.
    pub fn is_ancestor(&self, a: usize, b: usize) -> bool {
        self.lca(a, b) == a
    }

    /// The nodes from ancestor `top` down to `node`, both included.
    pub fn path(&self, top: usize, node: usize) -> Vec<usize> {
        let mut p = vec![node];
        let mut n = node;
        while n != top {
            match self.nodes[n].parent {
                Some(q) => {
                    n = q;
                    p.push(n);
                }
                None => break,
            }
        }
        p.reverse();
        p
    }

    /// Height of a node above the lowest point of the frame's figure, in units of `H`.
    fn rel_height(&self, n: usize, floor: f64) -> f64 {
        (self.nodes[n].pos.dot(self.up) - floor) / self.height.max(1e-12)
    }

    /// The source name of a node: `"<joint>"` or `"<joint>:end"`.
    pub fn name(&self, skeleton: &Skeleton, n: usize) -> String {
        let j = &skeleton.joints[self.nodes[n].joint].name;
        if self.nodes[n].end_site {
            format!("{j}:end")
        } else {
            j.clone()
        }
    }
}

/// The five chains of a humanoid, as node paths.
#[derive(Clone, Debug)]
pub(crate) struct Chains {
    /// Where the feet and the head part.
    pub pelvis: usize,
    /// Where the hands part.
    pub chest: usize,
    /// Pelvis → head end.
    pub spine: Vec<usize>,
    /// Pelvis → foot end, for the two legs (sides not yet told).
    pub legs: [Vec<usize>; 2],
    /// Chest hub → hand end, for the two arms (sides not yet told).
    pub arms: [Vec<usize>; 2],
}

/// Share of `H` a limb end must stick out from the spanned tree.
const LIMB_END_BRANCH: f64 = 0.10;
/// Share of `H` within which a leaf counts as lying on a spanned bone.
const ON_BONE: f64 = 0.02;
/// Share of `H` above the second foot within which a third limb end counts as on the floor.
const FLOOR_BAND: f64 = 0.15;

/// The limb ends of the tree (see the module documentation).
pub(crate) fn limb_ends(tree: &Tree) -> Vec<usize> {
    let leaves: Vec<usize> = (0..tree.nodes.len())
        .filter(|&i| tree.nodes[i].children.is_empty())
        .collect();
    if leaves.len() < 2 {
        return leaves;
    }
    let mut best = (0.0, leaves[0], leaves[1]);
    for (k, &a) in leaves.iter().enumerate() {
        for &b in &leaves[k + 1..] {
            let d = tree.dist(a, b);
            if d > best.0 {
                best = (d, a, b);
            }
        }
    }
    let mut picked = vec![best.1, best.2];
    let mut spanned = vec![false; tree.nodes.len()];
    let mark = |spanned: &mut Vec<bool>, a: usize, b: usize| {
        let c = tree.lca(a, b);
        for n in tree.path(c, a).into_iter().chain(tree.path(c, b)) {
            spanned[n] = true;
        }
    };
    mark(&mut spanned, best.1, best.2);
    let h = tree.height;
    loop {
        let top = (0..tree.nodes.len())
            .filter(|&n| spanned[n])
            .min_by_key(|&n| tree.nodes[n].depth)
            .expect("two leaves are spanned");
        let mut next: Option<(f64, usize, usize)> = None;
        for &x in &leaves {
            if spanned[x] {
                continue;
            }
            // Where x joins the spanned tree: its nearest spanned ancestor, else the top.
            let mut attach = top;
            let mut n = x;
            while let Some(p) = tree.nodes[n].parent {
                if spanned[p] {
                    attach = p;
                    break;
                }
                n = p;
            }
            let branch = tree.dist(x, attach);
            let on_bone = (0..tree.nodes.len())
                .filter(|&s| spanned[s])
                .filter_map(|s| tree.nodes[s].parent.filter(|&p| spanned[p]).map(|p| (p, s)))
                .any(|(p, s)| {
                    segment_distance(tree.nodes[x].pos, tree.nodes[p].pos, tree.nodes[s].pos)
                        < ON_BONE * h
                });
            if on_bone {
                continue;
            }
            if next.is_none_or(|(b, _, _)| branch > b) {
                next = Some((branch, x, attach));
            }
        }
        match next {
            Some((branch, x, attach)) if branch >= LIMB_END_BRANCH * h => {
                picked.push(x);
                mark(&mut spanned, x, attach);
            }
            _ => break,
        }
    }
    picked
}

/// Distance from `x` to the segment `a`–`b`.
fn segment_distance(x: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((x - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (x - (a + ab * t)).length()
}

/// The names of the nodes `v`, comma-separated.
fn node_names(tree: &Tree, skeleton: &Skeleton, v: &[usize]) -> String {
    v.iter()
        .map(|&n| tree.name(skeleton, n))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The limb ends, lowest first (relative to the lowest's height along up, `floor`), with the
/// second lowest's relative height. Errors: fewer than five ends, or more than two on the
/// floor.
fn limb_ends_by_height(tree: &Tree, skeleton: &Skeleton) -> Result<(Vec<usize>, f64, f64), String> {
    let names = |v: &[usize]| node_names(tree, skeleton, v);
    let mut ends = limb_ends(tree);
    if ends.len() < 5 {
        return Err(format!(
            "found {} limb end(s) ({}), a humanoid has five: two feet, two hands and the head",
            ends.len(),
            names(&ends)
        ));
    }
    let floor = ends
        .iter()
        .map(|&n| tree.nodes[n].pos.dot(tree.up))
        .fold(f64::MAX, f64::min);
    ends.sort_by(|&a, &b| {
        tree.rel_height(a, floor)
            .total_cmp(&tree.rel_height(b, floor))
    });
    let second = tree.rel_height(ends[1], floor);
    let on_floor: Vec<usize> = ends
        .iter()
        .copied()
        .filter(|&n| tree.rel_height(n, floor) < second + FLOOR_BAND)
        .collect();
    if on_floor.len() > 2 {
        return Err(format!(
            "{} limbs reach the floor ({}), a humanoid stands on two",
            on_floor.len(),
            names(&on_floor)
        ));
    }
    Ok((ends, floor, second))
}

/// The five chains of the tree, or why it is not a humanoid.
pub(crate) fn find_chains(tree: &Tree, skeleton: &Skeleton) -> Result<Chains, String> {
    if tree.height <= 1e-9 {
        return Err("the figure has no height in the frame used".into());
    }
    let names = |v: &[usize]| node_names(tree, skeleton, v);
    let (ends, floor, second) = limb_ends_by_height(tree, skeleton)?;
    let feet = [ends[0], ends[1]];
    let upper = &ends[2..];
    if upper.len() != 3 {
        return Err(format!(
            "found {} limb ends above the feet ({}), a humanoid has three: two hands and the head",
            upper.len(),
            names(upper)
        ));
    }
    let part = tree.lca(upper[0], tree.lca(upper[1], upper[2]));
    let head = *upper
        .iter()
        .min_by(|&&a, &&b| tree.dist(part, a).total_cmp(&tree.dist(part, b)))
        .expect("three limb ends");
    let hands: Vec<usize> = upper.iter().copied().filter(|&u| u != head).collect();
    let pelvis = tree.lca(feet[0], tree.lca(feet[1], head));
    let chest = tree.lca(hands[0], hands[1]);
    if !(tree.is_ancestor(pelvis, chest) && tree.is_ancestor(chest, head)) || chest == pelvis {
        return Err(format!(
            "the arms ({}) do not branch from the spine between the pelvis '{}' and the head '{}'",
            names(&hands),
            tree.name(skeleton, pelvis),
            tree.name(skeleton, head)
        ));
    }
    if tree.is_ancestor(feet[0], feet[1]) || tree.is_ancestor(feet[1], feet[0]) {
        return Err("the two lowest limb ends lie on one chain".into());
    }
    let above_feet = tree.rel_height(pelvis, floor) - second.min(tree.rel_height(ends[0], floor));
    let head_above = tree.rel_height(head, floor) - tree.rel_height(pelvis, floor);
    if above_feet < 0.25 || head_above < 0.2 {
        return Err(format!(
            "the figure is not upright in the frame used: the pelvis '{}' is {:.2} H above the \
             feet and the head end '{}' {:.2} H above the pelvis (a standing humanoid: about 0.5 \
             and 0.45)",
            tree.name(skeleton, pelvis),
            above_feet,
            tree.name(skeleton, head),
            head_above
        ));
    }
    Ok(Chains {
        pelvis,
        chest,
        spine: tree.path(pelvis, head),
        legs: [tree.path(pelvis, feet[0]), tree.path(pelvis, feet[1])],
        arms: [tree.path(chest, hands[0]), tree.path(chest, hands[1])],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::Joint;

    /// A T: a root with a long arm each way, a short twig on the left arm's bone and a short
    /// finger off its end.
    fn t_tree() -> (Skeleton, Tree) {
        let j = |name: &str, parent: Option<usize>, o: [f64; 3]| Joint {
            name: name.into(),
            parent,
            offset: DVec3::from_array(o),
            end_site: None,
        };
        let sk = Skeleton {
            joints: vec![
                j("root", None, [0.0, 1.0, 0.0]),
                j("a", Some(0), [0.5, 0.0, 0.0]),
                j("b", Some(1), [0.5, 0.0, 0.0]),
                j("twist", Some(1), [0.2, 0.0, 0.0]),
                j("finger", Some(2), [0.05, 0.0, 0.0]),
                j("c", Some(0), [-0.5, 0.0, 0.0]),
                j("d", Some(5), [-0.5, 0.0, 0.0]),
                j("e", Some(0), [0.0, -1.0, 0.0]),
            ],
        };
        let mut g = vec![Transform::IDENTITY; sk.joints.len()];
        let t: Vec<DVec3> = sk.joints.iter().map(|j| j.offset).collect();
        crate::skeleton::forward_kinematics(&sk, &t, &vec![glam::DQuat::IDENTITY; t.len()], &mut g);
        let tree = Tree::new(&sk, &g);
        (sk, tree)
    }

    #[test]
    fn limb_ends_skip_bones_lying_on_a_bone_and_short_twigs() {
        let (sk, tree) = t_tree();
        let mut ends: Vec<String> = limb_ends(&tree)
            .iter()
            .map(|&n| tree.name(&sk, n))
            .collect();
        ends.sort();
        assert_eq!(ends, ["d", "e", "finger"]);
        assert!((tree.dist(4, 6) - 2.05).abs() < 1e-12);
        assert_eq!(tree.lca(4, 3), 1);
        assert_eq!(tree.path(0, 4), [0, 1, 2, 4]);
    }

    #[test]
    fn segment_distance_is_to_the_nearest_point_of_the_segment() {
        let (a, b) = (DVec3::ZERO, DVec3::X);
        assert!((segment_distance(DVec3::new(0.5, 1.0, 0.0), a, b) - 1.0).abs() < 1e-12);
        assert!((segment_distance(DVec3::new(2.0, 0.0, 0.0), a, b) - 1.0).abs() < 1e-12);
        assert!((segment_distance(DVec3::new(3.0, 4.0, 0.0), a, a) - 5.0).abs() < 1e-12);
    }
}
