#!/usr/bin/env python3
"""Writes a CSE167 ray-tracer scene as a POV-Ray 3.7 scene, for timing POV-Ray beside
lucent on the same picture (scripts/povray_compare.py).

usage: to_povray.py SCENE.test OUT.pov   (prints "WIDTH HEIGHT" on success)

The commands of the CSE167 `raytracer` scenes are taken: size, camera, maxdepth, output,
maxverts, vertex, tri, sphere, translate, rotate, scale, pushTransform, popTransform,
directional, point, attenuation, ambient, diffuse, specular, shininess, emission (and the
`integrator raytracer` line). Any other command is refused (exit status 2): a scene with
more than this cannot be rendered alike by both programs.

The geometry, the camera, the lights and the number of rays are the same; the shading is
as close as POV-Ray's finish allows (docs/performance.md, "The whole Whitted renderer
beside POV-Ray", says where it differs):

- the course's `I = A + E + sum V C/att (D max(N.L,0) + S max(N.H,0)^s) + S I(reflected)`
  becomes pigment D, `diffuse 1`, `ambient (A+E)/D` (POV-Ray multiplies the ambient
  term by the pigment; a channel of D below 1/1000 is raised to 1/1000 so that the
  ambient can be expressed), `specular` the mean of S with `roughness 1/s` (POV-Ray's
  specular highlight is the same Blinn term, in one colour: the light's), and
  `reflection rgb S`;
- `maxdepth d` (the primary hit and at most d mirror bounces) is `max_trace_level d+1`
  with `adc_bailout 0`, so that POV-Ray does not stop early where lucent goes on;
- point-light attenuation `c0 + c1 r + c2 r^2`: POV-Ray's fade is `2 / (1 + (r/f)^p)`;
  with c1 = 0 it is exact (colour C/(2 c0), f = sqrt(c0/c2), p = 2), otherwise p and f
  match the course's value at r = 1 and r = 3;
- POV-Ray is left-handed: the camera's `right` vector is negated, the usual way to render
  a right-handed scene, and `angle` is the horizontal field of view of the course's
  vertical `fovy`;
- POV-Ray lights both sides of a triangle; the course lights only the side its winding
  faces (a difference in the picture, not in the rays traced).
"""

import math
import sys

SUPPORTED = {
    "size", "camera", "maxdepth", "output", "maxverts", "vertex", "tri", "sphere",
    "translate", "rotate", "scale", "pushTransform", "popTransform", "directional",
    "point", "attenuation", "ambient", "diffuse", "specular", "shininess", "emission",
    "integrator",
}


class Refused(Exception):
    pass


def identity():
    return [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def rotation(ax, ay, az, degrees):
    n = math.sqrt(ax * ax + ay * ay + az * az)
    if n == 0:
        raise Refused("rotate: zero axis")
    x, y, z = ax / n, ay / n, az / n
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    t = 1 - c
    m = identity()
    m[0][:3] = [c + t * x * x, t * x * y - s * z, t * x * z + s * y]
    m[1][:3] = [t * x * y + s * z, c + t * y * y, t * y * z - s * x]
    m[2][:3] = [t * x * z - s * y, t * y * z + s * x, c + t * z * z]
    return m


def apply_point(m, p):
    return [m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3] for i in range(3)]


def apply_vector(m, v):
    return [m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] for i in range(3)]


def vec(v):
    return "<%.9g, %.9g, %.9g>" % tuple(v)


def finish_of(material, maxdepth):
    ambient, diffuse, specular, shininess, emission = material
    pigment = [max(d, 1e-3) for d in diffuse]
    glow = [(a + e) / p for a, e, p in zip(ambient, emission, pigment)]
    spec = sum(specular) / 3
    parts = ["ambient rgb %s" % vec(glow), "diffuse 1", "brilliance 1"]
    if spec > 0:
        parts.append("specular %.9g roughness %.9g" % (spec, 1.0 / max(shininess, 1e-4)))
    if maxdepth > 0 and any(s > 0 for s in specular):
        parts.append("reflection { rgb %s }" % vec(specular))
    return "texture { pigment { rgb %s } finish { %s } }" % (vec(pigment), " ".join(parts))


def fade(c0, c1, c2):
    """POV-Ray's (colour factor, fade_distance, fade_power) for the course's attenuation."""
    if c1 == 0 and c2 == 0:
        return 1.0 / c0, None, None
    if c1 == 0:
        return 1.0 / (2 * c0), math.sqrt(c0 / c2), 2.0
    # 2/(1+(r/f)^p) = k/(c0+c1 r+c2 r^2) at r = 1 and r = 3, with k = 2/c0 (r -> 0).
    g1 = (c0 + c1 + c2) / c0 - 1
    g3 = (c0 + 3 * c1 + 9 * c2) / c0 - 1
    p = math.log(g3 / g1) / math.log(3)
    f = g1 ** (-1 / p)
    return 1.0 / (2 * c0), f, p


