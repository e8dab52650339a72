//! Which binary nodes become the wide tree's nodes and leaves: the choice with the least
//! expected traversal cost (the surface area heuristic), found by dynamic programming
//! over the binary tree, after Ylitie, Karras and Laine (2017), "Efficient incoherent
//! ray traversal on GPUs through compressed wide BVHs", section 4.
//!
//! A wide node standing for binary node `n` has up to `width` children (sixteen or eight,
//! see [`super::wide`]), each a binary
//! node below `n`: the roots of a cut through `n`'s subtree. Each child is a leaf (a
//! subtree of at most [`MERGE`] primitives, tested as packets of four) or a wide node of
//! its own. `cost(n, i)` is the least cost of `n`'s subtree when it may take up to `i`
//! slots of its parent; it is built from the children's costs, leaves upward.

use super::binary::{BinaryTree, Kind};
use super::packet::LANES;
use super::wide::MAX_WIDTH;

/// The most primitives a leaf holds (two packets).
pub(super) const MERGE: u32 = 2 * LANES as u32;
/// The cost of visiting a wide node, against testing one packet of four primitives, per
/// unit of surface area. Measured on the benchmark dragons (docs/performance.md): 1.5
/// traced faster than 1.0 or 2.0; allowing leaves of twelve left the 100k dragon's tree
/// the same size.
const NODE_COST: f32 = 1.5;
const PACKET_COST: f32 = 1.0;

/// The plan: for every binary node, how its subtree is cut.
pub(super) struct Plan {
    decisions: Vec<Decision>,
    /// The most children of a wide node.
    width: usize,
}

/// How binary node `n`'s subtree is cut (the costs that chose it are gone by then).
#[derive(Clone, Copy, Default)]
struct Decision {
    /// `split[i - 1]` for `i ≥ 2`: how many of up to `i` slots go to the left child (0:
    /// the subtree takes no more than `i - 1`). `split[0]`: 0 when the subtree is one leaf.
    split: [u8; MAX_WIDTH],
    /// How many slots the left child gets when this node becomes a wide node.
    node_split: u8,
}

/// What a parent needs of a child subtree.
#[derive(Clone, Copy)]
struct Summary {
    /// `cost[i - 1]`: the least cost with up to `i` slots.
    cost: [f32; MAX_WIDTH],
    prims: u32,
    /// The most slots the subtree can fill (its binary leaves, at most `width`): `cost` is
    /// the same from there on.
    slots: usize,
}

/// Subtrees of more binary nodes than this are planned with a task for each child on the
/// pool's threads (each node's decision is the same whichever thread makes it).
const PARALLEL_NODES: usize = 1 << 14;

impl Plan {
    /// The plan of nodes of at most `width` children (2 to [`MAX_WIDTH`]).
    pub(super) fn new(tree: &BinaryTree, width: usize) -> Plan {
        assert!((2..=MAX_WIDTH).contains(&width));
        let mut decisions = vec![Decision::default(); tree.nodes.len()];
        if !decisions.is_empty() {
            plan_subtree(tree, &mut decisions, 0, width);
        }
        Plan { decisions, width }
    }

    /// Whether binary node `n`, as a child slot, is a leaf.
    pub(super) fn is_leaf(&self, n: u32) -> bool {
        self.decisions[n as usize].split[0] == 0
    }

    /// The children of the wide node standing for interior binary node `b`, in the
    /// binary tree's left-to-right order, and how many.
    pub(super) fn children(&self, tree: &BinaryTree, b: u32) -> ([u32; MAX_WIDTH], usize) {
        let Kind::Interior { left, right } = tree.nodes[b as usize].kind else {
            unreachable!("interior")
        };
        let mut out = ([0u32; MAX_WIDTH], 0usize);
        let k = self.decisions[b as usize].node_split as usize;
        self.cut(tree, left, k, &mut out);
        self.cut(tree, right, self.width - k, &mut out);
        out
    }

    /// Appends the roots of node `n`'s subtree cut into up to `i` slots.
    fn cut(&self, tree: &BinaryTree, n: u32, i: usize, out: &mut ([u32; MAX_WIDTH], usize)) {
        let mut i = i;
        let d = &self.decisions[n as usize];
        while i > 1 && d.split[i - 1] == 0 {
            i -= 1;
        }
        if i == 1 {
            out.0[out.1] = n;
            out.1 += 1;
            return;
        }
        let Kind::Interior { left, right } = tree.nodes[n as usize].kind else {
            unreachable!("a leaf takes one slot")
        };
        let k = d.split[i - 1] as usize;
        self.cut(tree, left, k, out);
        self.cut(tree, right, i - k, out);
    }
}

