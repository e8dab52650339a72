//! Subdivision surfaces (`subdivmesh`): Loop subdivision of triangle meshes and
//! Catmull–Clark subdivision of polygon meshes, refined a number of levels, then
//! pushed to the limit surface with limit normals.
//!
//! Each level computes new vertices from the old ones with the schemes' masks:
//! - Loop: edge points `3/8 (a + b) + 1/8 (c + d)`, vertex points
//!   `(1 − nβ) v + β Σ neighbours` with Loop's `β(n)`; every triangle becomes four.
//! - Catmull–Clark: face points (centroids), edge points `(a + b + F₁ + F₂) / 4`,
//!   vertex points `(Q + 2R + (n − 3) v) / n`; an n-gon becomes n quads.
//!
//! Boundary edges follow the cubic B-spline rules (edge midpoint, vertex
//! `3/4 v + 1/8 (b₀ + b₁)`), so open meshes keep their rims. After the last level every
//! vertex moves to its limit position and gets the normal of the limit surface from the
//! schemes' tangent masks around its ordered ring of neighbours; where no ring can be
//! ordered (boundary or non-manifold vertices) the normal is the area-weighted average
//! of the faces around it.

use std::collections::HashMap;
use std::f64::consts::PI;

use crate::geometry::mesh::TriangleMesh;
use glam::DVec3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheme {
    Loop,
    CatmullClark,
}

/// A polygon mesh: faces are lists of vertex indices, counter-clockwise seen from
/// outside.
#[derive(Clone, Debug, Default)]
pub struct ControlMesh {
    pub positions: Vec<DVec3>,
    pub faces: Vec<Vec<u32>>,
}

const NONE: u32 = u32::MAX;

/// Edges of a mesh: for each, its two vertices and the faces on either side.
struct Topology {
    edge_of: HashMap<(u32, u32), u32>,
    ends: Vec<[u32; 2]>,
    /// Faces beside each edge; `NONE` where the edge is on the boundary.
    faces: Vec<[u32; 2]>,
}

impl Topology {
    fn new(m: &ControlMesh) -> Result<Topology, String> {
        let mut t = Topology {
            edge_of: HashMap::with_capacity(m.faces.len() * 2),
            ends: Vec::new(),
            faces: Vec::new(),
        };
        for (f, face) in m.faces.iter().enumerate() {
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                if a == b {
                    return Err(format!("face {f} repeats vertex {a}"));
                }
                let key = (a.min(b), a.max(b));
                let e = *t.edge_of.entry(key).or_insert_with(|| {
                    t.ends.push([key.0, key.1]);
                    t.faces.push([NONE, NONE]);
                    t.ends.len() as u32 - 1
                });
                let sides = &mut t.faces[e as usize];
                if sides[0] == NONE {
                    sides[0] = f as u32;
                } else if sides[1] == NONE {
                    sides[1] = f as u32;
                } else {
                    return Err(format!(
                        "the edge between vertices {} and {} belongs to more than two faces",
                        key.0, key.1
                    ));
                }
            }
        }
        Ok(t)
    }

    fn edge(&self, a: u32, b: u32) -> u32 {
        self.edge_of[&(a.min(b), a.max(b))]
    }

    fn is_boundary(&self, e: usize) -> bool {
        self.faces[e][1] == NONE
    }
}

/// Per vertex: the other ends of its edges, and those across a boundary edge.
fn neighbours(n: usize, t: &Topology) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let mut all = vec![Vec::new(); n];
    let mut rim = vec![Vec::new(); n];
    for (e, &[a, b]) in t.ends.iter().enumerate() {
        all[a as usize].push(b);
        all[b as usize].push(a);
        if t.is_boundary(e) {
            rim[a as usize].push(b);
            rim[b as usize].push(a);
        }
    }
    (all, rim)
}

/// The boundary rule shared by both schemes (and used where a vertex has an odd number
/// of boundary edges, which no rule covers: it stays put).
fn boundary_vertex(v: DVec3, rim: &[u32], p: &[DVec3]) -> DVec3 {
    match rim {
        [b0, b1] => 0.75 * v + 0.125 * (p[*b0 as usize] + p[*b1 as usize]),
        _ => v,
    }
}

