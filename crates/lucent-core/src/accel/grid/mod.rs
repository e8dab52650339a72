//! Uniform grid (`--accel grid`).
//!
//! Build: the scene box (volume `V`) is cut into cells of equal size, `(λ·N / V)^(1/3)`
//! per unit of length along every axis (λ = 3): about `λ·N` cells in all, so about
//! `λ^(1/3)·N^(1/3)` per axis, more along the box's long sides. An axis along which the
//! box is thinner than a cell gets one cell, and the others share the `λ·N` (a flat
//! scene's grid is a grid of its plane). Each primitive is entered into every
//! cell it overlaps — its bounding box picks the candidates, the exact triangle–box test
//! decides — in one flat array with an offset per cell. When the primitives' boxes
//! would put more than 64 entries a primitive into the cells (primitives that overlap,
//! at worst all at one place), the cells are made larger until they do not.
//!
//! A crowded cell (more than `NESTED_AT` primitives, and many more than the average)
//! gets a grid of its own over the part of it they fill, built by the same rules (down to
//! `MAX_LEVEL` levels below the scene's), where that pays: a uniform
//! grid's cells follow the scene's size, so a small detail in a large scene — 50,000
//! triangles 0.01 wide beside one 10⁴ away — fell into one cell, and every ray that
//! reached it tested all of them (a 160 × 120 render took 25 s; the BVH's, 0.2 s).
//!
//! Traversal: slab by slab across the axis along which the ray crosses the most cells,
//! nearest slab first, visiting in each slab the cells of the range the ray spans along
//! the two other axes (one to four for most rays, about as many as a 3-D DDA visits; a
//! cell's own grid is walked in its place, the same way); the search ends after the slab
//! the ray leaves beyond the closest hit. Mailboxing (`Mailbox`) tests a primitive that
//! spans several cells once per ray. The walk is conservative: computed in f64 and
//! widened by a bound on its own rounding and on how far from the exact ray the f32
//! primitive tests may accept a hit (which grows with the distance), so it visits every
//! cell that holds a hit whatever the cells' size and however far away the ray starts
//! (see `walk.rs`). The 3-D DDA it replaced (Amanatides & Woo 1987, in f32
//! from the entry point) had no such allowance: a small model seen from 10⁵ times its
//! size away lost hits, and the cells could not be finer than the scene's padding.

mod walk;

use super::overlap::{cell_padding, overlaps, padded};
use super::PrimitiveSet;
use crate::aabb::Aabb;
use crate::math::{DVec3, Vec3A};

/// Cells per primitive.
const DENSITY: f32 = 3.0;
const MAX_RES: usize = 512;
/// The most cell entries a primitive may make on average (see [`Grid::build`]).
const MAX_ENTRIES_PER_PRIM: usize = 64;
/// A cell gets its own grid when it holds more primitives than this, and more than
/// [`NESTED_CROWD`] times as many as the grid's cells on average: a detail crowded into
/// few cells of a scene much larger than it. (Where every cell is crowded alike — long
/// slivers, a mesh longer than 512 cells — grids in all of them took seconds to build
/// and a hundred bytes a triangle, for little.)
const NESTED_AT: usize = 128;
const NESTED_CROWD: usize = 8;
/// A cell's own grid is not made where its cells would hold each primitive more than
/// this many times on average (slivers as long as the cell, primitives that overlap):
/// the rays would meet most of them in every cell they cross.
const NESTED_SPREAD: usize = 24;
/// The cells and entries (4 bytes each) all nested grids may add, per primitive.
const NESTED_WORDS_PER_PRIM: usize = 16;
/// The scene's grid is level 0; grids in its cells level 1, and so on up to this.
const MAX_LEVEL: usize = 2;
/// [`Grid::nested`] of a cell without a grid of its own.
const NONE: u32 = u32::MAX;

pub struct Grid {
    bounds: Aabb,
    res: [usize; 3],
    cell_size: Vec3A,
    /// Primitives of cell `c`: `prim_ids[cell_start[c]..cell_start[c + 1]]`.
    cell_start: Vec<u32>,
    prim_ids: Vec<u32>,
    /// Cell `c`'s own grid, `grids[nested[c]]`, or [`NONE`]; empty when no cell has one.
    nested: Vec<u32>,
    grids: Vec<Grid>,
    prim_count: usize,
    /// The largest extent of a primitive in this grid (its whole box, not its part in a
    /// cell): the walk's allowance for the primitive tests' rounding grows with it.
    largest: f32,
}

