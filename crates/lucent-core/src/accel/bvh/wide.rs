//! Second stage of the BVH build: the binary tree collapsed into 8-wide nodes.
//!
//! Each wide node takes the place of a binary node and adopts its descendants: it starts
//! with the two children and keeps opening the child with the largest surface area until
//! it has eight (or only leaves are left); a child subtree of at most eight primitives
//! becomes one leaf (of at most two packets) instead of a node. The node stores its
//! children's boxes as structure-of-arrays, so one AVX instruction (or two SSE ones)
//! tests all eight. Leaves become runs of four-wide packets, laid out in the order
//! traversal meets them; the nodes are laid out on one thread, then the packets are
//! filled on the pool's threads.

use super::binary::{BinaryNode, BinaryTree, Kind, MAX_LEAF};
use super::packet::{Packet, LANES};
use crate::accel::PrimitiveSet;

pub const WIDTH: usize = 8;
/// A child slot that is a leaf: `LEAF | (packets - 1) << PACKET_SHIFT | first packet`;
/// an interior child is the byte offset of its node in the node array.
pub const LEAF: u32 = 1 << 31;
pub const PACKET_SHIFT: u32 = 28;
pub const FIRST_MASK: u32 = (1 << PACKET_SHIFT) - 1;
/// An unused slot; its box is empty (min > max), so no ray ever enters it.
pub const EMPTY: u32 = 0;

/// Eight child boxes and references. `bounds[0..3]` are the minima along x, y, z,
/// `bounds[3..6]` the maxima; lane `i` belongs to child `i`.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct WideNode {
    pub bounds: [[f32; WIDTH]; 6],
    pub child: [u32; WIDTH],
}

const _: () = assert!(MAX_LEAF.div_ceil(LANES) <= 1 << (31 - PACKET_SHIFT));

