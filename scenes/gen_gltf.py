#!/usr/bin/env python3
"""Write the glTF 2.0 scenes of scenes/ (Python 3 standard library only):

    python3 scenes/gen_gltf.py [OUTDIR]        (default: the folder of this script)

* cornell_gltf.glb: scenes/cornell.dae converted to glTF (binary): the same walls, blocks, colours,
  camera; the Lambertian surfaces become metallic 0 with KHR_materials_specular's factor 0 (no
  dielectric specular layer), the CGL area light an emissive quad (KHR_materials_emissive_strength,
  one-sided: doubleSided false, black and without specular layer, so it reflects nothing), the CGL
  spheres smooth-shaded UV spheres, the mirror a smooth metal, the glass
  KHR_materials_transmission with KHR_materials_ior. tests/test_gltf_render.cpp renders it against
  the .dae.
* showcase.gltf: what the glTF reader supports, in one JSON file with data: URIs: a checkerboard
  floor (an embedded PNG; REPEAT and MIRRORED_REPEAT wrapping), a wall with vertex colours
  (COLOR_0), a glass sphere, a rough gold sphere, an emissive panel, a KHR_lights_punctual spot
  light (candela) and a perspective camera.

The output is deterministic for a given zlib.
"""
import base64
import json
import math
import os
import struct
import sys
import xml.etree.ElementTree as ET
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
COLLADA_NS = "{http://www.collada.org/2005/11/COLLADASchema}"

# ---------------------------------------------------------------------------------------------
# glTF writing


class Gltf:
    """A glTF document with one binary buffer; accessors are appended to it."""

    def __init__(self, generator):
        self.doc = {"asset": {"version": "2.0", "generator": generator}, "scene": 0, "scenes": [{"nodes": []}],
                    "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [], "buffers": []}
        self.bin = bytearray()
        self.extensions = set()

    def _view(self, data, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.bin += data
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, view, ctype, count, kind, extra=None):
        acc = {"bufferView": view, "componentType": ctype, "count": count, "type": kind}
        acc.update(extra or {})
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def vectors(self, rows, kind):
        flat = [float(v) for row in rows for v in row]
        view = self._view(struct.pack("<%df" % len(flat), *flat), 34962)
        extra = {}
        if kind == "VEC3":  # POSITION needs its bounds
            extra = {"min": [min(r[i] for r in rows) for i in range(3)], "max": [max(r[i] for r in rows) for i in range(3)]}
        return self._accessor(view, 5126, len(rows), kind, extra)

    def indices(self, idx):
        big = max(idx) > 65535
        view = self._view(struct.pack("<%d%s" % (len(idx), "I" if big else "H"), *idx), 34963)
        return self._accessor(view, 5125 if big else 5123, len(idx), "SCALAR")

    def mesh(self, name, positions, indices, material, normals=None, uvs=None, colors=None):
        attrs = {"POSITION": self.vectors(positions, "VEC3")}
        if normals:
            attrs["NORMAL"] = self.vectors(normals, "VEC3")
        if uvs:
            attrs["TEXCOORD_0"] = self.vectors(uvs, "VEC2")
        if colors:
            attrs["COLOR_0"] = self.vectors(colors, "VEC4")
        prim = {"attributes": attrs, "indices": self.indices(indices), "material": material}
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def material(self, name, base=(1, 1, 1), metallic=0.0, roughness=1.0, emissive=None, transmission=None, ior=None,
                 texture=None, specular=None):
        pbr = {"baseColorFactor": [*base, 1.0], "metallicFactor": metallic, "roughnessFactor": roughness}
        if texture is not None:
            pbr["baseColorTexture"] = {"index": texture}
        m = {"name": name, "pbrMetallicRoughness": pbr}
        ext = {}
        if emissive:
            peak = max(emissive)
            m["emissiveFactor"] = [c / peak for c in emissive]
            if peak != 1:
                ext["KHR_materials_emissive_strength"] = {"emissiveStrength": peak}
        if transmission is not None:
            ext["KHR_materials_transmission"] = {"transmissionFactor": transmission}
        if ior is not None:
            ext["KHR_materials_ior"] = {"ior": ior}
        if specular is not None:  # 0: no dielectric specular layer, a Lambertian surface
            ext["KHR_materials_specular"] = {"specularFactor": specular}
        if ext:
            m["extensions"] = ext
            self.extensions.update(ext)
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def node(self, name, **props):
        node = {"name": name}
        node.update(props)
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)
        return len(self.doc["nodes"]) - 1

    def _finish(self, buffer):
        doc = dict(self.doc)
        doc["buffers"] = [buffer]
        if self.extensions:
            doc["extensionsUsed"] = sorted(self.extensions)
        return doc

    def write_glb(self, path):
        while len(self.bin) % 4:
            self.bin.append(0)
        text = json.dumps(self._finish({"byteLength": len(self.bin)}), separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(self.bin))
        out += struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(self.bin), 0x004E4942) + self.bin
        with open(path, "wb") as f:
            f.write(out)

    def write_gltf(self, path):
        uri = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.bin)).decode()
        with open(path, "w") as f:
            json.dump(self._finish({"byteLength": len(self.bin), "uri": uri}), f, indent=1)
            f.write("\n")