impl Grid {
    pub fn build<P: PrimitiveSet + ?Sized>(prims: &P) -> Grid {
        let items: Vec<(u32, Aabb)> = super::bounded(prims).collect();
        let scene = items.iter().fold(Aabb::EMPTY, |acc, (_, b)| acc.union(b));
        let mut budget = NESTED_WORDS_PER_PRIM * items.len();
        Grid::build_level(prims, &items, scene, 0, &mut budget).expect("level 0 always has a grid")
    }

    /// The grid over `items` in `scene` (their bounds, or their part in a cell of the
    /// level above), its crowded cells given grids of their own. Above level 0 (a cell's
    /// own grid), `None` where it would not pay: where its cells would hold each
    /// primitive more than [`NESTED_SPREAD`] times, where one cell keeps them all, or
    /// where its cells and entries do not fit `budget` (which they are taken from).
    fn build_level<P: PrimitiveSet + ?Sized>(
        prims: &P,
        items: &[(u32, Aabb)],
        scene: Aabb,
        level: usize,
        budget: &mut usize,
    ) -> Option<Grid> {
        if items.is_empty() {
            return Some(Grid {
                bounds: Aabb::EMPTY,
                res: [1; 3],
                cell_size: Vec3A::ONE,
                cell_start: vec![0, 0],
                prim_ids: Vec::new(),
                nested: Vec::new(),
                grids: Vec::new(),
                prim_count: 0,
                largest: 0.0,
            });
        }
        let pad = cell_padding(&scene);
        let bounds = padded(&scene, pad);
        let ext = bounds.extent();
        let largest = items
            .iter()
            .map(|&(i, _)| prims.bounds(i).extent().max_element())
            .fold(0.0f32, f32::max);
        let mut per_unit = cells_per_unit(ext.as_dvec3(), DENSITY as f64 * items.len() as f64);
        // Primitives that overlap (at worst all at one place) each span many cells: N of
        // them in N cells would make N² entries (12,000 spheres at one point, 1.7 GB). The
        // cells are halved along every axis until their candidates fit the bound.
        let bound = (MAX_ENTRIES_PER_PRIM * items.len()).clamp(1 << 12, u32::MAX as usize / 2);
        let mut first = true;
        let mut grid = loop {
            let res = [0, 1, 2].map(|a| ((ext[a] as f64 * per_unit).round() as usize).clamp(1, MAX_RES));
            let grid = Grid {
                bounds,
                res,
                cell_size: ext / Vec3A::new(res[0] as f32, res[1] as f32, res[2] as f32),
                cell_start: Vec::new(),
                prim_ids: Vec::new(),
                nested: Vec::new(),
                grids: Vec::new(),
                prim_count: prims.count(),
                largest,
            };
            let candidates = items
                .iter()
                .map(|(_, b)| {
                    let (lo, hi) = grid.cell_range(&padded(b, pad));
                    (0..3).map(|a| hi[a] - lo[a] + 1).product::<usize>()
                })
                .fold(0usize, usize::saturating_add);
            if level > 0 {
                let cells = res.iter().product::<usize>();
                if first && candidates > NESTED_SPREAD * items.len() || cells + candidates > *budget {
                    return None;
                }
                first = false;
            }
            if candidates <= bound || res == [1; 3] {
                break grid;
            }
            per_unit /= 2.0;
        };
        let res = grid.res;
        // Two passes: count the entries of every cell, then fill them in.
        let cells = res[0] * res[1] * res[2];
        let mut count = vec![0u32; cells + 1];
        grid.for_each_entry(prims, items, pad, |c, _| count[c] += 1);
        let mut start = 0u32;
        for c in count.iter_mut() {
            let n = *c;
            *c = start;
            start += n;
        }
        let mut fill = count.clone();
        let mut ids = vec![0u32; start as usize];
        grid.for_each_entry(prims, items, pad, |c, p| {
            ids[fill[c] as usize] = p;
            fill[c] += 1;
        });
        grid.cell_start = count;
        grid.prim_ids = ids;
        if level > 0 {
            if grid.largest_cell() >= items.len() {
                return None;
            }
            *budget = budget.saturating_sub(grid.cell_start.len() + grid.prim_ids.len());
        }
        if level < MAX_LEVEL {
            grid.nest(prims, level, budget);
        }
        Some(grid)
    }

