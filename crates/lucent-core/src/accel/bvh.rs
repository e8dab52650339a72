//! Bounding volume hierarchy (`--accel bvh`, the default).
//!
//! Build: top-down, binned surface area heuristic (Wald 2007): at each node the
//! primitive centroids are sorted into 16 bins along each axis, the 15 candidate planes
//! per axis are priced with `C_trav + (A_l N_l + A_r N_r) / A`, and the node becomes a
//! leaf when that is no cheaper than testing its primitives. Below depth 48 (which only
//! pathological inputs reach) nodes are split at the object median so the depth stays
//! bounded.
//!
//! Layout: 32-byte nodes in depth-first order; an interior node's left child follows it,
//! its right child is stored. Traversal tests both children's boxes, visits the nearer
//! first and keeps the other on a fixed-size stack; shadow rays stop at the first hit.

use super::Accelerator;
use crate::aabb::Aabb;
use crate::hit::Hit;
use crate::math::{component, Vec3A};
use crate::primitive::Primitive;
use crate::ray::{PreparedRay, Ray};

const BINS: usize = 16;
const MAX_LEAF: usize = 8;
const TRAVERSAL_COST: f32 = 1.0;
const MEDIAN_SPLIT_DEPTH: usize = 48;
/// Deep enough for the median-split tail below `MEDIAN_SPLIT_DEPTH` for any `u32` count.
const STACK_SIZE: usize = MEDIAN_SPLIT_DEPTH + 40;

#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node {
    min: [f32; 3],
    /// Leaf: first index into `indices`. Interior: index of the right child.
    first_or_right: u32,
    max: [f32; 3],
    /// Number of primitives in a leaf; 0 for an interior node.
    count: u32,
}

impl Node {
    #[inline(always)]
    fn hit(&self, r: &PreparedRay, t_max: f32) -> Option<f32> {
        let b = Aabb {
            min: Vec3A::from(self.min),
            max: Vec3A::from(self.max),
        };
        b.intersect(r, t_max).map(|(enter, _)| enter)
    }
}

pub struct Bvh {
    nodes: Vec<Node>,
    /// Primitive indices (scene order) in leaf order.
    indices: Vec<u32>,
}

struct Builder<'a> {
    bounds: &'a [Aabb],
    centroids: &'a [Vec3A],
    indices: Vec<u32>,
    nodes: Vec<Node>,
}

impl Bvh {
    pub fn build(prims: &[Primitive]) -> Bvh {
        let bounds: Vec<Aabb> = prims.iter().map(|p| p.bounds()).collect();
        let centroids: Vec<Vec3A> = bounds.iter().map(|b| b.centroid()).collect();
        let mut b = Builder {
            bounds: &bounds,
            centroids: &centroids,
            indices: (0..prims.len() as u32).collect(),
            nodes: Vec::with_capacity(2 * prims.len().max(1)),
        };
        // No primitives, no nodes: a lone node with count 0 would read as interior.
        if !prims.is_empty() {
            b.build_node(0, prims.len(), 0);
        }
        Bvh {
            nodes: b.nodes,
            indices: b.indices,
        }
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }
}