def uv_sphere(center, radius, segments, rings):
    """A UV sphere, counter-clockwise seen from outside, with unit normals and uvs."""
    pos, nrm, uvs, idx = [], [], [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            nrm.append(n)
            pos.append(tuple(center[i] + radius * n[i] for i in range(3)))
            uvs.append((s / segments, r / rings))
    row = segments + 1
    for r in range(rings):
        for s in range(segments):
            a, b = r * row + s, (r + 1) * row + s
            if r > 0:
                idx += [a, b, a + 1]
            if r < rings - 1:
                idx += [a + 1, b, b + 1]
    return pos, nrm, uvs, idx


def png_rgb(width, height, pixel):
    """An 8-bit RGB PNG of pixel(x, y) -> (r, g, b)."""
    raw = b"".join(b"\x00" + bytes(c for x in range(width) for c in pixel(x, y)) for y in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


# ---------------------------------------------------------------------------------------------
# cornell.dae -> cornell_gltf.glb


def collada_cornell(path):
    """The meshes, spheres, area light and camera of cornell.dae in the renderer's Y-up world."""
    root = ET.parse(path).getroot()
    q = lambda el, tag: el.find(COLLADA_NS + tag)
    qa = lambda el, tag: el.findall(COLLADA_NS + tag)
    nums = lambda el: [float(v) for v in el.text.split()]
    ids = {el.get("id"): el for el in root.iter() if el.get("id")}
    up = [[-1, 0, 0, 0], [0, 0, 1, 0], [0, 1, 0, 0], [0, 0, 0, 1]]  # Z_UP: (x, y, z) -> (-x, z, y)

    def matmul(a, b):
        return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]

    def apply(m, p, w=1.0):
        return tuple(m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3] * w for i in range(3))

    def colour(effect):
        cgl = [t for t in effect.iter(COLLADA_NS + "technique") if t.get("profile") == "CGL"]
        for t in cgl:
            if q(t, "mirror") is not None:
                return ("mirror", nums(q(q(t, "mirror"), "reflectance")))
            if q(t, "glass") is not None:
                g = q(t, "glass")
                return ("glass", nums(q(g, "transmittance")), nums(q(g, "ior"))[0])
        return ("diffuse", nums(next(effect.iter(COLLADA_NS + "diffuse")).find(COLLADA_NS + "color"))[:3])

    scene = {"meshes": [], "spheres": [], "light": None, "camera": None}
    for node in root.iter(COLLADA_NS + "node"):
        m = nums(q(node, "matrix"))
        world = matmul(up, [m[0:4], m[4:8], m[8:12], m[12:16]])
        if q(node, "instance_light") is not None:
            light = ids[q(node, "instance_light").get("url")[1:]]
            area = next(t for t in light.iter(COLLADA_NS + "technique") if t.get("profile") == "CGL")
            scene["light"] = {"centre": apply(world, (0, 0, 0)), "dx": apply(world, (-1, 0, 0), 0),
                              "dy": apply(world, (0, 1, 0), 0), "facing": apply(world, (0, 0, -1), 0),
                              "radiance": nums(q(q(area, "area"), "color"))}
        elif q(node, "instance_camera") is not None:
            cam = ids[q(node, "instance_camera").get("url")[1:]]
            persp = next(cam.iter(COLLADA_NS + "perspective"))
            scene["camera"] = {"position": apply(world, (0, 0, 0)), "xfov": nums(q(persp, "xfov"))[0],
                               "aspect": nums(q(persp, "aspect_ratio"))[0]}
        elif q(node, "instance_geometry") is not None:
            inst = q(node, "instance_geometry")
            geom = ids[inst.get("url")[1:]]
            mat = ids[next(inst.iter(COLLADA_NS + "instance_material")).get("target")[1:]]
            effect = ids[q(mat, "instance_effect").get("url")[1:]]
            look = (mat.get("name"), colour(effect))
            sphere = next(geom.iter(COLLADA_NS + "sphere"), None)
            if sphere is not None:
                scene["spheres"].append((node.get("name"), apply(world, (0, 0, 0)), nums(q(sphere, "radius"))[0], look))
                continue
            mesh = q(geom, "mesh")
            poly = q(mesh, "polylist")
            vsrc = ids[q(ids[[i for i in qa(poly, "input") if i.get("semantic") == "VERTEX"][0].get("source")[1:]],
                         "input").get("source")[1:]]
            flat = nums(q(vsrc, "float_array"))
            stride = len(qa(poly, "input"))
            p = [int(v) for v in q(poly, "p").text.split()]
            corners = [apply(world, tuple(flat[3 * p[i]:3 * p[i] + 3])) for i in range(0, len(p), stride)]
            scene["meshes"].append((node.get("name"), corners, look))
    return scene