    /// The most primitives one cell holds.
    fn largest_cell(&self) -> usize {
        self.cell_start
            .windows(2)
            .map(|w| (w[1] - w[0]) as usize)
            .max()
            .unwrap_or(0)
    }

    /// Gives each crowded cell (see [`NESTED_AT`]) a grid of its own over the part of the
    /// cell its primitives fill, where that pays (see [`Grid::build_level`]).
    fn nest<P: PrimitiveSet + ?Sized>(&mut self, prims: &P, level: usize, budget: &mut usize) {
        let cells = self.cell_start.len() - 1;
        let crowded = NESTED_AT.max(NESTED_CROWD * self.prim_ids.len() / cells);
        for c in 0..cells {
            let ids = self.cell_prims(c);
            if ids.len() <= crowded {
                continue;
            }
            let [x, y, z] = self.cell_coords(c);
            // The cell as its primitives were entered into it: padded. (Cut to the cell
            // itself, a primitive's part in the rounding between the f32 box and the
            // exact wall the walk decides by lay in neither neighbour's own grid: a
            // reviewer's rays 8·10⁻⁵ from such a wall lost 562 of 3,425 hits.)
            let cell = padded(&self.cell_box([x, y, z]), cell_padding(&self.bounds));
            let items: Vec<(u32, Aabb)> = ids
                .iter()
                .map(|&i| {
                    let b = prims.bounds(i);
                    let clipped = Aabb {
                        min: b.min.max(cell.min),
                        max: b.max.min(cell.max),
                    };
                    // A primitive the padding put here may lie just outside the cell.
                    (
                        i,
                        if clipped.min.cmple(clipped.max).all() {
                            clipped
                        } else {
                            b
                        },
                    )
                })
                .collect();
            let region = items.iter().fold(Aabb::EMPTY, |acc, (_, b)| acc.union(b));
            let Some(inner) = Grid::build_level(prims, &items, region, level + 1, budget) else {
                continue;
            };
            if self.nested.is_empty() {
                self.nested = vec![NONE; self.cell_start.len() - 1];
            }
            self.nested[c] = self.grids.len() as u32;
            self.grids.push(inner);
        }
    }

