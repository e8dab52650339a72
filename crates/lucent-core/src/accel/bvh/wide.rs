//! Second stage of the BVH build: the binary tree collapsed into nodes of `W` children,
//! 16 or 8 ([`super::Isa::node_width`]).
//!
//! Each wide node takes the place of a binary node and adopts the roots of a cut through
//! its subtree as its (up to `W`) children; each child is a leaf (a subtree of at most
//! eight primitives, one or two packets) or a wide node of its own. Which cut, and which
//! subtrees become leaves, is the plan of [`super::collapse_plan`]: the least expected
//! cost by the surface area heuristic. The node stores its children's boxes as
//! structure-of-arrays, so two eight-lane instructions (AVX, or AVX-512 VL; four SSE) test
//! all sixteen.
//!
//! Why sixteen: a single ray's walk waits, at every node, on the chain from loading a
//! child's reference to choosing the next child, so fewer levels are fewer waits; the
//! second group of eight boxes is tested beside the first, off that chain. Against
//! nodes of eight (on an AMD EPYC, Zen 4, paired): single rays 1.02–1.06× faster on
//! the dragons with the AVX-512 build, about the same with AVX2 alone (0.96–1.01×),
//! packets of rays the same, the same memory per triangle (see `docs/performance.md`).
//! Why eight with AVX2: on a CPU without AVX-512 (an AMD EPYC, Zen 3) nodes of eight,
//! one AVX2 group a visit, traced primary rays 1.01–1.09× faster and the others about
//! the same (sixteen vector registers do not hold a ray's constants and two groups).
//! With AVX-512 on an Intel Xeon, nodes of sixteen were 1.00–1.07× faster than nodes of
//! eight, both tested eight boxes at a time into mask registers.
//!
//! Leaves become runs of four-wide packets, laid out in the order traversal meets them.
//! With more than one thread, large subtrees are laid out by tasks of their own, each as
//! parts in the one-thread order, put together at the end; the packets are filled on the
//! pool's threads: the same tree for any number of threads.

use super::binary::{BinaryNode, BinaryTree, Kind, MAX_LEAF};
use super::collapse_plan::{Plan, MERGE};
use super::packet::{Packet, LANES};
use crate::accel::PrimitiveSet;

/// The most children a node has: sixteen for AVX-512 (and the portable paths), eight for
/// AVX2 (see [`super::Isa::node_width`]).
pub const MAX_WIDTH: usize = 16;
/// A child slot that is a leaf: `LEAF | (packets - 1) << PACKET_SHIFT | first packet`;
/// an interior child is the byte offset of its node in the node array.
pub const LEAF: u32 = 1 << 31;
pub const PACKET_SHIFT: u32 = 28;
pub const FIRST_MASK: u32 = (1 << PACKET_SHIFT) - 1;
/// An unused slot; its box is empty (min > max), so no ray ever enters it.
pub const EMPTY: u32 = 0;

/// `W` child boxes and references. `bounds[0..3]` are the minima along x, y, z,
/// `bounds[3..6]` the maxima; lane `i` belongs to child `i`.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct WideNode<const W: usize = MAX_WIDTH> {
    pub bounds: [[f32; W]; 6],
    pub child: [u32; W],
}

const _: () = assert!(MAX_LEAF.div_ceil(LANES) <= 1 << (31 - PACKET_SHIFT));

impl<const W: usize> WideNode<W> {
    pub const EMPTY: WideNode<W> = WideNode {
        bounds: [
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
        ],
        child: [EMPTY; W],
    };
}

pub struct WideTree<const W: usize> {
    pub nodes: Vec<WideNode<W>>,
    pub packets: Vec<Packet>,
}

/// How many node levels the tree has (a root whose children are all leaves: 1); what
/// the traversal stack must hold.
pub fn levels<const W: usize>(nodes: &[WideNode<W>]) -> usize {
    if nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    // (byte offset of a node, its level)
    let mut pending = vec![(0usize, 1usize)];
    while let Some((offset, level)) = pending.pop() {
        deepest = deepest.max(level);
        let node = &nodes[offset / std::mem::size_of::<WideNode<W>>()];
        for &child in &node.child {
            if child != EMPTY && child & LEAF == 0 {
                pending.push((child as usize, level + 1));
            }
        }
    }
    deepest
}