def write_cornell(out):
    scene = collada_cornell(os.path.join(HERE, "cornell.dae"))
    g = Gltf("scenes/gen_gltf.py from scenes/cornell.dae")
    materials = {}

    def material(look):
        name, kind = look
        if name not in materials:
            if kind[0] == "mirror":
                materials[name] = g.material(name, kind[1], metallic=1.0, roughness=0.0)
            elif kind[0] == "glass":
                materials[name] = g.material(name, kind[1], transmission=1.0, ior=kind[2], roughness=0.0)
            else:  # the course's Lambertian surfaces: glTF's dielectric without its specular layer
                materials[name] = g.material(name, kind[1], specular=0.0)
        return materials[name]

    for name, corners, look in scene["meshes"]:  # triangles that share no vertices: flat shading
        g.node(name, mesh=g.mesh(name, corners, list(range(len(corners))), material(look)))
    for name, centre, radius, look in scene["spheres"]:
        pos, nrm, _, idx = uv_sphere(centre, radius, 64, 32)
        g.node(name, mesh=g.mesh(name, pos, idx, material(look), normals=nrm))
    light = scene["light"]
    c, hx, hy = light["centre"], [v / 2 for v in light["dx"]], [v / 2 for v in light["dy"]]
    quad = [tuple(c[i] + sx * hx[i] + sy * hy[i] for i in range(3)) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    e1, e2 = [quad[1][i] - quad[0][i] for i in range(3)], [quad[2][i] - quad[0][i] for i in range(3)]
    normal = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
    idx = [0, 1, 2, 0, 2, 3] if sum(normal[i] * light["facing"][i] for i in range(3)) > 0 else [0, 2, 1, 0, 3, 2]
    emitter = g.material("ceiling_light", (0, 0, 0), emissive=light["radiance"], specular=0.0)  # reflects nothing
    g.node("ceiling_light", mesh=g.mesh("ceiling_light", quad, idx, emitter))
    cam = scene["camera"]
    yfov = 2 * math.atan(math.tan(math.radians(cam["xfov"]) / 2) / cam["aspect"])
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": cam["aspect"],
                                                                 "znear": 0.1, "zfar": 100}}]
    g.node("camera", camera=0, translation=list(cam["position"]))  # looks along -z, as the .dae's
    g.write_glb(os.path.join(out, "cornell_gltf.glb"))


# ---------------------------------------------------------------------------------------------
# showcase.gltf