    fn cell_coords(&self, c: usize) -> [usize; 3] {
        [
            c % self.res[0],
            c / self.res[0] % self.res[1],
            c / (self.res[0] * self.res[1]),
        ]
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

    /// The primitives of cell `c` (an index, [`Grid::index`]).
    #[inline(always)]
    fn cell_prims(&self, c: usize) -> &[u32] {
        &self.prim_ids[self.cell_start[c] as usize..self.cell_start[c + 1] as usize]
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

/// Cells per unit of length for about `cells` cells in a box of extent `ext`, an axis
/// along which the box is thinner than one cell getting one. In f64: in f32 the volume
/// of a scene under about 1e-13 across is subnormal, and under 1e-15 zero, which made
/// every axis [`MAX_RES`] cells (512³ for one primitive).
///
/// (Flat boxes were given a token thickness, a thousandth of their size, which made a
/// flat region's cells a fraction of its triangles' size: each triangle of a floor lay
/// in dozens.)
fn cells_per_unit(ext: DVec3, cells: f64) -> f64 {
    let mut thick = [0, 1, 2].map(|a| ext[a] > 0.0);
    let mut per_unit = 1.0;
    // Each pass may find more axes thinner than a cell (at most all three).
    for _ in 0..3 {
        let k = thick.iter().filter(|&&t| t).count();
        if k == 0 {
            break;
        }
        let volume: f64 = (0..3).filter(|&a| thick[a]).map(|a| ext[a]).product();
        per_unit = (cells / volume).powf(1.0 / k as f64);
        let thin = (0..3)
            .filter(|&a| thick[a] && ext[a] * per_unit < 1.0)
            .collect::<Vec<_>>();
        if thin.is_empty() {
            break;
        }
        for a in thin {
            thick[a] = false;
        }
    }
    per_unit
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::test_sets::Triangles;
    use crate::ray::PreparedRay;

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

    /// The most primitives a ray from nearby meets in one cell of `grid` (cells with
    /// grids of their own keep their lists for rays from far away).
    fn largest_list(grid: &Grid) -> usize {
        let own = (0..grid.cell_start.len() - 1)
            .filter(|&c| grid.nested.get(c).is_none_or(|&g| g == NONE))
            .map(|c| (grid.cell_start[c + 1] - grid.cell_start[c]) as usize);
        own.chain(grid.grids.iter().map(largest_list)).max().unwrap_or(0)
    }

    #[test]
    fn a_small_detail_in_a_large_scene_gets_a_grid_of_its_own() {
        // 5,000 triangles 0.01 wide and one 10⁴ away: the scene's cells are about 500
        // wide, and the detail lay in one (a list of 5,000).
        let prims = Triangles::detail_in_a_stadium(7, 5_000);
        let grid = Grid::build(&prims);
        let largest = largest_list(&grid);
        assert!(largest <= NESTED_AT, "a cell of {largest}");
        assert!(grid.prim_ids.len() + grid.grids.iter().map(|g| g.prim_ids.len()).sum::<usize>() <= 64 * 2 * 5_001);
    }

    #[test]
    fn rays_by_the_wall_between_two_cells_own_grids_find_what_the_list_finds() {
        // A reviewer's scene: one triangle 10⁴ away and one at x = 10 make a grid of 512
        // cells along x, and 1,500 small upright triangles straddle the last wall but one,
        // so that the cells on both sides get grids of their own. Cut to the cells'
        // unpadded f32 boxes, those grids left out the strip between a box and the exact
        // wall the walk decides by: rays 8·10⁻⁵ from the wall lost 562 of 3,425 hits.
        use crate::accel::test_sets::Rng;
        use crate::accel::{AccelKind, Accelerator};
        use crate::ray::Ray;
        let far = Vec3A::new(-1e4, 0.0, 0.0);
        let ends = [
            [far, far + Vec3A::Y, far + Vec3A::Z],
            [Vec3A::X * 10.0, Vec3A::new(10.0, 1.0, 0.0), Vec3A::new(10.0, 0.0, 1.0)],
        ];
        let scene = |w: f32| {
            let mut rng = Rng(5);
            let detail = (0..1500).map(|_| {
                let (y, z) = (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
                [
                    Vec3A::new(w - 0.004, y, z),
                    Vec3A::new(w + 0.004, y, z),
                    Vec3A::new(w, y, z + 0.004),
                ]
            });
            Triangles(ends.iter().copied().chain(detail).collect())
        };
        // The wall, from a first build (the detail does not change the scene's box).
        let first = Grid::build(&scene(-9.44));
        let k = first.res[0] - 1;
        let w = (first.bounds.min.x as f64 + k as f64 * first.cell_size.x as f64) as f32;
        let prims = scene(w);
        let grid = Grid::build(&prims);
        assert_eq!((grid.res[0], grid.bounds.min.x), (first.res[0], first.bounds.min.x));
        assert!(
            grid.grids.len() >= 2,
            "{} cells with grids of their own",
            grid.grids.len()
        );
        let list = AccelKind::List.build(&prims);
        let mut hits = 0;
        for t in &prims.0[2..] {
            for dx in [-8e-5, -2e-5, 0.0, 2e-5, 8e-5, 3e-4] {
                for dir in [Vec3A::Y, Vec3A::new(0.0, 0.958, 0.287).normalize()] {
                    let o = Vec3A::new(w + dx, t[0].y - 1.5 * dir.y, t[0].z + 0.001 - 1.5 * dir.z);
                    let r = PreparedRay::new(Ray::new(o, dir));
                    let expected = list.closest_hit(&prims, &r);
                    hits += expected.is_some() as usize;
                    assert_eq!(grid.closest_hit(&prims, &r), expected, "{o:?} {dir:?}");
                }
            }
        }
        assert!(hits > 10_000, "{hits}");
    }

    #[test]
    fn rays_from_near_a_detail_far_from_the_grids_low_corner_walk_its_own_grid() {
        // The teapot in a stadium with every coordinate negated: the detail lies 10⁴ from
        // the grid's low corner. The allowance that decides whether a ray walks a cell's
        // own grid or tests the cell's whole list was taken from that corner's distance
        // (10⁴ · 2⁻²⁰, more than the detail's cells), so every ray tested all 20,000
        // triangles; rays from 2.5 units away test a few dozen.
        use crate::accel::test_sets::Rng;
        use crate::accel::Accelerator;
        use crate::hit::Hit;
        use crate::ray::Ray;
        use std::sync::atomic::{AtomicUsize, Ordering};
        struct Counted(Triangles, AtomicUsize);
        impl PrimitiveSet for Counted {
            fn count(&self) -> usize {
                self.0.count()
            }
            fn bounds(&self, i: u32) -> Aabb {
                self.0.bounds(i)
            }
            fn triangle(&self, i: u32) -> Option<[Vec3A; 3]> {
                self.0.triangle(i)
            }
            fn intersect(&self, i: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
                self.1.fetch_add(1, Ordering::Relaxed);
                self.0.intersect(i, ray, t_max)
            }
        }
        let negated = Triangles::detail_in_a_stadium(3, 20_000)
            .0
            .iter()
            .map(|t| t.map(|p| -p))
            .collect();
        let prims = Counted(Triangles(negated), AtomicUsize::new(0));
        let grid = Grid::build(&prims);
        let mut rng = Rng(4);
        let rays = 1000;
        for _ in 0..rays {
            let target = -(rng.vec(0.5) + Vec3A::splat(0.5));
            let o = target + rng.vec(1.0).normalize() * 2.5;
            grid.closest_hit(&prims, &PreparedRay::new(Ray::new(o, (target - o).normalize())));
        }
        let tests = prims.1.load(Ordering::Relaxed) / rays;
        assert!(tests < 500, "{tests} triangle tests a ray");
    }

    #[test]
    fn a_flat_box_is_cut_in_its_plane_and_a_thin_one_along_its_length() {
        let res = |ext: DVec3, cells: f64| {
            let per_unit = cells_per_unit(ext, cells);
            [0, 1, 2].map(|a| (ext[a] * per_unit).round() as usize)
        };
        assert_eq!(res(DVec3::new(10.0, 10.0, 1e-4), 300.0), [17, 17, 0]);
        assert_eq!(res(DVec3::new(1e-4, 1000.0, 1e-4), 300.0), [0, 300, 0]);
        assert_eq!(res(DVec3::splat(2.0), 27_000.0), [30, 30, 30]);
        // A box with no extent at all (one point, unpadded) gets one cell per axis.
        assert_eq!(res(DVec3::ZERO, 300.0), [0, 0, 0]);
    }

    #[test]
    fn a_flat_detail_in_a_large_scene_gets_a_grid_of_its_plane() {
        // A floor of 60 × 60 squares in the unit square and one triangle 10⁴ away. The
        // detail lies in one of the scene's cells. Before flat boxes were cut in their
        // plane (they were given a thousandth of their width as thickness), the grid
        // in that cell would have had cells a fifth of a triangle's width, putting each
        // into about 30 of them, and it was not made: a cell of 7,200.
        let p = |i: usize, j: usize| Vec3A::new(i as f32 / 60.0, j as f32 / 60.0, 0.5);
        let mut tris: Vec<[Vec3A; 3]> = (0..3600)
            .flat_map(|k| {
                let (i, j) = (k % 60, k / 60);
                [
                    [p(i, j), p(i + 1, j), p(i + 1, j + 1)],
                    [p(i, j), p(i + 1, j + 1), p(i, j + 1)],
                ]
            })
            .collect();
        let far = Vec3A::splat(1e4);
        tris.push([far, far + Vec3A::X, far + Vec3A::Y]);
        let grid = Grid::build(&Triangles(tris));
        let largest = largest_list(&grid);
        assert!(largest <= NESTED_AT, "a cell of {largest}");
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