/// The tree in nodes of at most `W` children.
pub fn collapse<const W: usize, P: PrimitiveSet + ?Sized>(tree: &BinaryTree, prims: &P) -> WideTree<W> {
    let threads = rayon::current_num_threads();
    let plan = Plan::new(tree, W);
    let plan = &plan;
    let parts = match tree.nodes.first() {
        None => vec![],
        // A lone leaf still gets a node above it: traversal starts at a node.
        Some(
            root @ BinaryNode {
                kind: Kind::Leaf { .. },
                ..
            },
        ) => {
            let mut part = Part::with_capacity(1, 1);
            part.nodes.push(WideNode::EMPTY);
            let slot = leaf_slot(root, &mut part);
            set_child(&mut part.nodes[0], 0, root, slot);
            vec![part]
        }
        Some(_) if threads == 1 => {
            let mut part = Part::with_capacity(tree.nodes.len() / 4 + 1, tree.refs.len() / 3 + 1);
            collapse_node(tree, plan, 0, &mut part);
            vec![part]
        }
        Some(_) => {
            // Enough tasks to keep every thread busy, few enough that parts stay large.
            let parallel = PARALLEL_REFS.max(tree.refs.len() / (8 * threads));
            collapse_parallel(tree, plan, 0, parallel)
        }
    };
    let (nodes, packet_refs) = join_parts(parts);
    // The packets' corners are gathered from the primitives (scattered reads, most of
    // the collapse's time) on the pool's threads, each written in its place: the same
    // packets for any number of threads.
    let mut packets = crate::huge_pages::vec_with_capacity(packet_refs.len());
    {
        use rayon::prelude::*;
        packets.par_extend(packet_refs.par_iter().map(|&(start, count)| {
            let mut ids = [0u32; LANES];
            let chunk = &tree.refs[start as usize..(start + count) as usize];
            for (id, r) in ids.iter_mut().zip(chunk) {
                *id = r.prim;
            }
            Packet::new(prims, &ids[..chunk.len()])
        }));
    }
    WideTree { nodes, packets }
}

/// With more than one thread, subtrees of more than this many references (more for
/// large trees: see [`collapse`]) are collapsed with a parallel task for each large child.
const PARALLEL_REFS: usize = 4096;

/// A run of the wide tree in the one-thread order, laid out on its own: its nodes and,
/// for each packet, the references it will hold (`tree.refs[start..start + count]`).
/// Its interior references count (in bytes) from its first node, its leaf references
/// from its first packet; [`join_parts`] moves them to their places.
struct Part<const W: usize> {
    nodes: Vec<WideNode<W>>,
    packet_refs: Vec<(u32, u32)>,
}

impl<const W: usize> Part<W> {
    fn with_capacity(nodes: usize, packets: usize) -> Part<W> {
        Part {
            nodes: crate::huge_pages::vec_with_capacity(nodes),
            packet_refs: Vec::with_capacity(packets),
        }
    }
}

/// How many references the subtree under binary node `n` holds (they are contiguous:
/// from its leftmost leaf's first to its rightmost leaf's last).
fn subtree_refs(tree: &BinaryTree, n: u32) -> usize {
    let (mut first, mut last) = (n, n);
    while let Kind::Interior { left, .. } = tree.nodes[first as usize].kind {
        first = left;
    }
    while let Kind::Interior { right, .. } = tree.nodes[last as usize].kind {
        last = right;
    }
    match (tree.nodes[first as usize].kind, tree.nodes[last as usize].kind) {
        (Kind::Leaf { start, .. }, Kind::Leaf { start: s, count }) => (s + count - start) as usize,
        _ => unreachable!("leaves"),
    }
}