def convert(path):
    size = camera = None
    maxdepth = 5
    attenuation = (1.0, 0.0, 0.0)
    ambient, diffuse, specular = [0.2] * 3, [0.0] * 3, [0.0] * 3
    shininess, emission = 1.0, [0.0] * 3
    stack = [identity()]
    vertices = []
    lights, spheres = [], []
    # Runs of triangles that share a material, each a mesh2: (material, vertices, faces).
    meshes = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            words = line.split()
            if not words or words[0].startswith("#"):
                continue
            cmd, args = words[0], words[1:]
            if cmd not in SUPPORTED:
                raise Refused("%s:%d: %s is not a command of the CSE167 ray tracer" % (path, number, cmd))
            nums = []
            if cmd not in ("output", "integrator"):
                nums = [float(a) for a in args]
            m = stack[-1]
            if cmd == "size":
                size = (int(nums[0]), int(nums[1]))
            elif cmd == "camera":
                camera = nums
            elif cmd == "maxdepth":
                maxdepth = int(nums[0])
                if maxdepth < 0:
                    maxdepth = 100
            elif cmd == "integrator":
                if args[0] != "raytracer":
                    raise Refused("%s:%d: integrator %s (only raytracer scenes)" % (path, number, args[0]))
            elif cmd == "vertex":
                vertices.append(nums)
            elif cmd == "tri":
                material = (tuple(ambient), tuple(diffuse), tuple(specular), shininess, tuple(emission))
                if not meshes or meshes[-1][0] != material:
                    meshes.append((material, {}, []))
                _, index, faces = meshes[-1]
                face = []
                # A vertex is shared by the triangles that use it under the same transform.
                transform = tuple(map(tuple, m))
                for i in nums:
                    key = (int(i), transform)
                    if key not in index:
                        index[key] = (len(index), apply_point(m, vertices[int(i)]))
                    face.append(index[key][0])
                faces.append(face)
            elif cmd == "sphere":
                material = (tuple(ambient), tuple(diffuse), tuple(specular), shininess, tuple(emission))
                spheres.append((nums[:3], nums[3], [row[:] for row in m], material))
            elif cmd == "translate":
                t = identity()
                t[0][3], t[1][3], t[2][3] = nums
                stack[-1] = matmul(m, t)
            elif cmd == "rotate":
                stack[-1] = matmul(m, rotation(*nums))
            elif cmd == "scale":
                s = identity()
                s[0][0], s[1][1], s[2][2] = nums
                stack[-1] = matmul(m, s)
            elif cmd == "pushTransform":
                stack.append([row[:] for row in m])
            elif cmd == "popTransform":
                if len(stack) == 1:
                    raise Refused("%s:%d: popTransform with nothing pushed" % (path, number))
                stack.pop()
            elif cmd == "directional":
                lights.append(("directional", apply_vector(m, nums[:3]), nums[3:], None))
            elif cmd == "point":
                lights.append(("point", apply_point(m, nums[:3]), nums[3:], attenuation))
            elif cmd == "attenuation":
                attenuation = tuple(nums)
            elif cmd == "ambient":
                ambient = nums
            elif cmd == "diffuse":
                diffuse = nums
            elif cmd == "specular":
                specular = nums
            elif cmd == "shininess":
                shininess = nums[0]
            elif cmd == "emission":
                emission = nums
    if size is None or camera is None:
        raise Refused("%s: no size or no camera" % path)
    return size, camera, maxdepth, lights, spheres, meshes


def write(out, size, camera, maxdepth, lights, spheres, meshes):
    w, h = size
    eye, at, up, fovy = camera[0:3], camera[3:6], camera[6:9], camera[9]
    aspect = w / h
    hfov = math.degrees(2 * math.atan(math.tan(math.radians(fovy) / 2) * aspect))
    o = []
    o.append("// Written by lucent's scripts/to_povray.py\n")
    o.append("global_settings { assumed_gamma 1.0 max_trace_level %d adc_bailout 0 ambient_light rgb 1 }\n"
             % min(maxdepth + 1, 256))
    o.append("background { rgb 0 }\n")
    o.append("camera { perspective location %s look_at %s sky %s up y right -x*%.9g angle %.9g }\n"
             % (vec(eye), vec(at), vec(up), aspect, hfov))
    # Where directional lights are put: far away from the eye, along their direction.
    far = 1e5 * (1 + max(abs(c) for c in eye + at))
    for kind, where, colour, att in lights:
        if kind == "directional":
            n = math.sqrt(sum(c * c for c in where))
            d = [c / n for c in where]
            o.append("light_source { %s color rgb %s parallel point_at %s }\n"
                     % (vec([at[i] + far * d[i] for i in range(3)]), vec(colour), vec(at)))
        else:
            k, f, p = fade(*att)
            extra = "" if f is None else " fade_distance %.9g fade_power %.9g" % (f, p)
            o.append("light_source { %s color rgb %s%s }\n" % (vec(where), vec([c * k for c in colour]), extra))
    for centre, radius, m, material in spheres:
        val = [m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1], m[0][2], m[1][2], m[2][2],
               m[0][3], m[1][3], m[2][3]]
        o.append("sphere { %s, %.9g matrix <%s> %s }\n"
                 % (vec(centre), radius, ", ".join("%.9g" % v for v in val), finish_of(material, maxdepth)))
    for material, index, faces in meshes:
        verts = sorted(index.values())
        o.append("mesh2 {\n vertex_vectors { %d,\n" % len(verts))
        o.append(",\n".join(vec(p) for _, p in verts))
        o.append("\n }\n face_indices { %d,\n" % len(faces))
        o.append(",\n".join("<%d, %d, %d>" % tuple(f) for f in faces))
        o.append("\n }\n %s\n}\n" % finish_of(material, maxdepth))
    with open(out, "w") as f:
        f.write("".join(o))


def main():
    if len(sys.argv) != 3:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    try:
        size, camera, maxdepth, lights, spheres, meshes = convert(sys.argv[1])
    except (Refused, ValueError, IndexError) as e:
        print("to_povray.py: %s" % e, file=sys.stderr)
        sys.exit(2)
    write(sys.argv[2], size, camera, maxdepth, lights, spheres, meshes)
    print(size[0], size[1])


if __name__ == "__main__":
    main()
