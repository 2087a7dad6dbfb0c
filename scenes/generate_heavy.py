#!/usr/bin/env python3
"""Write scenes/heavy.dae: a >= 100,000-triangle test scene in the CS184 COLLADA dialect.

    python3 generate_heavy.py OUTPUT.dae

A Cornell-style box (10 triangles) with a CGL area light holds
  * a noise-displaced icosphere ("rock", 81,920 triangles, rough gold microfacet conductor),
  * an upright torus (12,288 triangles, diffuse),
  * a tilted torus (12,288 triangles, copper microfacet conductor),
106,506 triangles in all. Python 3 standard library only; the output is byte-for-byte deterministic.
The build runs this script (see CMakeLists.txt) into <build>/scenes/heavy.dae; the file is not
kept in the repository.

Geometry is built in the renderer's Y-up world frame and written in Blender's Z-up frame
(blender = (-x, z, y)), like the course files; meshes are closed, consistently oriented triangle
meshes with shared vertices, so the renderer's area-weighted vertex normals shade them smoothly.
"""
import math
import os
import sys

# ---------------------------------------------------------------------------------------------
# small vector helpers


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a):
    n = math.sqrt(dot(a, a))
    return (a[0] / n, a[1] / n, a[2] / n)


def rotate_x(p, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return (p[0], c * p[1] - s * p[2], s * p[1] + c * p[2])


def rotate_y(p, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return (c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2])


def rotate_z(p, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return (c * p[0] - s * p[1], s * p[0] + c * p[1], p[2])


# ---------------------------------------------------------------------------------------------
# deterministic value noise (integer hash, no random module)


def hash3(ix, iy, iz):
    h = (ix * 374761393 + iy * 668265263 + iz * 2147483647) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    h ^= h >> 16
    return h / 0xFFFFFFFF * 2.0 - 1.0


def value_noise(x, y, z):
    ix, iy, iz = math.floor(x), math.floor(y), math.floor(z)
    fx, fy, fz = x - ix, y - iy, z - iz
    ux, uy, uz = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy), fz * fz * (3 - 2 * fz)

    def lerp(a, b, t):
        return a + (b - a) * t

    c = [[[hash3(ix + i, iy + j, iz + k) for k in (0, 1)] for j in (0, 1)] for i in (0, 1)]
    x00 = lerp(c[0][0][0], c[1][0][0], ux)
    x10 = lerp(c[0][1][0], c[1][1][0], ux)
    x01 = lerp(c[0][0][1], c[1][0][1], ux)
    x11 = lerp(c[0][1][1], c[1][1][1], ux)
    return lerp(lerp(x00, x10, uy), lerp(x01, x11, uy), uz)


def fbm(p, octaves=5):
    total, amp, freq = 0.0, 0.5, 1.0
    for _ in range(octaves):
        total += amp * value_noise(p[0] * freq + 17.3, p[1] * freq - 4.1, p[2] * freq + 8.7)
        amp *= 0.5
        freq *= 2.03
    return total


# ---------------------------------------------------------------------------------------------
# meshes: (positions, triangles) in world space


def icosphere(level):
    t = (1 + math.sqrt(5)) / 2
    verts = [normalize(v) for v in [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                                     (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        cache = {}

        def mid(a, b):
            key = (a, b) if a < b else (b, a)
            if key not in cache:
                cache[key] = len(verts)
                verts.append(normalize(mul(add(verts[a], verts[b]), 0.5)))
            return cache[key]

        nf = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = nf
    return verts, faces


def rock(center, radius, level=6):
    unit, faces = icosphere(level)
    pos = []
    for n in unit:
        d = fbm(mul(n, 2.2))
        ridge = 1.0 - abs(value_noise(n[0] * 5.0, n[1] * 5.0 + 3.0, n[2] * 5.0 - 1.0))
        r = radius * (1.0 + 0.30 * d + 0.05 * ridge)
        pos.append(add(center, mul(n, r)))
    return pos, faces


def torus(center, major, minor, nu, nv, rot):
    """rot(p) orients the torus (whose axis is local +Y) before it is moved to centre."""
    pos, faces = [], []
    for i in range(nu):
        u = 2 * math.pi * i / nu
        for j in range(nv):
            v = 2 * math.pi * j / nv
            p = ((major + minor * math.cos(v)) * math.cos(u), minor * math.sin(v),
                 (major + minor * math.cos(v)) * math.sin(u))
            pos.append(add(center, rot(p)))
    for i in range(nu):
        for j in range(nv):
            a, b = i * nv + j, i * nv + (j + 1) % nv
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, ((i + 1) % nu) * nv + j
            faces += [(a, b, c), (a, c, d)]
    return pos, faces


def signed_volume(pos, faces):
    return sum(dot(pos[a], cross(pos[b], pos[c])) for a, b, c in faces) / 6


# ---------------------------------------------------------------------------------------------
# COLLADA output


def num(v):
    s = "%.5f" % v
    s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def to_blender(p):
    return (-p[0], p[2], p[1])


def effect_xml(name, diffuse, cgl=None):
    d = " ".join(num(v) for v in diffuse)
    x = [f'    <effect id="{name}-effect">', '      <profile_COMMON>', '        <technique sid="common">',
         f'          <phong><diffuse><color sid="diffuse">{d} 1</color></diffuse></phong>',
         '        </technique>', '      </profile_COMMON>']
    if cgl:
        x += ['      <extra>', '        <technique profile="CGL">'] + ['          ' + c for c in cgl] + \
             ['        </technique>', '      </extra>']
    return "\n".join(x + ['    </effect>'])


def microfacet(alpha, eta, k):
    return ['<microfacet>', f'  <alpha>{num(alpha)}</alpha>', '  <eta>' + " ".join(num(v) for v in eta) + '</eta>',
            '  <k>' + " ".join(num(v) for v in k) + '</k>', '</microfacet>']


def geometry_xml(name, pos, faces, material):
    pa = " ".join(num(c) for p in pos for c in to_blender(p))
    return "\n".join([
        f'    <geometry id="{name}-mesh" name="{name}">', '      <mesh>',
        f'        <source id="{name}-mesh-positions">',
        f'          <float_array id="{name}-mesh-positions-array" count="{3 * len(pos)}">{pa}</float_array>',
        '          <technique_common>',
        f'            <accessor source="#{name}-mesh-positions-array" count="{len(pos)}" stride="3">',
        '              <param name="X" type="float"/>', '              <param name="Y" type="float"/>',
        '              <param name="Z" type="float"/>', '            </accessor>', '          </technique_common>',
        '        </source>',
        f'        <vertices id="{name}-mesh-vertices">',
        f'          <input semantic="POSITION" source="#{name}-mesh-positions"/>', '        </vertices>',
        f'        <polylist material="{material}" count="{len(faces)}">',
        f'          <input semantic="VERTEX" source="#{name}-mesh-vertices" offset="0"/>',
        '          <vcount>' + " ".join("3" for _ in faces) + '</vcount>',
        '          <p>' + " ".join(f"{a} {b} {c}" for a, b, c in faces) + '</p>',
        '        </polylist>', '      </mesh>', '    </geometry>'])


def node_xml(name, matrix, payload):
    m = " ".join(num(v) for row in matrix for v in row)
    return (f'      <node id="{name}" name="{name}" type="NODE">\n        <matrix sid="transform">{m}</matrix>\n'
            f'{payload}\n      </node>')


def geometry_node(name, material):
    return node_xml(name, [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
                    f'        <instance_geometry url="#{name}-mesh">\n          <bind_material>\n'
                    f'            <technique_common>\n'
                    f'              <instance_material symbol="{material}" target="#{material}"/>\n'
                    f'            </technique_common>\n          </bind_material>\n        </instance_geometry>')


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: generate_heavy.py OUTPUT.dae")
    out_path = sys.argv[1]

    # World frame: box x in [-1, 1], y in [-0.75, 0.75], z in [-1, 1], open towards +z; the
    # bounding-box centre is the origin, so the course framing puts the camera at (0, 0, 4.8).
    x0, x1, y0, y1, z0, z1 = -1.0, 1.0, -0.75, 0.75, -1.0, 1.0
    walls = [  # (name, material, quad counter-clockwise seen from inside)
        ("floor", "white", [(x0, y0, z1), (x1, y0, z1), (x1, y0, z0), (x0, y0, z0)]),
        ("ceiling", "white", [(x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)]),
        ("back_wall", "white", [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)]),
        ("left_wall", "brick", [(x0, y0, z1), (x0, y0, z0), (x0, y1, z0), (x0, y1, z1)]),
        ("right_wall", "teal", [(x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0)]),
    ]
    objects = [
        ("rock", "gold", rock((0.0, y0 + 0.47, -0.25), 0.42)),
        ("ceramic_torus", "ceramic",
         torus((-0.55, y0 + 0.30, 0.35), 0.22, 0.075, 128, 48, lambda p: rotate_y(rotate_x(p, 90), 35))),
        ("copper_torus", "copper",
         torus((0.55, y0 + 0.245, 0.38), 0.2, 0.07, 128, 48, lambda p: rotate_y(rotate_x(p, 60), -25))),
    ]
    for name, _, (pos, faces) in objects:
        if signed_volume(pos, faces) <= 0:
            raise SystemExit(f"internal error: {name} is not outward oriented")

    effects = [
        effect_xml("white", (0.75, 0.75, 0.72)),
        effect_xml("brick", (0.62, 0.18, 0.1)),
        effect_xml("teal", (0.1, 0.42, 0.45)),
        effect_xml("ceramic", (0.85, 0.85, 0.8)),
        # Gold and copper at 614 / 549 / 466 nm (the course's RGB convention).
        effect_xml("gold", (0.8, 0.6, 0.2), microfacet(0.2, (0.21646, 0.42833, 1.3284), (3.239, 2.4599, 1.8661))),
        effect_xml("copper", (0.8, 0.4, 0.3), microfacet(0.12, (0.2004, 0.92406, 1.1023), (3.9129, 2.4528, 2.1421))),
    ]
    materials = [f'    <material id="{m}" name="{m}">\n      <instance_effect url="#{m}-effect"/>\n    </material>'
                 for m in ("white", "brick", "teal", "ceramic", "gold", "copper")]
    geometries, nodes = [], []

    # Area light 0.7 x 0.5 just under the ceiling, facing down: node scale gives its size.
    nodes.append(node_xml("ceiling_light", [[0.7, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1, y1 - 0.01], [0, 0, 0, 1]],
                          '        <instance_light url="#ceiling_light-light"/>'))
    # Camera at (0, 0, 4.8) looking at the origin (the course framing computes the same pose).
    nodes.append(node_xml("camera", [[-1, 0, 0, 0], [0, 0, 1, 4.8], [0, 1, 0, 0], [0, 0, 0, 1]],
                          '        <instance_camera url="#camera-camera"/>'))
    triangles = 0
    for name, material, quad in walls:
        geometries.append(geometry_xml(name, quad, [(0, 1, 2), (0, 2, 3)], material))
        nodes.append(geometry_node(name, material))
        triangles += 2
    for name, material, (pos, faces) in objects:
        geometries.append(geometry_xml(name, pos, faces, material))
        nodes.append(geometry_node(name, material))
        triangles += len(faces)

    text = "\n".join([
        '<?xml version="1.0" encoding="utf-8"?>',
        '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">',
        f'  <!-- Generated by scenes/generate_heavy.py: {triangles} triangles. Do not edit. -->',
        '  <asset>', '    <contributor>', '      <author>pathtracer project</author>',
        '      <authoring_tool>scenes/generate_heavy.py</authoring_tool>', '    </contributor>',
        '    <unit name="meter" meter="1"/>', '    <up_axis>Z_UP</up_axis>', '  </asset>',
        '  <library_lights>', '    <light id="ceiling_light-light" name="ceiling_light">',
        '      <technique_common>', '        <point>', '          <color sid="color">12 11.5 10.5</color>',
        '          <constant_attenuation>1</constant_attenuation>', '          <linear_attenuation>0</linear_attenuation>',
        '          <quadratic_attenuation>0</quadratic_attenuation>', '        </point>', '      </technique_common>',
        '      <extra>', '        <technique profile="CGL">', '          <area>',
        '            <color sid="color">12 11.5 10.5</color>', '          </area>', '        </technique>',
        '      </extra>', '    </light>', '  </library_lights>',
        '  <library_cameras>', '    <camera id="camera-camera" name="camera">', '      <optics>',
        '        <technique_common>', '          <perspective>', '            <xfov sid="xfov">49.13434</xfov>',
        '            <aspect_ratio>1.333333</aspect_ratio>', '            <znear sid="znear">0.1</znear>',
        '            <zfar sid="zfar">100</zfar>', '          </perspective>', '        </technique_common>',
        '      </optics>', '    </camera>', '  </library_cameras>',
        '  <library_effects>', *effects, '  </library_effects>',
        '  <library_materials>', *materials, '  </library_materials>',
        '  <library_geometries>', *geometries, '  </library_geometries>',
        '  <library_visual_scenes>', '    <visual_scene id="Scene" name="heavy">', *nodes, '    </visual_scene>',
        '  </library_visual_scenes>',
        '  <scene>', '    <instance_visual_scene url="#Scene"/>', '  </scene>',
        '</COLLADA>', ''])

    out_dir = os.path.dirname(os.path.abspath(out_path))
    os.makedirs(out_dir, exist_ok=True)
    tmp = out_path + ".tmp"
    with open(tmp, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)
    os.replace(tmp, out_path)  # never leave a half-written scene behind
    print(f"wrote {out_path}: {triangles} triangles")


if __name__ == "__main__":
    main()
