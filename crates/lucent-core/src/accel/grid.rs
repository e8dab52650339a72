//! Uniform grid (`--accel grid`).
//!
//! Build: the scene box (volume `V`) is cut into cells of equal size, `(λ·N / V)^(1/3)`
//! per unit of length along every axis (λ = 3): about `λ·N` cells in all, so about
//! `λ^(1/3)·N^(1/3)` per axis, more along the box's long sides. Each primitive is entered into every
//! cell it overlaps — its bounding box picks the candidates, the exact triangle–box test
//! decides — in one flat array with an offset per cell. When the primitives' boxes
//! would put more than 64 entries a primitive into the cells (primitives that overlap,
//! at worst all at one place), the cells are made larger until they do not.
//!
//! Traversal: 3-D DDA (Amanatides & Woo 1987) from the cell where the ray enters, always
//! stepping across the nearest cell wall, so cells are visited in ray order; the search
//! ends when the closest hit lies inside the current cell. Mailboxing ([`Mailbox`])
//! tests a primitive that spans several cells once per ray.

use super::cell_walk::CellWalk;
use super::overlap::{cell_padding, overlaps, padded};
use super::{search_limit, PrimitiveSet};
use crate::aabb::Aabb;
use crate::math::Vec3A;
use crate::ray::PreparedRay;

/// Cells per primitive.
const DENSITY: f32 = 3.0;
const MAX_RES: usize = 512;
/// The most cell entries a primitive may make on average (see [`Grid::build`]).
const MAX_ENTRIES_PER_PRIM: usize = 64;

pub struct Grid {
    bounds: Aabb,
    res: [usize; 3],
    cell_size: Vec3A,
    /// Primitives of cell `c`: `prim_ids[cell_start[c]..cell_start[c + 1]]`.
    cell_start: Vec<u32>,
    prim_ids: Vec<u32>,
    prim_count: usize,
}

impl Grid {
    pub fn build<P: PrimitiveSet + ?Sized>(prims: &P) -> Grid {
        let items: Vec<(u32, Aabb)> = super::bounded(prims).collect();
        let scene = items.iter().fold(Aabb::EMPTY, |acc, (_, b)| acc.union(b));
        if items.is_empty() {
            return Grid {
                bounds: Aabb::EMPTY,
                res: [1; 3],
                cell_size: Vec3A::ONE,
                cell_start: vec![0, 0],
                prim_ids: Vec::new(),
                prim_count: 0,
            };
        }
        let pad = cell_padding(&scene);
        let bounds = padded(&scene, pad);
        let ext = bounds.extent();
        // Flat scenes have no volume: give thin axes a token thickness for the estimate.
        // In f64: in f32 the volume of a scene under about 1e-13 across is subnormal, and
        // under 1e-15 zero, which made every axis MAX_RES cells (512³ for one primitive).
        let e = ext.max(Vec3A::splat(ext.max_element() * 1e-3)).as_dvec3();
        let mut per_unit = (DENSITY as f64 * items.len() as f64 / (e.x * e.y * e.z)).cbrt();
        // Primitives that overlap (at worst all at one place) each span many cells: N of
        // them in N cells would make N² entries (12,000 spheres at one point, 1.7 GB). The
        // cells are halved along every axis until their candidates fit the bound.
        let bound = (MAX_ENTRIES_PER_PRIM * items.len()).clamp(1 << 12, u32::MAX as usize / 2);
        let mut grid = loop {
            let res = [0, 1, 2].map(|a| ((ext[a] as f64 * per_unit).round() as usize).clamp(1, MAX_RES));
            let grid = Grid {
                bounds,
                res,
                cell_size: ext / Vec3A::new(res[0] as f32, res[1] as f32, res[2] as f32),
                cell_start: Vec::new(),
                prim_ids: Vec::new(),
                prim_count: prims.count(),
            };
            let candidates = items
                .iter()
                .map(|(_, b)| {
                    let (lo, hi) = grid.cell_range(&padded(b, pad));
                    (0..3).map(|a| hi[a] - lo[a] + 1).product::<usize>()
                })
                .fold(0usize, usize::saturating_add);
            if candidates <= bound || res == [1; 3] {
                break grid;
            }
            per_unit /= 2.0;
        };
        let res = grid.res;
        // Two passes: count the entries of every cell, then fill them in.
        let cells = res[0] * res[1] * res[2];
        let mut count = vec![0u32; cells + 1];
        grid.for_each_entry(prims, &items, pad, |c, _| count[c] += 1);
        let mut start = 0u32;
        for c in count.iter_mut() {
            let n = *c;
            *c = start;
            start += n;
        }
        let mut fill = count.clone();
        let mut ids = vec![0u32; start as usize];
        grid.for_each_entry(prims, &items, pad, |c, p| {
            ids[fill[c] as usize] = p;
            fill[c] += 1;
        });
        grid.cell_start = count;
        grid.prim_ids = ids;
        grid
    }

    /// The first and last cells, along each axis, that box `b` overlaps.
    fn cell_range(&self, b: &Aabb) -> ([usize; 3], [usize; 3]) {
        (
            [0, 1, 2].map(|a| self.cell_of(b.min, a)),
            [0, 1, 2].map(|a| self.cell_of(b.max, a)),
        )
    }

