#!/usr/bin/env python3
"""Writes the meshes the gallery scenes use (scenes/models/), all made here from formulas:

  torus.obj + torus.mtl  a torus with vertex normals and texture coordinates, its two
                         halves in two MTL materials (OBJ, text)
  knot.ply               a trefoil-knot tube with vertex normals (PLY, binary little endian)
  cube.obj               a cube of six quads, the control cage for Catmull-Clark
  tetra.obj              a tetrahedron, the control cage for Loop
  letter_l.obj           an L-shaped prism of quads (valence-3, -4 and -5 vertices)
  bricks.png             a brick wall (diffuse map), 8-bit sRGB
  bricks_height.png      its height field for bump mapping (mortar low, bricks high)
  sky.png                an equirectangular sky: blue gradient, a horizon, a sun toward -z
  sky.hdr                a linear sky with a bright sun (Radiance HDR): the light of the
                         path-traced scenes
  dusk.hdr               a uniform dusky blue (Radiance HDR): what the showcase's mirrors
                         see above the scene, whichever way is up

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


def write_png(path, width, height, pixel):
    """A minimal 8-bit RGB PNG writer (zlib, filter 0): no imaging library needed."""
    import zlib

    rows = b"".join(b"\x00" + bytes(c for x in range(width) for c in pixel(x, y)) for y in range(height))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))


def brick(x, y, w=256, h=128):
    """(is mortar, brick id) at texel (x, y): 8 rows of bricks, every other row offset."""
    row = y * 8 // h
    bx = (x + (w // 16 if row % 2 else 0)) % w
    col = bx * 8 // w
    in_x = bx % (w // 8)
    in_y = y % (h // 8)
    mortar = in_x < 2 or in_y < 2
    return mortar, row * 8 + col


def bricks(path):
    def pixel(x, y):
        mortar, k = brick(x, y)
        if mortar:
            return (200, 195, 185)
        shade = 150 + (k * 37) % 60
        return (shade, shade * 55 // 100, shade * 40 // 100)

    write_png(path, 256, 128, pixel)


def bricks_height(path):
    def pixel(x, y):
        mortar, _ = brick(x, y)
        v = 40 if mortar else 220
        return (v, v, v)

    write_png(path, 256, 128, pixel)


def sky(path, w=512, h=256):
    def pixel(x, y):
        # Longitude: u = 0.5 looks along -z; latitude: row 0 is straight up.
        u, v = (x + 0.5) / w, (y + 0.5) / h
        phi = (u - 0.5) * 2 * math.pi
        theta = v * math.pi
        d = (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))
        if d[1] < 0:
            g = 60 + int(40 * (1 + d[1]))
            return (g, g * 9 // 10, g * 7 // 10)
        t = d[1]
        r, g, b = int(110 + 60 * (1 - t)), int(150 + 60 * (1 - t)), 235
        sun = (0.3, 0.35, -0.89)
        c = sum(a * b for a, b in zip(d, sun)) / math.sqrt(sum(a * a for a in sun))
        if c > 0.995:
            return (255, 250, 230)
        return (r, g, b)

    write_png(path, w, h, pixel)


def write_hdr(path, width, height, pixel):
    """A minimal Radiance HDR writer: flat (uncompressed) RGBE scanlines, top row first."""

    def rgbe(c):
        m = max(c)
        if m < 1e-32:
            return b"\x00\x00\x00\x00"
        mant, e = math.frexp(m)
        scale = mant * 256.0 / m
        return bytes([min(255, int(x * scale)) for x in c] + [e + 128])

    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width))
        f.write(b"".join(rgbe(pixel(x, y)) for y in range(height) for x in range(width)))


def sky_hdr(path, w=512, h=256):
    """Linear radiance: a blue zenith paling toward the horizon, a brown ground, and a sun
    of angular radius 4 degrees at 35 degrees elevation, from the back left of a camera
    looking along -z (about two thirds of the light falling on a floor)."""
    sun = (-0.6, math.sin(math.radians(35)), -0.6)
    n = math.sqrt(sum(a * a for a in sun))
    sun = tuple(a / n for a in sun)
    cos_sun = math.cos(math.radians(4))

    def pixel(x, y):
        u, v = (x + 0.5) / w, (y + 0.5) / h
        phi = (u - 0.5) * 2 * math.pi
        theta = v * math.pi
        d = (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))
        if sum(a * b for a, b in zip(d, sun)) > cos_sun:
            return (590.0, 535.0, 440.0)
        if d[1] < 0:
            return (0.16, 0.13, 0.10)
        t = d[1] ** 0.5
        horizon, zenith = (0.85, 0.9, 1.0), (0.2, 0.4, 0.95)
        return tuple(0.9 * (a + (b - a) * t) for a, b in zip(horizon, zenith))

    write_hdr(path, w, h, pixel)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    torus(os.path.join(OUT, "torus.obj"), os.path.join(OUT, "torus.mtl"))
    knot(os.path.join(OUT, "knot.ply"))
    cube(os.path.join(OUT, "cube.obj"))
    tetra(os.path.join(OUT, "tetra.obj"))
    letter_l(os.path.join(OUT, "letter_l.obj"))
    bricks(os.path.join(OUT, "bricks.png"))
    bricks_height(os.path.join(OUT, "bricks_height.png"))
    sky(os.path.join(OUT, "sky.png"))
    sky_hdr(os.path.join(OUT, "sky.hdr"))
    write_hdr(os.path.join(OUT, "dusk.hdr"), 4, 2, lambda x, y: (0.22, 0.27, 0.42))