/// The new positions of the old vertices: the boundary rule on the rim, isolated
/// vertices left alone, and the scheme's `interior` rule elsewhere.
fn vertex_points<'a>(
    p: &'a [DVec3],
    all: &'a [Vec<u32>],
    rim: &'a [Vec<u32>],
    interior: impl Fn(usize, DVec3) -> DVec3 + 'a,
) -> impl Iterator<Item = DVec3> + 'a {
    p.iter().enumerate().map(move |(v, &pos)| {
        if !rim[v].is_empty() {
            boundary_vertex(pos, &rim[v], p)
        } else if all[v].is_empty() {
            pos
        } else {
            interior(v, pos)
        }
    })
}

/// The new points on the old edges: midpoints on the boundary, the scheme's `interior`
/// rule (given the edge's ends and its two faces) elsewhere.
fn edge_points<'a>(
    p: &'a [DVec3],
    t: &'a Topology,
    interior: impl Fn(u32, u32, [u32; 2]) -> DVec3 + 'a,
) -> impl Iterator<Item = DVec3> + 'a {
    t.ends.iter().enumerate().map(move |(e, &[a, b])| {
        if t.is_boundary(e) {
            0.5 * (p[a as usize] + p[b as usize])
        } else {
            interior(a, b, t.faces[e])
        }
    })
}

fn loop_beta(n: usize) -> f64 {
    let n = n as f64;
    let c = 0.375 + 0.25 * (2.0 * PI / n).cos();
    (0.625 - c * c) / n
}

fn loop_step(m: &ControlMesh) -> Result<ControlMesh, String> {
    let t = Topology::new(m)?;
    let p = &m.positions;
    let (all, rim) = neighbours(p.len(), &t);
    let mut out = Vec::with_capacity(p.len() + t.ends.len());
    out.extend(vertex_points(p, &all, &rim, |v, pos| {
        let n = all[v].len();
        let beta = loop_beta(n);
        let sum: DVec3 = all[v].iter().map(|&u| p[u as usize]).sum();
        (1.0 - n as f64 * beta) * pos + beta * sum
    }));
    let opposite = |f: u32, a: u32, b: u32| -> DVec3 {
        let face = &m.faces[f as usize];
        let c = face.iter().find(|&&x| x != a && x != b).expect("a triangle");
        p[*c as usize]
    };
    out.extend(edge_points(p, &t, |a, b, [f0, f1]| {
        0.375 * (p[a as usize] + p[b as usize]) + 0.125 * (opposite(f0, a, b) + opposite(f1, a, b))
    }));
    let base = p.len() as u32;
    let mut faces = Vec::with_capacity(m.faces.len() * 4);
    for f in &m.faces {
        let [a, b, c] = [f[0], f[1], f[2]];
        let [ab, bc, ca] = [t.edge(a, b), t.edge(b, c), t.edge(c, a)].map(|e| base + e);
        faces.extend([vec![a, ab, ca], vec![b, bc, ab], vec![c, ca, bc], vec![ab, bc, ca]]);
    }
    Ok(ControlMesh { positions: out, faces })
}

fn catmull_clark_step(m: &ControlMesh) -> Result<ControlMesh, String> {
    let t = Topology::new(m)?;
    let p = &m.positions;
    let (all, rim) = neighbours(p.len(), &t);
    let centroid: Vec<DVec3> = m
        .faces
        .iter()
        .map(|f| f.iter().map(|&v| p[v as usize]).sum::<DVec3>() / f.len() as f64)
        .collect();
    let mut faces_of = vec![Vec::new(); p.len()];
    for (f, face) in m.faces.iter().enumerate() {
        for &v in face {
            faces_of[v as usize].push(f as u32);
        }
    }
    let mut out = Vec::with_capacity(p.len() + t.ends.len() + m.faces.len());
    out.extend(vertex_points(p, &all, &rim, |v, pos| {
        let n = all[v].len() as f64;
        let q = faces_of[v].iter().map(|&f| centroid[f as usize]).sum::<DVec3>() / faces_of[v].len() as f64;
        let r = all[v].iter().map(|&u| 0.5 * (pos + p[u as usize])).sum::<DVec3>() / n;
        (q + 2.0 * r + (n - 3.0) * pos) / n
    }));
    out.extend(edge_points(p, &t, |a, b, [f0, f1]| {
        0.25 * (p[a as usize] + p[b as usize] + centroid[f0 as usize] + centroid[f1 as usize])
    }));
    out.extend(&centroid);
    let edge_base = p.len() as u32;
    let face_base = edge_base + t.ends.len() as u32;
    let mut faces = Vec::new();
    for (f, face) in m.faces.iter().enumerate() {
        let k = face.len();
        for i in 0..k {
            let (prev, v, next) = (face[(i + k - 1) % k], face[i], face[(i + 1) % k]);
            faces.push(vec![
                v,
                edge_base + t.edge(v, next),
                face_base + f as u32,
                edge_base + t.edge(prev, v),
            ]);
        }
    }
    Ok(ControlMesh { positions: out, faces })
}

