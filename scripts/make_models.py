#!/usr/bin/env python3
"""Writes the meshes the gallery scenes use (scenes/models/), all made here from formulas:

  torus.obj + torus.mtl  a torus with vertex normals and texture coordinates, its two
                         halves in two MTL materials (OBJ, text)
  knot.ply               a trefoil-knot tube with vertex normals (PLY, binary little endian)
  cube.obj               a cube of six quads, the control cage for Catmull-Clark
  tetra.obj              a tetrahedron, the control cage for Loop
  letter_l.obj           an L-shaped prism of quads (valence-3, -4 and -5 vertices)

Run from the repository root: python3 scripts/make_models.py
"""
import math
import os
import struct

OUT = os.path.join("scenes", "models")


def torus(path_obj, path_mtl, R=1.0, r=0.38, nu=64, nv=32):
    with open(path_mtl, "w") as f:
        f.write("# two materials for the halves of torus.obj\n")
        f.write("newmtl copper\nKd 0.55 0.25 0.12\nKs 0.6 0.4 0.3\nNs 60\n")
        f.write("newmtl jade\nKd 0.1 0.45 0.3\nKs 0.2 0.2 0.2\nNs 20\n")
    lines = ["# a torus: major radius %g, minor radius %g, %d x %d quads" % (R, r, nu, nv), "mtllib torus.mtl"]
    for i in range(nu + 1):
        u = 2 * math.pi * i / nu
        for j in range(nv + 1):
            v = 2 * math.pi * j / nv
            c = [math.cos(u), math.sin(u)]
            lines.append("v %.6f %.6f %.6f" % ((R + r * math.cos(v)) * c[0], r * math.sin(v), (R + r * math.cos(v)) * c[1]))
            lines.append("vn %.6f %.6f %.6f" % (math.cos(v) * c[0], math.sin(v), math.cos(v) * c[1]))
            lines.append("vt %.6f %.6f" % (i / nu, j / nv))
    at = lambda i, j: i * (nv + 1) + j + 1
    for half, name in ((0, "copper"), (1, "jade")):
        lines.append("usemtl " + name)
        for i in range(half * nu // 2, (half + 1) * nu // 2):
            for j in range(nv):
                q = [at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]
                lines.append("f " + " ".join("%d/%d/%d" % (k, k, k) for k in q))
    with open(path_obj, "w") as f:
        f.write("\n".join(lines) + "\n")


def knot(path, nu=240, nv=16, r=0.28):
    def curve(t):
        return (math.sin(t) + 2 * math.sin(2 * t), math.cos(t) - 2 * math.cos(2 * t), -math.sin(3 * t))

    def sub(a, b):
        return [a[k] - b[k] for k in range(3)]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    def norm(a):
        l = math.sqrt(sum(x * x for x in a))
        return [x / l for x in a]

    verts = []
    for i in range(nu):
        t = 2 * math.pi * i / nu
        p = curve(t)
        tangent = norm(sub(curve(t + 1e-4), curve(t - 1e-4)))
        n1 = norm(cross(tangent, [0.0, 0.0, 1.0]))
        n2 = cross(tangent, n1)
        for j in range(nv):
            a = 2 * math.pi * j / nv
            n = [math.cos(a) * n1[k] + math.sin(a) * n2[k] for k in range(3)]
            verts.append(([p[k] + r * n[k] for k in range(3)], n))
    faces = []
    for i in range(nu):
        for j in range(nv):
            at = lambda i, j: (i % nu) * nv + (j % nv)
            faces.append([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment a trefoil-knot tube, made by scripts/make_models.py\n"
        "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "element face %d\nproperty list uchar uint vertex_indices\nend_header\n" % (len(verts), len(faces))
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        for p, n in verts:
            f.write(struct.pack("<6f", *p, *n))
        for q in faces:
            # Counter-clockwise seen from outside the tube.
            f.write(struct.pack("<B4I", 4, q[0], q[3], q[2], q[1]))


def write_obj(path, comment, verts, faces):
    with open(path, "w") as f:
        f.write("# %s\n" % comment)
        for v in verts:
            f.write("v %g %g %g\n" % v)
        for q in faces:
            f.write("f " + " ".join(str(k + 1) for k in q) + "\n")


def cube(path):
    verts = [(x, y, z) for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)]
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    write_obj(path, "a cube of six quads: the control cage of a Catmull-Clark surface", verts, faces)


def tetra(path):
    verts = [(1, 1, 1), (-1, -1, 1), (-1, 1, -1), (1, -1, -1)]
    faces = [[0, 1, 3], [0, 2, 1], [0, 3, 2], [1, 2, 3]]
    write_obj(path, "a tetrahedron: the control cage of a Loop surface", verts, faces)


def letter_l(path):
    # The L outline in the xy plane (counter-clockwise), extruded along z, in unit squares.
    outline = [(0, 0), (1, 0), (2, 0), (3, 0), (3, 1), (2, 1), (1, 1), (1, 2), (1, 3), (0, 3), (0, 2), (0, 1)]
    n = len(outline)
    verts = [(x, y, z) for z in (0, 1) for (x, y) in outline]
    faces = []
    for k in range(n):
        a, b = k, (k + 1) % n
        faces.append([a, b, b + n, a + n])
    # Caps made of quads: the five unit squares of the L, all on outline points.
    idx = {p: k for k, p in enumerate(outline)}
    squares = [[(0, 0), (1, 0), (1, 1), (0, 1)], [(1, 0), (2, 0), (2, 1), (1, 1)], [(2, 0), (3, 0), (3, 1), (2, 1)],
               [(0, 1), (1, 1), (1, 2), (0, 2)], [(0, 2), (1, 2), (1, 3), (0, 3)]]
    for sq in squares:
        ids = [idx[p] for p in sq]
        faces.append([i + n for i in ids])  # top (z = 1), counter-clockwise from +z
        faces.append(list(reversed(ids)))  # bottom, counter-clockwise from -z
    write_obj(path, "an L-shaped prism of quads: the control cage of a Catmull-Clark surface", verts, faces)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    torus(os.path.join(OUT, "torus.obj"), os.path.join(OUT, "torus.mtl"))
    knot(os.path.join(OUT, "knot.ply"))
    cube(os.path.join(OUT, "cube.obj"))
    tetra(os.path.join(OUT, "tetra.obj"))
    letter_l(os.path.join(OUT, "letter_l.obj"))