impl WideNode {
    pub const EMPTY: WideNode = WideNode {
        bounds: [
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        child: [EMPTY; WIDTH],
    };
}

pub struct WideTree {
    pub nodes: Vec<WideNode>,
    pub packets: Vec<Packet>,
}

/// How many node levels the tree has (a root whose children are all leaves: 1); what
/// the traversal stack must hold.
pub fn levels(nodes: &[WideNode]) -> usize {
    if nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    // (byte offset of a node, its level)
    let mut pending = vec![(0usize, 1usize)];
    while let Some((offset, level)) = pending.pop() {
        deepest = deepest.max(level);
        let node = &nodes[offset / std::mem::size_of::<WideNode>()];
        for &child in &node.child {
            if child != EMPTY && child & LEAF == 0 {
                pending.push((child as usize, level + 1));
            }
        }
    }
    deepest
}

pub fn collapse<P: PrimitiveSet + ?Sized>(tree: &BinaryTree, prims: &P) -> WideTree {
    let mut out = Collapse {
        nodes: crate::huge_pages::vec_with_capacity(tree.nodes.len() / 4 + 1),
        packet_refs: Vec::with_capacity(prims.count() / 3 + 1),
    };
    if let Some(root) = tree.nodes.first() {
        match root.kind {
            // A lone leaf still gets a node above it: traversal starts at a node.
            Kind::Leaf { .. } => {
                out.nodes.push(WideNode::EMPTY);
                let slot = leaf_slot(root, &mut out);
                set_child(&mut out.nodes[0], 0, root, slot);
            }
            Kind::Interior { .. } => {
                collapse_node(tree, 0, &mut out);
            }
        }
    }
    // The packets' corners are gathered from the primitives (scattered reads, most of
    // the collapse's time) on the pool's threads, each written in its place: the same
    // packets for any number of threads.
    let mut packets = crate::huge_pages::vec_with_capacity(out.packet_refs.len());
    {
        use rayon::prelude::*;
        packets.par_extend(out.packet_refs.par_iter().map(|&(start, count)| {
            let mut ids = [0u32; LANES];
            let chunk = &tree.refs[start as usize..(start + count) as usize];
            for (id, r) in ids.iter_mut().zip(chunk) {
                *id = r.prim;
            }
            Packet::new(prims, &ids[..chunk.len()])
        }));
    }
    WideTree {
        nodes: out.nodes,
        packets,
    }
}

/// The wide tree as the collapse lays it out: its nodes, and for each packet the
/// references it will hold (`tree.refs[start..start + count]`).
struct Collapse {
    nodes: Vec<WideNode>,
    packet_refs: Vec<(u32, u32)>,
}

fn set_child(node: &mut WideNode, slot: usize, child: &BinaryNode, reference: u32) {
    let (lo, hi) = (child.bounds.min, child.bounds.max);
    for axis in 0..3 {
        node.bounds[axis][slot] = lo[axis];
        node.bounds[axis + 3][slot] = hi[axis];
    }
    node.child[slot] = reference;
}

/// A subtree with at most this many primitives becomes one leaf (of at most two packets)
/// rather than a node of its own. Such subtrees are what is left over below a full
/// node, and a node with two small leaves costs a visit that testing both packets
/// outright does not (measured: 3–5% faster on the benchmark dragons; 12 is no better).
const MERGE: u32 = 2 * LANES as u32;
const _: () = assert!((MERGE as usize).div_ceil(LANES) <= 1 << (31 - PACKET_SHIFT));

/// The references under binary node `n`, `(start, count)` (a subtree's references are
/// contiguous), if there are at most [`MERGE`]; stops looking as soon as there are more.
fn small_subtree(tree: &BinaryTree, n: u32) -> Option<(u32, u32)> {
    match tree.nodes[n as usize].kind {
        Kind::Leaf { start, count } => (count <= MERGE).then_some((start, count)),
        Kind::Interior { left, right } => {
            let (start, a) = small_subtree(tree, left)?;
            let (_, b) = small_subtree(tree, right)?;
            (a + b <= MERGE).then_some((start, a + b))
        }
    }
}

/// Lays out the packets of a binary leaf; returns its slot reference.
fn leaf_slot(leaf: &BinaryNode, out: &mut Collapse) -> u32 {
    let Kind::Leaf { start, count } = leaf.kind else {
        unreachable!("a leaf")
    };
    let first = out.packet_refs.len() as u32;
    for k in (0..count).step_by(LANES) {
        out.packet_refs.push((start + k, (count - k).min(LANES as u32)));
    }
    let n = out.packet_refs.len() as u32 - first;
    assert!(
        first <= FIRST_MASK,
        "too many primitives for the BVH's 28-bit packet index"
    );
    LEAF | (n - 1) << PACKET_SHIFT | first
}

/// Builds the wide node standing for interior binary node `b`; returns its index.
fn collapse_node(tree: &BinaryTree, b: u32, out: &mut Collapse) -> u32 {
    let Kind::Interior { left, right } = tree.nodes[b as usize].kind else {
        unreachable!("interior")
    };
    let mut children = Vec::with_capacity(WIDTH);
    children.extend([left, right]);
    while children.len() < WIDTH {
        // Open the interior child with the largest surface area.
        let widest = children
            .iter()
            .enumerate()
            .filter(|(_, &c)| matches!(tree.nodes[c as usize].kind, Kind::Interior { .. }))
            .max_by(|(_, &a), (_, &c)| {
                let area = |n: u32| tree.nodes[n as usize].bounds.surface_area();
                area(a).total_cmp(&area(c))
            })
            .map(|(i, _)| i);
        let Some(i) = widest else { break };
        let Kind::Interior { left, right } = tree.nodes[children[i] as usize].kind else {
            unreachable!()
        };
        children[i] = left;
        children.insert(i + 1, right);
    }
    let me = out.nodes.len();
    out.nodes.push(WideNode::EMPTY);
    for (slot, &c) in children.iter().enumerate() {
        let child = &tree.nodes[c as usize];
        let reference = match child.kind {
            Kind::Leaf { .. } => leaf_slot(child, out),
            Kind::Interior { .. } if let Some((start, count)) = small_subtree(tree, c) => {
                let merged = BinaryNode {
                    bounds: child.bounds,
                    kind: Kind::Leaf { start, count },
                };
                leaf_slot(&merged, out)
            }
            Kind::Interior { .. } => {
                // Interior children are referenced by byte offset: traversal then needs
                // no multiplication between loading a reference and loading the node.
                let offset = collapse_node(tree, c, out) as usize * std::mem::size_of::<WideNode>();
                assert!(
                    offset < LEAF as usize,
                    "too many nodes for the BVH's 31-bit node offsets"
                );
                offset as u32
            }
        };
        set_child(&mut out.nodes[me], slot, child, reference);
    }
    me as u32
}