/// The ring around vertex `v` in counter-clockwise order, as `(edge neighbour, the
/// face's vertex across from v)` per face (the second is the edge neighbour's
/// successor for triangles); `None` if the faces around `v` do not form one closed fan.
fn ordered_ring(corners: &[(u32, u32, u32)]) -> Option<Vec<(u32, u32)>> {
    // Each corner of a face at v: (next vertex, opposite vertex, previous vertex).
    let n = corners.len();
    if n < 3 {
        return None;
    }
    let mut ring = Vec::with_capacity(n);
    let mut at = 0;
    for _ in 0..n {
        let (next, opposite, prev) = corners[at];
        ring.push((next, opposite));
        // The face counter-clockwise from this one starts where this one ends.
        let mut found = corners.iter().enumerate().filter(|(_, c)| c.0 == prev);
        let (k, _) = found.next()?;
        if found.next().is_some() {
            return None;
        }
        at = k;
    }
    (at == 0).then_some(ring)
}

/// Limit positions and normals of the refined mesh `m`.
fn to_limit(m: &ControlMesh, scheme: Scheme) -> Result<(Vec<DVec3>, Vec<DVec3>), String> {
    let t = Topology::new(m)?;
    let p = &m.positions;
    let (all, rim) = neighbours(p.len(), &t);
    let mut corners = vec![Vec::new(); p.len()];
    for face in &m.faces {
        let k = face.len();
        for i in 0..k {
            let opposite = face[(i + k / 2) % k];
            corners[face[i] as usize].push((face[(i + 1) % k], opposite, face[(i + k - 1) % k]));
        }
    }
    // Fallback normals: area-weighted face normals (Newell's method for polygons).
    let mut averaged = vec![DVec3::ZERO; p.len()];
    for face in &m.faces {
        let mut n = DVec3::ZERO;
        for i in 0..face.len() {
            let (a, b) = (p[face[i] as usize], p[face[(i + 1) % face.len()] as usize]);
            n += a.cross(b);
        }
        for &v in face {
            averaged[v as usize] += n;
        }
    }
    let mut limit = Vec::with_capacity(p.len());
    let mut normals = Vec::with_capacity(p.len());
    for (v, &pos) in p.iter().enumerate() {
        let ring = if rim[v].is_empty() {
            ordered_ring(&corners[v])
        } else {
            None
        };
        let sum = |ids: &mut dyn Iterator<Item = u32>| ids.map(|u| p[u as usize]).sum::<DVec3>();
        let position = match (&rim[v][..], scheme) {
            ([b0, b1], _) => (p[*b0 as usize] + 4.0 * pos + p[*b1 as usize]) / 6.0,
            (r, _) if !r.is_empty() || all[v].is_empty() => pos,
            (_, Scheme::Loop) => {
                let n = all[v].len() as f64;
                let w = 1.0 / (n + 3.0 / (8.0 * loop_beta(all[v].len())));
                (1.0 - n * w) * pos + w * sum(&mut all[v].iter().copied())
            }
            (_, Scheme::CatmullClark) => {
                let n = all[v].len() as f64;
                let diagonal = sum(&mut corners[v].iter().map(|c| c.1));
                (n * n * pos + 4.0 * sum(&mut all[v].iter().copied()) + diagonal) / (n * (n + 5.0))
            }
        };
        let tangent_normal = ring.and_then(|ring| {
            let n = ring.len();
            let angle = |i: usize| 2.0 * PI * i as f64 / n as f64;
            let (mut t1, mut t2) = (DVec3::ZERO, DVec3::ZERO);
            match scheme {
                Scheme::Loop => {
                    for (i, &(e, _)) in ring.iter().enumerate() {
                        t1 += angle(i).cos() * p[e as usize];
                        t2 += angle(i).sin() * p[e as usize];
                    }
                }
                Scheme::CatmullClark => {
                    let c = (2.0 * PI / n as f64).cos();
                    let a = 1.0 + c + (PI / n as f64).cos() * (2.0 * (9.0 + c)).sqrt();
                    for (i, &(e, f)) in ring.iter().enumerate() {
                        let (pe, pf) = (p[e as usize], p[f as usize]);
                        t1 += a * angle(i).cos() * pe + (angle(i).cos() + angle(i + 1).cos()) * pf;
                        t2 += a * angle(i).sin() * pe + (angle(i).sin() + angle(i + 1).sin()) * pf;
                    }
                }
            }
            let n = t1.cross(t2);
            (n.length_squared() > 0.0 && n.is_finite()).then(|| n.normalize())
        });
        limit.push(position);
        normals.push(tangent_normal.unwrap_or_else(|| averaged[v].normalize_or_zero()));
    }
    Ok((limit, normals))
}

