//! The uniform grid's walk along a ray (`--accel grid`; the grid and its build are the
//! parent module's): slab by slab across the axis along which the ray crosses the most
//! cells, computed in f64 and widened by a bound on its own rounding and on how far
//! from the exact ray the f32 primitive tests accept a hit, so that no cell holding a
//! hit is skipped however far away the ray starts.

use super::{Grid, NESTED_AT, NONE};
use crate::accel::cell_walk::CellWalk;
use crate::accel::search_limit;
use crate::ray::PreparedRay;

/// A bound on the relative rounding of the walk's f64 arithmetic: each position and
/// distance it computes takes a handful of roundings of 2⁻⁵³ of the magnitudes it is
/// computed from; this allows eight (see [`Grid::walk_from`]).
const ROUNDING: f64 = 1.0 / (1u64 << 50) as f64;
/// How far from the exact ray, relative to the distance travelled and the primitive's
/// size, a hit the primitive tests accept may lie. The watertight triangle test works in
/// f32 on the corners translated to the ray's origin and sheared: each projected corner
/// is off by at most about 7 ulps of its distance from the origin, and each edge
/// function's sign by about 4 ulps of the triangle's size, so a hit is within
/// 2⁻²¹·(distance + 2·size) of the exact ray; this allows twice that. (The ray from
/// 10⁶ away that a small detail's grid must not miss is 2 units wide by this measure, as
/// it is to the BVH's box tests, whose offsets widen by 2⁻¹⁸ of `o/d`.)
const PRIMITIVE_SLACK: f64 = 1.0 / (1u64 << 20) as f64;

/// One axis of a grid as its walk sees it (f64).
struct Axis {
    index: usize,
    lo: f64,
    hi: f64,
    size: f64,
    inv_size: f64,
    /// The rounding of a cell division, at most.
    slack: f64,
    last: usize,
}

impl Axis {
    /// The cells that coordinates `from..=to` (already widened by their own error)
    /// touch, widened by the rounding of the cell division; `None` when they lie outside
    /// the grid.
    #[inline(always)]
    fn cells(&self, from: f64, to: f64) -> Option<(usize, usize)> {
        let (from, to) = (from - self.slack, to + self.slack);
        if !(to >= self.lo && from <= self.hi) {
            return None;
        }
        Some((self.cell(from), self.cell(to)))
    }

    /// The cells that fractional cell coordinates `from..=to` (already widened by their
    /// error) touch; `None` when they lie outside the grid.
    #[inline(always)]
    fn cell_range(&self, from: f64, to: f64) -> Option<(usize, usize)> {
        if !(to >= 0.0 && from < (self.last + 1) as f64) {
            return None;
        }
        let of = |u: f64| if u > 0.0 { (u as usize).min(self.last) } else { 0 };
        Some((of(from), of(to)))
    }

    /// The cell of coordinate `x`, clamped to the grid. (Truncation is the floor of a
    /// non-negative quotient; `floor` itself is a library call on CPUs without SSE4.1,
    /// which the default build allows for.)
    #[inline(always)]
    fn cell(&self, x: f64) -> usize {
        let q = (x - self.lo) * self.inv_size;
        if q > 0.0 {
            (q as usize).min(self.last)
        } else {
            0
        }
    }
}

impl CellWalk for Grid {
    #[inline(always)]
    fn walk(&self, r: &PreparedRay, mut cell: impl FnMut(&[u32]) -> Option<f32>) {
        if self.prim_count == 0 {
            return;
        }
        self.walk_from(r, f32::INFINITY, &mut cell);
    }

    fn prim_count(&self) -> usize {
        self.prim_count
    }

    fn memory_bytes(&self) -> usize {
        (self.cell_start.len() + self.prim_ids.len() + self.nested.len()) * 4
            + self.grids.iter().map(|g| CellWalk::memory_bytes(g)).sum::<usize>()
    }
}