/// The wide subtree standing for interior binary node `b` as consecutive parts: the
/// nodes and packets of [`collapse_node`], in its order, with large child subtrees
/// collapsed on the pool's threads.
fn collapse_parallel<const W: usize>(tree: &BinaryTree, plan: &Plan, b: u32, parallel: usize) -> Vec<Part<W>> {
    let refs = subtree_refs(tree, b);
    if refs <= parallel {
        // About one node for every six references, one packet for every three.
        let mut part = Part::with_capacity(refs / 6 + 1, refs / 3 + 1);
        collapse_node(tree, plan, b, &mut part);
        return vec![part];
    }
    let (children, count) = plan.children(tree, b);
    let children = &children[..count];
    let leaves: Vec<Option<(u32, u32)>> = children.iter().map(|&c| leaf_refs(tree, plan, c)).collect();
    let subtrees: Vec<Vec<Part<W>>> = {
        use rayon::prelude::*;
        let interior: Vec<u32> = (children.iter().zip(&leaves))
            .filter_map(|(&c, leaf)| leaf.is_none().then_some(c))
            .collect();
        interior
            .par_iter()
            .map(|&c| collapse_parallel(tree, plan, c, parallel))
            .collect()
    };
    let mut subtrees = subtrees.into_iter();
    // This node first, then its children in slot order: a leaf child's packets where
    // `collapse_node` puts them, between the parts of the subtrees.
    let mut parts = vec![Part {
        nodes: vec![WideNode::EMPTY],
        packet_refs: Vec::new(),
    }];
    let mut node = WideNode::EMPTY;
    // Nodes and packets laid out since this node's part began.
    let (mut nodes_before, mut packets_before) = (1usize, 0usize);
    for (slot, (&c, leaf)) in children.iter().zip(&leaves).enumerate() {
        let reference = match *leaf {
            Some((start, count)) => {
                let last = parts.last_mut().expect("this node's part");
                let first = packets_before + last.packet_refs.len();
                push_packets(start, count, first, &mut last.packet_refs)
            }
            None => {
                if let Some(last) = parts.last() {
                    packets_before += last.packet_refs.len();
                }
                let offset = byte_offset::<W>(nodes_before);
                for part in subtrees.next().expect("a subtree for each interior child") {
                    nodes_before += part.nodes.len();
                    packets_before += part.packet_refs.len();
                    parts.push(part);
                }
                // For the packets of the leaf children that follow.
                parts.push(Part {
                    nodes: Vec::new(),
                    packet_refs: Vec::new(),
                });
                offset
            }
        };
        set_child(&mut node, slot, &tree.nodes[c as usize], reference);
    }
    parts[0].nodes[0] = node;
    parts
}

/// The parts put together: each part's references moved by the nodes and packets before
/// it, the nodes written in place on the pool's threads.
fn join_parts<const W: usize>(mut parts: Vec<Part<W>>) -> (Vec<WideNode<W>>, Vec<(u32, u32)>) {
    if parts.len() <= 1 {
        return parts.pop().map_or_else(Default::default, |p| (p.nodes, p.packet_refs));
    }
    // Each part's first node and first packet in the whole tree.
    let mut node_base = Vec::with_capacity(parts.len());
    let mut packet_base = Vec::with_capacity(parts.len());
    let (mut nodes, mut packets) = (0usize, 0usize);
    for part in &parts {
        node_base.push(nodes);
        packet_base.push(packets);
        nodes += part.nodes.len();
        packets += part.packet_refs.len();
    }
    let mut out = crate::huge_pages::vec_with_capacity(nodes);
    {
        use rayon::prelude::*;
        out.par_extend((0..nodes).into_par_iter().map(|i| {
            // The last part that begins at or before node i (an empty part begins where
            // the next one does).
            let k = node_base.partition_point(|&b| b <= i) - 1;
            let mut node = parts[k].nodes[i - node_base[k]];
            for c in &mut node.child {
                *c = relocate::<W>(*c, node_base[k], packet_base[k]);
            }
            node
        }));
    }
    let mut packet_refs = Vec::with_capacity(packets);
    for part in &parts {
        packet_refs.extend_from_slice(&part.packet_refs);
    }
    (out, packet_refs)
}