/// Refines `control` `levels` times and returns the limit surface's triangles (quads
/// split along their first diagonal), with limit normals. Level 0 is the control mesh
/// itself, triangulated and shaded flat.
pub fn subdivide(control: &ControlMesh, scheme: Scheme, levels: u32) -> Result<TriangleMesh, String> {
    if let Some((f, face)) = control.faces.iter().enumerate().find(|(_, f)| f.len() < 3) {
        return Err(format!("face {f} has {} vertices (at least 3 needed)", face.len()));
    }
    if let Some((f, _)) = control
        .faces
        .iter()
        .enumerate()
        .find(|(_, f)| f.iter().any(|&v| v as usize >= control.positions.len()))
    {
        return Err(format!("face {f} refers to a vertex that does not exist"));
    }
    let mut m = control.clone();
    if scheme == Scheme::Loop {
        // Loop refines triangles: fan-triangulate polygons first.
        m.faces = fan(&m.faces).map(|t| t.to_vec()).collect();
    }
    for _ in 0..levels {
        m = match scheme {
            Scheme::Loop => loop_step(&m)?,
            Scheme::CatmullClark => catmull_clark_step(&m)?,
        };
    }
    // Level 0 is the cage itself: flat faces, no normals to interpolate.
    let (positions, normals) = if levels == 0 {
        (m.positions.clone(), Vec::new())
    } else {
        to_limit(&m, scheme)?
    };
    Ok(TriangleMesh {
        positions: positions.iter().map(|p| p.as_vec3()).collect(),
        normals: normals.iter().map(|n| n.as_vec3()).collect(),
        indices: fan(&m.faces).collect(),
        ..TriangleMesh::default()
    })
}