/// Plans binary node `first`'s subtree, whose decisions are `decisions` (a subtree's
/// nodes are contiguous: the node, its left subtree, its right subtree).
fn plan_subtree(tree: &BinaryTree, decisions: &mut [Decision], first: usize, width: usize) -> Summary {
    let node = &tree.nodes[first];
    let Kind::Interior { left, right } = node.kind else {
        let Kind::Leaf { count, .. } = node.kind else {
            unreachable!()
        };
        let cost = node.bounds.surface_area() * PACKET_COST * packets(count);
        return Summary {
            cost: [cost; MAX_WIDTH],
            prims: count,
            slots: 1,
        };
    };
    let parallel = decisions.len() > PARALLEL_NODES;
    let (own, rest) = decisions.split_at_mut(1);
    let (l, r) = rest.split_at_mut(right as usize - left as usize);
    let (l, r) = if parallel {
        rayon::join(
            || plan_subtree(tree, l, left as usize, width),
            || plan_subtree(tree, r, right as usize, width),
        )
    } else {
        (
            plan_subtree(tree, l, left as usize, width),
            plan_subtree(tree, r, right as usize, width),
        )
    };
    let (summary, decision) = combine(node.bounds.surface_area(), &l, &r, width);
    own[0] = decision;
    summary
}

fn packets(prims: u32) -> f32 {
    prims.div_ceil(LANES as u32) as f32
}

/// An interior node of surface area `area` over children `l` and `r`: its costs, and
/// how it is cut into nodes of at most `width` children.
fn combine(area: f32, l: &Summary, r: &Summary, width: usize) -> (Summary, Decision) {
    let prims = l.prims + r.prims;
    let slots = (l.slots + r.slots).min(width);
    // shared[j]: the least cost of both children in up to j slots, and the left child's
    // share of them. Slots beyond a child's `slots` change nothing, so they are not
    // tried (most nodes are near the leaves, with few).
    let mut shared = [f32::INFINITY; MAX_WIDTH + 1];
    let mut shared_split = [0u8; MAX_WIDTH + 1];
    for j in 2..=slots {
        for k in j.saturating_sub(r.slots).max(1)..=(j - 1).min(l.slots) {
            let c = l.cost[k - 1] + r.cost[j - k - 1];
            // (The first candidate is kept even when every cost is infinite: boxes whose
            // areas overflow `f32` still get a valid cut.)
            if c < shared[j] || shared_split[j] == 0 {
                shared[j] = c;
                shared_split[j] = k as u8;
            }
        }
    }
    // With room for more slots than the children can fill, the best is the fullest cut.
    for j in slots + 1..=width {
        shared[j] = shared[slots];
        shared_split[j] = shared_split[slots];
    }
    let as_node = area * NODE_COST + shared[width];
    let as_leaf = if prims <= MERGE {
        area * PACKET_COST * packets(prims)
    } else {
        f32::INFINITY
    };
    let mut cost = [0.0; MAX_WIDTH];
    let mut split = [0u8; MAX_WIDTH];
    cost[0] = as_node.min(as_leaf);
    split[0] = (prims > MERGE || as_leaf > as_node) as u8;
    for i in 2..=width {
        if shared[i] < cost[i - 2] {
            cost[i - 1] = shared[i];
            split[i - 1] = shared_split[i];
        } else {
            cost[i - 1] = cost[i - 2];
        }
    }
    let decision = Decision {
        split,
        node_split: shared_split[width],
    };
    (Summary { cost, prims, slots }, decision)
}

#[cfg(test)]
mod tests {
    use super::super::binary;
    use super::super::sah_bins::tests::boxes;
    use super::*;
    use std::collections::HashMap;

    fn area(tree: &BinaryTree, n: u32) -> f32 {
        tree.nodes[n as usize].bounds.surface_area()
    }

    fn prims(tree: &BinaryTree, n: u32) -> u32 {
        match tree.nodes[n as usize].kind {
            Kind::Leaf { count, .. } => count,
            Kind::Interior { left, right } => prims(tree, left) + prims(tree, right),
        }
    }