/// A child reference of a part whose first node and first packet are `node_base` and
/// `packet_base` of the whole tree, as the whole tree's reference.
fn relocate<const W: usize>(c: u32, node_base: usize, packet_base: usize) -> u32 {
    if c == EMPTY {
        EMPTY
    } else if c & LEAF != 0 {
        let first = (c & FIRST_MASK) as usize + packet_base;
        (c & !FIRST_MASK) | checked_first(first)
    } else {
        byte_offset::<W>(c as usize / std::mem::size_of::<WideNode<W>>() + node_base)
    }
}

/// A packet index as a leaf reference holds it.
fn checked_first(first: usize) -> u32 {
    assert!(
        first <= FIRST_MASK as usize,
        "too many primitives for the BVH's 28-bit packet index"
    );
    first as u32
}

/// The reference to the node at `index`: interior children are referenced by byte
/// offset, so traversal needs no multiplication between loading a reference and
/// loading the node.
fn byte_offset<const W: usize>(index: usize) -> u32 {
    let offset = index * std::mem::size_of::<WideNode<W>>();
    assert!(
        offset < LEAF as usize,
        "too many nodes for the BVH's 31-bit node offsets"
    );
    offset as u32
}

fn set_child<const W: usize>(node: &mut WideNode<W>, slot: usize, child: &BinaryNode, reference: u32) {
    let (lo, hi) = (child.bounds.min, child.bounds.max);
    for axis in 0..3 {
        node.bounds[axis][slot] = lo[axis];
        node.bounds[axis + 3][slot] = hi[axis];
    }
    node.child[slot] = reference;
}

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

/// The references `refs[start..start + count]` as packets appended to `packet_refs`,
/// the first of them packet `first` of its part; returns the leaf's slot reference.
fn push_packets(start: u32, count: u32, first: usize, packet_refs: &mut Vec<(u32, u32)>) -> u32 {
    for k in (0..count).step_by(LANES) {
        packet_refs.push((start + k, (count - k).min(LANES as u32)));
    }
    let n = count.div_ceil(LANES as u32);
    LEAF | (n - 1) << PACKET_SHIFT | checked_first(first)
}

/// Lays out the packets of a binary leaf; returns its slot reference.
fn leaf_slot<const W: usize>(leaf: &BinaryNode, out: &mut Part<W>) -> u32 {
    let Kind::Leaf { start, count } = leaf.kind else {
        unreachable!("a leaf")
    };
    push_packets(start, count, out.packet_refs.len(), &mut out.packet_refs)
}

/// The references of child `c` if it becomes a leaf: a binary leaf, or a subtree the
/// plan merges into one.
fn leaf_refs(tree: &BinaryTree, plan: &Plan, c: u32) -> Option<(u32, u32)> {
    match tree.nodes[c as usize].kind {
        Kind::Leaf { start, count } => Some((start, count)),
        Kind::Interior { .. } if plan.is_leaf(c) => small_subtree(tree, c),
        Kind::Interior { .. } => None,
    }
}

/// Builds the wide node standing for interior binary node `b`, its subtree after it;
/// returns its index.
fn collapse_node<const W: usize>(tree: &BinaryTree, plan: &Plan, b: u32, out: &mut Part<W>) -> u32 {
    let (children, count) = plan.children(tree, b);
    let me = out.nodes.len();
    out.nodes.push(WideNode::EMPTY);
    for (slot, &c) in children[..count].iter().enumerate() {
        let reference = match leaf_refs(tree, plan, c) {
            Some((start, n)) => push_packets(start, n, out.packet_refs.len(), &mut out.packet_refs),
            None => byte_offset::<W>(collapse_node(tree, plan, c, out) as usize),
        };
        set_child(&mut out.nodes[me], slot, &tree.nodes[c as usize], reference);
    }
    me as u32
}
