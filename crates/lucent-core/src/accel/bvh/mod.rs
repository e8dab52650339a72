//! Bounding volume hierarchy (`--accel bvh`, the default): an 8-wide BVH over packets
//! of four triangles.
//!
//! Build ([`binary`], [`wide`]): a binned-SAH binary tree, collapsed into nodes of eight
//! children whose boxes are stored as structure-of-arrays; leaves become packets of four
//! primitives with precomputed triangle corners in SIMD layout ([`packet`]).
//!
//! Traversal ([`traverse`]): eight box tests per visit with AVX when the CPU has it
//! (decided once, at build time, with `is_x86_feature_detected!`), two SSE halves when
//! not; nearest child first, an explicit fixed-size stack, no allocation per ray; the
//! packet test is bit-identical to the scalar watertight triangle test, so the answers
//! are exactly the brute-force list's.

mod binary;
mod packet;
mod traverse;
mod wide;

use super::{Accelerator, PrimitiveSet};
use crate::hit::Hit;
use crate::ray::PreparedRay;
use packet::Packet;
use wide::WideNode;

/// The box-test implementation chosen for this CPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    Avx2,
    Sse2,
    Scalar,
}

impl Isa {
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                Isa::Avx2
            } else {
                Isa::Sse2
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Isa::Scalar
        }
    }
}

pub struct Bvh {
    nodes: Vec<WideNode>,
    packets: Vec<Packet>,
    isa: Isa,
}

impl Bvh {
    pub fn build<P: PrimitiveSet + ?Sized>(prims: &P) -> Bvh {
        Bvh::build_for(prims, Isa::detect())
    }

    /// Builds for a given instruction set (tests use this to check every path).
    pub fn build_for<P: PrimitiveSet + ?Sized>(prims: &P, isa: Isa) -> Bvh {
        let tree = binary::build(super::bounded(prims));
        let wide = wide::collapse(&tree, prims);
        #[cfg(target_arch = "x86_64")]
        assert!(
            isa != Isa::Avx2 || std::arch::is_x86_feature_detected!("avx2"),
            "AVX2 requested on a CPU without it"
        );
        Bvh {
            nodes: wide.nodes,
            packets: wide.packets,
            isa,
        }
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Every primitive index the leaves hold, in leaf order.
    #[cfg(test)]
    fn leaf_prims(&self) -> Vec<u32> {
        self.packets
            .iter()
            .flat_map(|p| (0..packet::LANES).filter_map(|l| p.prim(l)))
            .collect()
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn closest_avx2<P: PrimitiveSet + ?Sized>(b: &Bvh, prims: &P, r: &PreparedRay, zero: bool) -> Option<Hit> {
    if zero {
        traverse::closest::<traverse::Avx, true, P>(&b.nodes, &b.packets, prims, r)
    } else {
        traverse::closest::<traverse::Avx, false, P>(&b.nodes, &b.packets, prims, r)
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn occluded_avx2<P: PrimitiveSet + ?Sized>(b: &Bvh, prims: &P, r: &PreparedRay, zero: bool) -> bool {
    if zero {
        traverse::occluded::<traverse::Avx, true, P>(&b.nodes, &b.packets, prims, r)
    } else {
        traverse::occluded::<traverse::Avx, false, P>(&b.nodes, &b.packets, prims, r)
    }
}

fn has_zero_axis(r: &PreparedRay) -> bool {
    r.zero_axes.any()
}

impl<P: PrimitiveSet + ?Sized> Accelerator<P> for Bvh {
    fn closest_hit(&self, prims: &P, r: &PreparedRay) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let zero = has_zero_axis(r);
        // SAFETY: node and packet references were built by `wide::collapse` for these
        // primitives; the AVX2 path is only taken when the CPU has AVX2 (checked at build).
        unsafe {
            match self.isa {
                #[cfg(target_arch = "x86_64")]
                Isa::Avx2 => closest_avx2(self, prims, r, zero),
                #[cfg(target_arch = "x86_64")]
                Isa::Sse2 if zero => traverse::closest::<traverse::Sse, true, P>(&self.nodes, &self.packets, prims, r),
                #[cfg(target_arch = "x86_64")]
                Isa::Sse2 => traverse::closest::<traverse::Sse, false, P>(&self.nodes, &self.packets, prims, r),
                _ if zero => traverse::closest::<traverse::Scalar, true, P>(&self.nodes, &self.packets, prims, r),
                _ => traverse::closest::<traverse::Scalar, false, P>(&self.nodes, &self.packets, prims, r),
            }
        }
    }

    fn occluded(&self, prims: &P, r: &PreparedRay) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let zero = has_zero_axis(r);
        // SAFETY: as in `closest_hit`.
        unsafe {
            match self.isa {
                #[cfg(target_arch = "x86_64")]
                Isa::Avx2 => occluded_avx2(self, prims, r, zero),
                #[cfg(target_arch = "x86_64")]
                Isa::Sse2 if zero => traverse::occluded::<traverse::Sse, true, P>(&self.nodes, &self.packets, prims, r),
                #[cfg(target_arch = "x86_64")]
                Isa::Sse2 => traverse::occluded::<traverse::Sse, false, P>(&self.nodes, &self.packets, prims, r),
                _ if zero => traverse::occluded::<traverse::Scalar, true, P>(&self.nodes, &self.packets, prims, r),
                _ => traverse::occluded::<traverse::Scalar, false, P>(&self.nodes, &self.packets, prims, r),
            }
        }
    }

    fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<WideNode>() + self.packets.len() * std::mem::size_of::<Packet>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::test_scenes::soup;

    #[test]
    fn every_primitive_is_in_exactly_one_leaf_and_nodes_are_wide() {
        let prims = soup(11, 5000);
        let bvh = Bvh::build(prims.as_slice());
        let mut seen = bvh.leaf_prims();
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..prims.len() as u32));
        // A binary tree with leaves of up to four would need about n/2 nodes; eight-wide
        // nodes need several times fewer.
        assert!(
            bvh.node_count() > 50 && bvh.node_count() < prims.len() / 6,
            "{}",
            bvh.node_count()
        );
        // Packets are mostly full.
        assert!(bvh.packets.len() * packet::LANES < prims.len() * 3 / 2);
    }
}