    fn cell_of(&self, p: Vec3A, axis: usize) -> usize {
        let x = ((p[axis] - self.bounds.min[axis]) / self.cell_size[axis]).floor();
        (x.max(0.0) as usize).min(self.res[axis] - 1)
    }

    fn cell_box(&self, c: [usize; 3]) -> Aabb {
        let lo = self.bounds.min + self.cell_size * Vec3A::new(c[0] as f32, c[1] as f32, c[2] as f32);
        Aabb {
            min: lo,
            max: lo + self.cell_size,
        }
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.res[1] + c[1]) * self.res[0] + c[0]
    }

    /// Calls `f(cell, prim)` for every cell every primitive overlaps.
    fn for_each_entry<P: PrimitiveSet + ?Sized>(
        &self,
        prims: &P,
        items: &[(u32, Aabb)],
        pad: f32,
        mut f: impl FnMut(usize, u32),
    ) {
        for &(i, bounds) in items {
            let b = padded(&bounds, pad);
            let (lo, hi) = self.cell_range(&b);
            let single = lo == hi;
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let c = [x, y, z];
                        if single || overlaps(prims, i, &padded(&self.cell_box(c), pad)) {
                            f(self.index(c), i);
                        }
                    }
                }
            }
        }
    }
}

impl CellWalk for Grid {
    #[inline(always)]
    fn walk(&self, r: &PreparedRay, mut cell: impl FnMut(&[u32]) -> Option<f32>) {
        if self.prim_count == 0 {
            return;
        }
        let ray = &r.ray;
        let Some((t0, _)) = self.bounds.intersect(r, search_limit(ray.t_max)) else {
            return;
        };
        let entry = ray.at(t0);
        let mut c = [0, 1, 2].map(|a| self.cell_of(entry, a));
        let mut step = [0isize; 3];
        let mut next_t = [f32::INFINITY; 3];
        let wall = |c: usize, a: usize| self.bounds.min[a] + c as f32 * self.cell_size[a];
        for a in 0..3 {
            if ray.dir[a] > 0.0 {
                step[a] = 1;
                next_t[a] = (wall(c[a] + 1, a) - ray.origin[a]) * r.inv_dir[a];
            } else if ray.dir[a] < 0.0 {
                step[a] = -1;
                next_t[a] = (wall(c[a], a) - ray.origin[a]) * r.inv_dir[a];
            }
        }
        loop {
            let i = self.index(c);
            let ids = &self.prim_ids[self.cell_start[i] as usize..self.cell_start[i + 1] as usize];
            let Some(limit) = cell(ids) else { return };
            let a = if next_t[0] < next_t[1] {
                if next_t[0] < next_t[2] {
                    0
                } else {
                    2
                }
            } else if next_t[1] < next_t[2] {
                1
            } else {
                2
            };
            let exit = next_t[a];
            // The closest hit lies in this cell, or the ray ends in it; or no wall lies
            // ahead at a finite distance (the nearest is along an axis the ray does not
            // move along: every distance overflowed).
            if limit < exit || exit > search_limit(ray.t_max) || step[a] == 0 {
                return;
            }
            let n = c[a] as isize + step[a];
            if n < 0 || n >= self.res[a] as isize {
                return;
            }
            c[a] = n as usize;
            let w = if step[a] > 0 { c[a] + 1 } else { c[a] };
            next_t[a] = (wall(w, a) - ray.origin[a]) * r.inv_dir[a];
        }
    }

    fn prim_count(&self) -> usize {
        self.prim_count
    }

    fn memory_bytes(&self) -> usize {
        (self.cell_start.len() + self.prim_ids.len()) * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::test_sets::Triangles;

    #[test]
    fn a_scene_too_small_for_f32_volumes_gets_a_handful_of_cells() {
        // All corners at one point (the padded box is about 1e-38 across: its volume is
        // zero in f32), and a triangle a few 1e-14 across.
        for size in [0.0f32, 3e-14] {
            let tri = [Vec3A::ZERO, Vec3A::new(size, 0.0, 0.0), Vec3A::new(0.0, size, size)];
            let grid = Grid::build(&Triangles(vec![tri; 2]));
            assert!(grid.res.iter().product::<usize>() <= 8, "{size}: {:?}", grid.res);
        }
    }

    #[test]
    fn primitives_at_one_place_make_a_bounded_grid() {
        use crate::accel::{AccelKind, Accelerator};
        use crate::ray::Ray;
        // 3,000 copies of one triangle: a grid sized for 3,000 primitives made every copy
        // an entry of every cell the triangle crosses, 65,829,000 entries in all.
        let prims = Triangles(vec![[Vec3A::ZERO, Vec3A::X, Vec3A::Y]; 3000]);
        let grid = Grid::build(&prims);
        assert!(grid.prim_ids.len() <= 64 * 3000, "{} entries", grid.prim_ids.len());
        let list = AccelKind::List.build(&prims);
        for k in 0..100 {
            let o = Vec3A::new(k as f32 / 80.0 - 0.1, 0.3, 1.0);
            let r = PreparedRay::new(Ray::new(o, (Vec3A::new(0.25, 0.25, 0.0) - o).normalize()));
            assert_eq!(grid.closest_hit(&prims, &r), list.closest_hit(&prims, &r), "ray {k}");
        }
    }
}