impl Grid {
    /// Walks this grid's cells along the ray, the search limit `limit` so far (where the
    /// closest hit found lies, or infinity). Returns the limit after its cells, or `None`
    /// once `cell` has ended the search.
    ///
    /// Slab by slab across the axis the ray crosses most cells of (`m`), nearest slab
    /// first; in each slab, every cell of the range of the two other axes that the ray's
    /// part in the slab spans — one to four cells for most rays, about as many as a 3-D
    /// DDA visits. The walk stops after the slab the ray leaves beyond the closest hit.
    ///
    /// It visits every cell that holds a hit the primitive tests can report: everything
    /// is computed in f64 from the ray's own f32 values, each coordinate widened by a
    /// bound on that rounding ([`ROUNDING`]) and by how far from the exact ray the f32
    /// primitive tests may accept a hit ([`PRIMITIVE_SLACK`]), which grows with the
    /// distance travelled. (A 3-D DDA in f32 from the entry point, the walk before, was
    /// off by ulps of the distance — 0.06 from 10⁶ away — with no allowance but the
    /// cells' padding, so the cells of a small detail could not be finer than the
    /// scene's padding.) Rays whose allowance spans several cells visit them all.
    #[inline(always)]
    fn walk_from<F: FnMut(&[u32]) -> Option<f32>>(&self, r: &PreparedRay, mut limit: f32, cell: &mut F) -> Option<f32> {
        let ray = &r.ray;
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let (lo, hi) = (self.bounds.min.as_dvec3(), self.bounds.max.as_dvec3());
        let largest = self.largest as f64;
        // The primitive tests' allowance at the box's farthest corner (distances as sums
        // of components: upper bounds).
        let farthest = (o - lo).abs().max((o - hi).abs()).element_sum();
        let box_slack = PRIMITIVE_SLACK * (farthest + 2.0 * largest);
        // The part of the ray inside the grid's box (widened by that allowance), its
        // ends widened by their rounding.
        let mut t0 = ray.t_min as f64;
        let mut t1 = search_limit(ray.t_max).min(limit) as f64;
        for a in 0..3 {
            let (lo, hi) = (lo[a] - box_slack, hi[a] + box_slack);
            if d[a] == 0.0 {
                if !(o[a] >= lo && o[a] <= hi) {
                    return Some(limit);
                }
                continue;
            }
            let (near, far) = ((lo - o[a]) / d[a], (hi - o[a]) / d[a]);
            let (near, far) = if near <= far { (near, far) } else { (far, near) };
            t0 = t0.max(near - near.abs() * ROUNDING);
            t1 = t1.min(far + far.abs() * ROUNDING);
        }
        if !(t0 <= t1) {
            return Some(limit);
        }
        let size = self.cell_size.as_dvec3();
        if !(size.is_finite() && lo.is_finite() && hi.is_finite() && box_slack.is_finite()) {
            // A scene whose extent overflows f32 (corners near ±3·10³⁸): its cells have
            // no finite size, and the allowances no finite width.
            return self.visit_all(limit, cell);
        }
        // The axis along which the ray crosses the most cells per unit of distance: in
        // each of its slabs the ray moves by at most one cell along the other two.
        let per_t = d.abs() / size;
        let m = if per_t.x >= per_t.y && per_t.x >= per_t.z {
            0
        } else if per_t.y >= per_t.z {
            1
        } else {
            2
        };
        let main = self.axis(m);
        let minor = [self.axis((m + 1) % 3), self.axis((m + 2) % 3)];
        let (om, sm) = (o[m], main.size);
        let inv_dm = 1.0 / d[m];
        // Distances along `m` are measured from the origin: `x`. The primitive tests'
        // allowance at `x` is `slack_at(|x|)` (the distance bounded by the sum of the
        // direction's components), and the error of a coordinate along `m` there,
        // `error_m(|x|)`, adds the rounding of `om + x`.
        let dist_per_x = d.abs().element_sum() * inv_dm.abs();
        let slack_at = |x: f64| PRIMITIVE_SLACK * (x * dist_per_x + 2.0 * largest);
        let error_m = |x: f64| (om.abs() + x) * ROUNDING + slack_at(x);
        // The ray's span along `m`, from where it enters to where it leaves.
        let (x0, x1) = ((t0 * d[m]), (t1 * d[m]));
        let forward = d[m] > 0.0;
        let (start, end) = if forward {
            (x0 - error_m(x0.abs()), x1 + error_m(x1.abs()))
        } else {
            (x0 + error_m(x0.abs()), x1 - error_m(x1.abs()))
        };
        let Some((k_lo, k_hi)) = main.cells(om + start.min(end), om + start.max(end)) else {
            return Some(limit);
        };
        // Wall `k` of `m` lies at `x = x_wall + k·sm`; where the ray crosses it, it is in
        // cell `u0 + k·du` (fractional) of each other axis, off by at most
        // `margin + margin_per_k·k` cells: the rounding of these sums (relative to their
        // terms, which cancel when the origin is far), the primitive tests' allowance,
        // and the allowance along `m` times the slope (a hit across a wall from the ray).
        let x_wall = main.lo - om;
        let x_reach = x_wall.abs();
        let wall_error = error_m(x_reach) + main.lo.abs() * ROUNDING;
        let wall_error_per_k = sm * (ROUNDING + PRIMITIVE_SLACK * dist_per_x);
        let mut u0 = [0.0; 2];
        let mut du = [0.0; 2];
        let mut margin = [0.0; 2];
        let mut margin_per_k = [0.0; 2];
        for i in 0..2 {
            let a = &minor[i];
            let slope = d[a.index] * inv_dm;
            let offset = o[a.index] - a.lo;
            u0[i] = (offset + x_wall * slope) * a.inv_size;
            du[i] = sm * slope * a.inv_size;
            let rounding = 2.0 * ROUNDING * (offset.abs() + x_reach * slope.abs()) + ROUNDING * u0[i].abs() * a.size;
            margin[i] = (rounding + slack_at(x_reach) + slope.abs() * wall_error) * a.inv_size;
            margin_per_k[i] = (2.0 * ROUNDING * du[i].abs() * a.size
                + PRIMITIVE_SLACK * sm * dist_per_x
                + slope.abs() * wall_error_per_k)
                * a.inv_size;
        }
        // The distance to wall `k`, `t_wall + k·dt`, less its error: the search ends
        // once the closest hit lies before that at the slab's exit wall.
        let (t_wall, dt) = (x_wall * inv_dm, sm * inv_dm);
        let t_error = 2.0 * ROUNDING * t_wall.abs() + wall_error * inv_dm.abs();
        let t_error_per_k = 2.0 * ROUNDING * dt.abs() + wall_error_per_k * inv_dm.abs();
        if !(u0
            .iter()
            .chain(&du)
            .chain(&margin)
            .chain(&margin_per_k)
            .all(|v| v.is_finite())
            && t_error.is_finite()
            && t_error_per_k.is_finite())
        {
            // (Overflow in f64 from finite f32 inputs is out of reach; NaN, from a zero
            // times an infinite allowance, is kept from skipping cells all the same.)
            return self.visit_all(limit, cell);
        }
        let (mut k, last) = if forward { (k_lo, k_hi) } else { (k_hi, k_lo) };
        let u_at = |i: usize, wall: f64| u0[i] + wall * du[i];
        // Where the ray enters the first slab and leaves the last, in walls (a wall
        // index with a fraction): the slab's whole width is not taken there, so that a
        // ray leaving a surface does not visit the cells behind it.
        let (first_wall, last_wall) = ((start - x_wall) / sm, (end - x_wall) / sm);
        let mut u_in = [u_at(0, first_wall), u_at(1, first_wall)];
        let mut at = [0usize; 3];
        loop {
            let out = if k == last {
                last_wall
            } else {
                (if forward { k + 1 } else { k }) as f64
            };
            let u_out = [u_at(0, out), u_at(1, out)];
            let far_wall = (k + 1) as f64;
            let e = [0, 1].map(|i| margin[i] + margin_per_k[i] * far_wall);
            let ranges =
                [0, 1].map(|i| minor[i].cell_range(u_in[i].min(u_out[i]) - e[i], u_in[i].max(u_out[i]) + e[i]));
            if let [Some((b0, b1)), Some((c0, c1))] = ranges {
                // (At the slab's farther wall from the origin: a bound taken from the
                // grid's low wall, like the margins', would span a small detail's cells
                // wherever it lies far from that wall, and its own grid would never
                // be walked.)
                let near_wall = x_wall + k as f64 * sm;
                let slab_slack = slack_at(near_wall.abs().max((near_wall + sm).abs()));
                at[m] = k;
                for z in c0..=c1 {
                    at[minor[1].index] = z;
                    for y in b0..=b1 {
                        at[minor[0].index] = y;
                        let i = self.index(at);
                        let list = self.cell_prims(i);
                        // (An empty cell changes nothing: `cell` would return the same
                        // limit. Most cells a ray crosses are empty, and `cell` is not
                        // inlined into this loop.)
                        if list.is_empty() {
                            continue;
                        }
                        // A cell's own grid (only crowded cells have one: the lookup is
                        // made for those alone), unless the allowance spans its cells (a
                        // ray from far away): its walk would visit most of them, and the
                        // cell's list holds each primitive once.
                        let inner = if list.len() > NESTED_AT {
                            self.nested.get(i)
                        } else {
                            None
                        };
                        limit = match inner {
                            Some(&g) if g != NONE && slab_slack < self.grids[g as usize].finest() => {
                                self.grids[g as usize].walk_nested(r, limit, cell)?
                            }
                            _ => cell(list)?,
                        };
                    }
                }
            }
            if k == last {
                return Some(limit);
            }
            if (limit as f64) < t_wall + out * dt - (t_error + t_error_per_k * far_wall) {
                return Some(limit);
            }
            u_in = u_out;
            k = if forward { k + 1 } else { k - 1 };
        }
    }