def write_showcase(out):
    g = Gltf("scenes/gen_gltf.py")
    g.extensions.add("KHR_lights_punctual")

    def checker(x, y):  # 8 x 8 checks over 64 pixels, warm and cool, brighter to the right
        light = ((x // 8) + (y // 8)) % 2 == 0
        t = x / 63
        return (int(200 + 40 * t), int(170 + 30 * t), 120) if light else (40, int(60 + 30 * t), int(110 + 40 * t))

    png = png_rgb(64, 64, checker)
    g.doc["images"] = [{"name": "checker", "uri": "data:image/png;base64," + base64.b64encode(png).decode()}]
    g.doc["samplers"] = [{"magFilter": 9729, "minFilter": 9729, "wrapS": 10497, "wrapT": 33648}]
    g.doc["textures"] = [{"sampler": 0, "source": 0}]
    floor_mat = g.material("checker floor", (1, 1, 1), texture=0)
    s = 3.0  # the floor: 6 x 6 m, its uvs over [0, 3]: three checkerboards each way, every other mirrored in v
    floor = [(-s, 0, s), (s, 0, s), (s, 0, -s), (-s, 0, -s)]
    g.node("floor", mesh=g.mesh("floor", floor, [0, 1, 2, 0, 2, 3], floor_mat, normals=[(0, 1, 0)] * 4,
                                uvs=[(0, 3), (3, 3), (3, 0), (0, 0)]))
    wall = [(-s, 0, -2.5), (s, 0, -2.5), (s, 3, -2.5), (-s, 3, -2.5)]
    colours = [(0.9, 0.3, 0.3, 1), (0.3, 0.9, 0.3, 1), (0.3, 0.3, 0.9, 1), (0.9, 0.9, 0.9, 1)]
    wall_mat = g.material("vertex-coloured wall", (0.8, 0.8, 0.8))
    g.node("wall", mesh=g.mesh("wall", wall, [0, 1, 2, 0, 2, 3], wall_mat, colors=colours))
    glass = g.material("glass", (0.95, 0.98, 1.0), roughness=0.0, transmission=1.0, ior=1.5)
    pos, nrm, uvs, idx = uv_sphere((0, 0, 0), 0.6, 48, 24)
    g.node("glass sphere", mesh=g.mesh("glass sphere", pos, idx, glass, normals=nrm), translation=[-0.8, 0.6, 0.3])
    gold = g.material("rough gold", (1.0, 0.766, 0.336), metallic=1.0, roughness=0.35)
    pos, nrm, uvs, idx = uv_sphere((0, 0, 0), 0.5, 48, 24)
    g.node("gold sphere", mesh=g.mesh("gold sphere", pos, idx, gold, normals=nrm), translation=[0.9, 0.5, -0.6])
    panel = g.material("emissive panel", (0, 0, 0), emissive=(6.0, 5.4, 4.8))
    g.node("panel", mesh=g.mesh("panel", [(-0.6, 0, -0.3), (0.6, 0, -0.3), (0.6, 0, 0.3), (-0.6, 0, 0.3)],
                                [0, 1, 2, 0, 2, 3], panel), translation=[0, 2.6, 0])  # facing down
    # A spot light of 15,000 cd (about 22 W/sr in our units) aimed at the origin from (2.5, 3.5, 2.5).
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "spot", "type": "spot", "color": [1.0, 0.95, 0.85], "intensity": 15000.0,
         "spot": {"innerConeAngle": 0.35, "outerConeAngle": 0.5}}]}}
    g.node("spot", rotation=look_at_rotation((2.5, 3.5, 2.5), (0, 0, 0)), translation=[2.5, 3.5, 2.5],
           extensions={"KHR_lights_punctual": {"light": 0}})
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.75, "aspectRatio": 4 / 3, "znear": 0.05}}]
    g.node("camera", camera=0, rotation=look_at_rotation((0, 1.6, 5.5), (0, 0.8, 0)), translation=[0, 1.6, 5.5])
    g.write_gltf(os.path.join(out, "showcase.gltf"))


def look_at_rotation(eye, target):
    """The unit quaternion (x, y, z, w) turning local -z towards target (and local +y up)."""
    f = [target[i] - eye[i] for i in range(3)]
    n = math.sqrt(sum(v * v for v in f))
    back = [-v / n for v in f]
    right = [back[2], 0.0, -back[0]]  # up (0, 1, 0) x back
    n = math.sqrt(sum(v * v for v in right))
    right = [v / n for v in right]
    up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2],
          back[0] * right[1] - back[1] * right[0]]
    m = [[right[0], up[0], back[0]], [right[1], up[1], back[1]], [right[2], up[2], back[2]]]
    w = math.sqrt(max(0.0, 1 + m[0][0] + m[1][1] + m[2][2])) / 2
    return [(m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w), (m[1][0] - m[0][1]) / (4 * w), w]


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else HERE
    os.makedirs(out, exist_ok=True)
    write_cornell(out)
    write_showcase(out)