fn fan(faces: &[Vec<u32>]) -> impl Iterator<Item = [u32; 3]> + '_ {
    faces
        .iter()
        .flat_map(|f| (1..f.len() - 1).map(move |j| [f[0], f[j], f[j + 1]]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn octahedron() -> ControlMesh {
        ControlMesh {
            positions: vec![DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z],
            faces: vec![
                vec![0, 2, 4],
                vec![2, 1, 4],
                vec![1, 3, 4],
                vec![3, 0, 4],
                vec![2, 0, 5],
                vec![1, 2, 5],
                vec![3, 1, 5],
                vec![0, 3, 5],
            ],
        }
    }

    fn cube() -> ControlMesh {
        let positions = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                )
            })
            .collect();
        // Counter-clockwise seen from outside.
        let faces = vec![
            vec![0, 2, 3, 1], // z = -1
            vec![4, 5, 7, 6], // z = +1
            vec![0, 1, 5, 4], // y = -1
            vec![2, 6, 7, 3], // y = +1
            vec![0, 4, 6, 2], // x = -1
            vec![1, 3, 7, 5], // x = +1
        ];
        ControlMesh { positions, faces }
    }

    /// Closed: every edge has exactly two triangles, traversed in opposite directions
    /// (consistently oriented), and V − E + F = 2 (a sphere's topology).
    fn assert_closed(m: &TriangleMesh) {
        let mut directed = HashMap::new();
        for t in &m.indices {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "edge {a}-{b} used twice in one direction");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
        }
        let (v, e, f) = (
            m.positions.len() as i64,
            directed.len() as i64 / 2,
            m.indices.len() as i64,
        );
        assert_eq!(v - e + f, 2);
    }

    fn radii(m: &TriangleMesh) -> (f64, f64) {
        m.positions.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
            let r = p.as_dvec3().length();
            (lo.min(r), hi.max(r))
        })
    }

    fn assert_outward_normals(m: &TriangleMesh) {
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((n.length() - 1.0).abs() < 1e-5);
            assert!(p.normalize().dot(*n) > 0.5, "normal {n} at {p} does not point outward");
        }
    }

    #[test]
    fn loop_keeps_an_octahedron_closed_and_moves_it_to_its_limit_surface() {
        // The limit point of an original (valence 4) vertex is (1 − 4w) v with
        // w = 1 / (4 + 3 / (8 β(4))), since its neighbours sum to zero: every level
        // must put it there, and the rest of the surface lies between it and the limit
        // points of the face centres, well inside the control octahedron.
        let control = octahedron();
        let w = 1.0 / (4.0 + 3.0 / (8.0 * loop_beta(4)));
        let corner = 1.0 - 4.0 * w;
        let mut previous_lo = 0.0;
        for levels in 1..=4 {
            let m = subdivide(&control, Scheme::Loop, levels).unwrap();
            assert_eq!(m.indices.len(), 8 * 4usize.pow(levels));
            assert_closed(&m);
            assert_outward_normals(&m);
            let (lo, hi) = radii(&m);
            assert!((hi - corner).abs() < 1e-6, "level {levels}: {hi} vs {corner}");
            assert!(lo > 0.4 && lo < hi, "level {levels}: radii {lo}..{hi}");
            // Finer levels sample the same surface: the smallest radius settles.
            if levels > 1 {
                assert!((lo - previous_lo).abs() < 0.01, "{lo} vs {previous_lo}");
            }
            previous_lo = lo;
        }
    }

    #[test]
    fn catmull_clark_keeps_a_cube_closed_and_moves_it_to_its_limit_surface() {
        // The limit point of a cube corner (valence 3) is
        // (9 v + 4 Σ edge neighbours + Σ diagonal neighbours) / 24 = v / 2.
        let control = cube();
        for levels in 1..=4 {
            let m = subdivide(&control, Scheme::CatmullClark, levels).unwrap();
            assert_eq!(m.indices.len(), 2 * 24 * 4usize.pow(levels - 1));
            assert_closed(&m);
            assert_outward_normals(&m);
            let (lo, hi) = radii(&m);
            assert!((hi - 3f64.sqrt() / 2.0).abs() < 1e-6, "level {levels}: {hi}");
            assert!(lo > 0.5 && lo < hi, "level {levels}: radii {lo}..{hi}");
        }
    }

    #[test]
    fn limit_normals_match_the_exact_surface_on_a_regular_grid() {
        // A regular 6×6 quad grid in z = 0 lifted into z = x²: Catmull–Clark of a
        // quadratic is exact in the interior (B-splines reproduce quadratics), so the
        // limit normal at an interior vertex is the parabola's normal.
        let n = 7;
        let mut m = ControlMesh::default();
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (i as f64 - 3.0, j as f64 - 3.0);
                m.positions.push(DVec3::new(x, y, x * x));
            }
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let at = |i: usize, j: usize| (j * n + i) as u32;
                m.faces
                    .push(vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        let out = subdivide(&m, Scheme::CatmullClark, 2).unwrap();
        let mut checked = 0;
        for (p, nrm) in out.positions.iter().zip(&out.normals) {
            let p = p.as_dvec3();
            if p.x.abs() > 1.5 || p.y.abs() > 1.5 {
                continue;
            }
            // The limit surface of the control points (x, y, x²) is z = x² + 1/3 (the
            // B-spline of x² is shifted by the variance of the cubic basis).
            assert!((p.z - (p.x * p.x + 1.0 / 3.0)).abs() < 1e-5, "{p}");
            let exact = DVec3::new(-2.0 * p.x, 0.0, 1.0).normalize();
            assert!((nrm.as_dvec3() - exact).length() < 1e-6, "{nrm} vs {exact} at {p}");
            checked += 1;
        }
        assert!(checked > 20, "{checked}");
    }

    #[test]
    fn bad_control_meshes_are_errors() {
        let mut m = octahedron();
        m.faces.push(vec![0, 2, 4]); // a third face on edges 0-2, 2-4, 4-0
        assert!(subdivide(&m, Scheme::Loop, 1)
            .unwrap_err()
            .contains("more than two faces"));
        let mut m = octahedron();
        m.faces[0] = vec![0, 9, 4];
        assert!(subdivide(&m, Scheme::Loop, 1).is_err());
        let mut m = cube();
        m.faces[0] = vec![0, 2];
        assert!(subdivide(&m, Scheme::CatmullClark, 1).is_err());
    }
}