impl Builder<'_> {
    fn range_bounds(&self, start: usize, end: usize) -> (Aabb, Aabb) {
        let mut b = Aabb::EMPTY;
        let mut c = Aabb::EMPTY;
        for &i in &self.indices[start..end] {
            b = b.union(&self.bounds[i as usize]);
            c = c.grow(self.centroids[i as usize]);
        }
        (b, c)
    }

    /// Builds the subtree over `indices[start..end]`; returns its node index.
    fn build_node(&mut self, start: usize, end: usize, depth: usize) -> u32 {
        let (bounds, centroid_bounds) = self.range_bounds(start, end);
        let me = self.nodes.len();
        self.nodes.push(Node {
            min: if bounds.is_empty() { [0.0; 3] } else { bounds.min.into() },
            first_or_right: start as u32,
            max: if bounds.is_empty() { [0.0; 3] } else { bounds.max.into() },
            count: (end - start) as u32,
        });
        let count = end - start;
        if count <= 1 {
            return me as u32;
        }
        let mid = if depth >= MEDIAN_SPLIT_DEPTH {
            Some(self.median_split(start, end, &centroid_bounds))
        } else {
            match self.sah_split(start, end, &bounds, &centroid_bounds) {
                Some(mid) => Some(mid),
                None if count > MAX_LEAF => Some(self.median_split(start, end, &centroid_bounds)),
                None => None,
            }
        };
        let Some(mid) = mid else { return me as u32 };
        self.build_node(start, mid, depth + 1);
        let right = self.build_node(mid, end, depth + 1);
        self.nodes[me].first_or_right = right;
        self.nodes[me].count = 0;
        me as u32
    }

    /// Splits at the best SAH plane, or returns `None` when a leaf is cheaper (or no
    /// plane separates the centroids).
    fn sah_split(&mut self, start: usize, end: usize, bounds: &Aabb, cb: &Aabb) -> Option<usize> {
        let count = end - start;
        let extent = cb.extent();
        let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, split bin)
        for axis in 0..3 {
            let ext = component(extent, axis);
            if !(ext > 0.0) {
                continue;
            }
            let mut bin_bounds = [Aabb::EMPTY; BINS];
            let mut bin_count = [0usize; BINS];
            let lo = component(cb.min, axis);
            let scale = BINS as f32 / ext;
            for &i in &self.indices[start..end] {
                let b = bin_of(component(self.centroids[i as usize], axis), lo, scale);
                bin_count[b] += 1;
                bin_bounds[b] = bin_bounds[b].union(&self.bounds[i as usize]);
            }
            // Sweep from the right to get the cost of every right side, then from the left.
            let mut right_area = [0.0f32; BINS];
            let mut right_count = [0usize; BINS];
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for k in (1..BINS).rev() {
                acc = acc.union(&bin_bounds[k]);
                n += bin_count[k];
                right_area[k] = acc.surface_area();
                right_count[k] = n;
            }
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for k in 1..BINS {
                acc = acc.union(&bin_bounds[k - 1]);
                n += bin_count[k - 1];
                if n == 0 || right_count[k] == 0 {
                    continue;
                }
                let cost = acc.surface_area() * n as f32 + right_area[k] * right_count[k] as f32;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, k));
                }
            }
        }
        let (cost, axis, split) = best?;
        let area = bounds.surface_area();
        let split_cost = TRAVERSAL_COST + if area > 0.0 { cost / area } else { count as f32 };
        if count <= MAX_LEAF && split_cost >= count as f32 {
            return None;
        }
        let lo = component(cb.min, axis);
        let scale = BINS as f32 / component(extent, axis);
        let centroids = self.centroids;
        let mid = start
            + partition(&mut self.indices[start..end], |&i| {
                bin_of(component(centroids[i as usize], axis), lo, scale) < split
            });
        (mid != start && mid != end).then_some(mid)
    }

    /// Splits in the middle of the range by centroid along the widest axis.
    fn median_split(&mut self, start: usize, end: usize, cb: &Aabb) -> usize {
        let axis = cb.largest_axis();
        let mid = start + (end - start) / 2;
        let centroids = self.centroids;
        self.indices[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            component(centroids[a as usize], axis)
                .total_cmp(&component(centroids[b as usize], axis))
                .then(a.cmp(&b))
        });
        mid
    }
}

#[inline(always)]
fn bin_of(c: f32, lo: f32, scale: f32) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// In-place partition; returns the number of elements for which `pred` holds.
fn partition<T>(v: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut i = 0;
    for j in 0..v.len() {
        if pred(&v[j]) {
            v.swap(i, j);
            i += 1;
        }
    }
    i
}

impl Accelerator for Bvh {
    fn closest_hit(&self, prims: &[Primitive], ray: &Ray) -> Option<Hit> {
        let r = PreparedRay::new(*ray);
        let mut best: Option<Hit> = None;
        let mut t_max = ray.t_max;
        self.nodes.first()?.hit(&r, t_max)?;
        let mut stack = [0u32; STACK_SIZE];
        let mut sp = 0;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                let first = n.first_or_right as usize;
                for &pi in &self.indices[first..first + n.count as usize] {
                    if let Some((t, b1, b2)) = prims[pi as usize].intersect(&r, t_max) {
                        if Hit::is_closer_than(t, pi, &best) {
                            best = Some(Hit { t, prim: pi, b1, b2 });
                            t_max = t;
                        }
                    }
                }
            } else {
                let (left, right) = (node + 1, n.first_or_right as usize);
                match (self.nodes[left].hit(&r, t_max), self.nodes[right].hit(&r, t_max)) {
                    (Some(tl), Some(tr)) => {
                        let (near, far) = if tl <= tr { (left, right) } else { (right, left) };
                        stack[sp] = far as u32;
                        sp += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = left;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = right;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop the next subtree that still lies within the closest hit so far.
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                node = stack[sp] as usize;
                if self.nodes[node].hit(&r, t_max).is_some() {
                    break;
                }
            }
        }
    }

    fn occluded(&self, prims: &[Primitive], ray: &Ray) -> bool {
        let r = PreparedRay::new(*ray);
        let t_max = ray.t_max;
        let mut stack = [0u32; STACK_SIZE];
        let mut sp = 0;
        if self.nodes.first().and_then(|n| n.hit(&r, t_max)).is_none() {
            return false;
        }
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                let first = n.first_or_right as usize;
                if self.indices[first..first + n.count as usize]
                    .iter()
                    .any(|&pi| prims[pi as usize].intersect(&r, t_max).is_some())
                {
                    return true;
                }
            } else {
                let (left, right) = (node + 1, n.first_or_right as usize);
                let hl = self.nodes[left].hit(&r, t_max).is_some();
                let hr = self.nodes[right].hit(&r, t_max).is_some();
                if hl && hr {
                    stack[sp] = right as u32;
                    sp += 1;
                }
                if hl || hr {
                    node = if hl { left } else { right };
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = stack[sp] as usize;
        }
    }

    fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>() + self.indices.len() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::super::list::PrimitiveList;
    use super::super::test_scenes::{coplanar_grid, soup, Rng};
    use super::*;

    fn check_against_list(prims: &[Primitive], rays: impl Iterator<Item = Ray>) -> usize {
        let bvh = Bvh::build(prims);
        let list = PrimitiveList::new(prims.len());
        let mut hits = 0;
        for ray in rays {
            let a = bvh.closest_hit(prims, &ray);
            let b = list.closest_hit(prims, &ray);
            assert_eq!(a, b, "closest hit differs for {ray:?}");
            assert_eq!(
                bvh.occluded(prims, &ray),
                list.occluded(prims, &ray),
                "occlusion differs for {ray:?}"
            );
            hits += a.is_some() as usize;
        }
        hits
    }

    #[test]
    fn random_soups_match_the_list() {
        for seed in 1..6 {
            let prims = soup(seed, 700);
            let mut rng = Rng(seed * 31);
            let rays = (0..3000).map(|_| {
                let o = rng.vec(15.0);
                let d = (rng.vec(8.0) - o).normalize();
                Ray::segment(
                    o,
                    d,
                    1e-4,
                    if rng.next() < 0.3 {
                        rng.range(1.0, 20.0)
                    } else {
                        f32::INFINITY
                    },
                )
            });
            assert!(check_against_list(&prims, rays) > 500);
        }
    }

    #[test]
    fn coplanar_grid_with_axis_parallel_rays_matches_the_list() {
        let prims = coplanar_grid(20);
        let mut rng = Rng(99);
        // Rays straight down through vertices and edges (exact ties), and rays in the plane.
        let mut rays: Vec<Ray> = (0..2000)
            .map(|i| {
                let (x, y) = if i % 2 == 0 {
                    ((i % 21) as f32, ((i / 21) % 21) as f32)
                } else {
                    (rng.range(0.0, 20.0), rng.range(0.0, 20.0))
                };
                Ray::segment(Vec3A::new(x, y, 5.0), -Vec3A::Z, 1e-4, f32::INFINITY)
            })
            .collect();
        rays.extend(
            (0..200).map(|i| Ray::segment(Vec3A::new(-1.0, i as f32 * 0.1, 0.0), Vec3A::X, 1e-4, f32::INFINITY)),
        );
        assert!(check_against_list(&prims, rays.into_iter()) >= 2000);
    }

    #[test]
    fn degenerate_inputs() {
        // Empty scene, a single primitive, identical primitives, zero-area triangles.
        let none: Vec<Primitive> = Vec::new();
        let bvh = Bvh::build(&none);
        for o in [Vec3A::ZERO, Vec3A::new(0.0, 0.0, -1.0)] {
            let ray = Ray::segment(o, Vec3A::Z, 1e-4, f32::INFINITY);
            assert!(bvh.closest_hit(&none, &ray).is_none());
            assert!(!bvh.occluded(&none, &ray));
        }

        let mut prims = soup(7, 1);
        prims.extend(std::iter::repeat_n(prims[0], 40));
        let p = Vec3A::new(1.0, 1.0, 1.0);
        prims.push(Primitive {
            shape: crate::primitive::Shape::Triangle {
                p: [p, p, p],
                normals: None,
            },
            material: 0,
        });
        let mut rng = Rng(5);
        let rays = (0..500).map(|_| {
            let o = rng.vec(15.0);
            Ray::segment(o, (rng.vec(10.0) - o).normalize(), 1e-4, f32::INFINITY)
        });
        check_against_list(&prims, rays);

        // Huge and tiny coordinates.
        let mut big = soup(3, 200);
        for p in &mut big {
            if let crate::primitive::Shape::Triangle { p, .. } = &mut p.shape {
                for v in p.iter_mut() {
                    *v *= 1e6;
                }
            }
        }
        let mut rng = Rng(8);
        let rays = (0..500).map(|_| {
            let o = rng.vec(2e7);
            Ray::segment(o, (rng.vec(1e7) - o).normalize(), 1e-4, f32::INFINITY)
        });
        check_against_list(&big, rays);
    }

    #[test]
    fn builds_a_real_hierarchy() {
        let prims = soup(11, 5000);
        let bvh = Bvh::build(&prims);
        assert!(bvh.node_count() > 1000 && bvh.node_count() < 2 * prims.len());
        let mut seen = bvh.indices.clone();
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..prims.len() as u32));
    }
}