    /// Every cell's list, in order: what a ray sees of a grid whose walk cannot be
    /// computed (see [`Grid::walk_from`]). Each primitive is tested once all the same.
    #[cold]
    #[inline(never)]
    fn visit_all<F: FnMut(&[u32]) -> Option<f32>>(&self, mut limit: f32, cell: &mut F) -> Option<f32> {
        for c in 0..self.cell_start.len() - 1 {
            let list = self.cell_prims(c);
            if !list.is_empty() {
                limit = cell(list)?;
            }
        }
        Some(limit)
    }

    /// What the walk needs of axis `a`.
    #[inline(always)]
    fn axis(&self, a: usize) -> Axis {
        let (lo, hi) = (self.bounds.min[a] as f64, self.bounds.max[a] as f64);
        let size = self.cell_size[a] as f64;
        Axis {
            index: a,
            lo,
            hi,
            size,
            inv_size: 1.0 / size,
            slack: (lo.abs() + hi.abs()) * ROUNDING,
            last: self.res[a] - 1,
        }
    }

    /// The side of this grid's cells along their shortest axis of more than one cell
    /// (infinite if none: a ray's allowance spans nothing there).
    fn finest(&self) -> f64 {
        (0..3)
            .filter(|&a| self.res[a] > 1)
            .map(|a| self.cell_size[a] as f64)
            .fold(f64::INFINITY, f64::min)
    }

    /// [`Grid::walk_from`] for a cell's own grid: out of line, since it calls itself.
    #[inline(never)]
    fn walk_nested<F: FnMut(&[u32]) -> Option<f32>>(&self, r: &PreparedRay, limit: f32, cell: &mut F) -> Option<f32> {
        self.walk_from(r, limit, cell)
    }
}