    /// Every way of cutting `n`'s subtree into at most `max` roots.
    fn cuts(tree: &BinaryTree, n: u32, max: usize) -> Vec<Vec<u32>> {
        let mut all = vec![vec![n]];
        if max < 2 {
            return all;
        }
        if let Kind::Interior { left, right } = tree.nodes[n as usize].kind {
            for a in cuts(tree, left, max - 1) {
                for b in cuts(tree, right, max - a.len()) {
                    all.push([a.clone(), b].concat());
                }
            }
        }
        all
    }

    /// The least cost of `n` as a child slot, by trying every cut below every node.
    /// (Each node's least slot cost is found once: `memo`.)
    fn best_slot(tree: &BinaryTree, n: u32, width: usize, memo: &mut HashMap<u32, f32>) -> f32 {
        if let Some(&c) = memo.get(&n) {
            return c;
        }
        let c = match tree.nodes[n as usize].kind {
            Kind::Leaf { count, .. } => area(tree, n) * PACKET_COST * packets(count),
            _ if prims(tree, n) <= MERGE => {
                (area(tree, n) * PACKET_COST * packets(prims(tree, n))).min(best_node(tree, n, width, memo))
            }
            _ => best_node(tree, n, width, memo),
        };
        memo.insert(n, c);
        c
    }

    fn best_node(tree: &BinaryTree, n: u32, width: usize, memo: &mut HashMap<u32, f32>) -> f32 {
        let Kind::Interior { left, right } = tree.nodes[n as usize].kind else {
            unreachable!()
        };
        let mut best = f32::INFINITY;
        for a in cuts(tree, left, width - 1) {
            for b in cuts(tree, right, width - a.len()) {
                let c: f32 = a.iter().chain(&b).map(|&m| best_slot(tree, m, width, memo)).sum();
                best = best.min(c);
            }
        }
        area(tree, n) * NODE_COST + best
    }

    /// The cost of the wide tree the plan makes below `n` as a wide node.
    fn planned_node(plan: &Plan, tree: &BinaryTree, n: u32) -> f32 {
        let (children, count) = plan.children(tree, n);
        let slots: f32 = children[..count]
            .iter()
            .map(|&m| match tree.nodes[m as usize].kind {
                Kind::Interior { .. } if !plan.is_leaf(m) => planned_node(plan, tree, m),
                _ => area(tree, m) * PACKET_COST * packets(prims(tree, m)),
            })
            .sum();
        area(tree, n) * NODE_COST + slots
    }

    #[test]
    fn the_plan_costs_what_the_best_of_every_cut_costs() {
        for (n, width) in [
            (9, 16),
            (17, 16),
            (24, 16),
            (33, 16),
            (41, 16),
            (17, 8),
            (33, 8),
            (41, 8),
        ] {
            let tree = binary::build(boxes(n).into_iter());
            let plan = Plan::new(&tree, width);
            let best = best_node(&tree, 0, width, &mut HashMap::new());
            let planned = planned_node(&plan, &tree, 0);
            assert!(
                (planned - best).abs() <= 1e-5 * best,
                "{n} boxes in nodes of {width}: {planned} against {best}"
            );
        }
    }

    #[test]
    fn every_primitive_is_in_exactly_one_child_of_each_node() {
        // Also with boxes so large that their areas overflow to infinity.
        for scale in [1.0, 1e30] {
            let scaled = boxes(500).into_iter().map(|(i, b)| {
                let b = crate::aabb::Aabb {
                    min: b.min * scale,
                    max: b.max * scale,
                };
                (i, b)
            });
            let tree = binary::build(scaled);
            check_cuts(&tree, 16);
            check_cuts(&tree, 8);
        }
    }

    fn check_cuts(tree: &BinaryTree, width: usize) {
        let plan = Plan::new(tree, width);
        let mut pending = vec![0u32];
        while let Some(n) = pending.pop() {
            let (children, count) = plan.children(tree, n);
            assert!((2..=width).contains(&count));
            let total: u32 = children[..count].iter().map(|&m| prims(tree, m)).sum();
            assert_eq!(total, prims(tree, n));
            for &m in &children[..count] {
                if plan.is_leaf(m) {
                    assert!(prims(tree, m) <= MERGE || matches!(tree.nodes[m as usize].kind, Kind::Leaf { .. }));
                } else {
                    pending.push(m);
                }
            }
        }
    }
}
