"""Our glTF test scenes for bench/vs_cycles.py, built in Blender with bpy and written by Blender's
own glTF exporter, as a user's would be (run inside build/cycles-venv, which vs_cycles.py makes):

    build/cycles-venv/bin/python bench/blender_scenes.py [OUTDIR [NAME ...]]    (default build/cycles-scenes, all)

Each scene has a camera (4:3) and a black world; its textures are generated here and packed into
the .glb (128x128 PNGs). The scenes: mr_grid (a 5x5 metallic/roughness sphere grid under an
emissive panel), plastic (dielectric specular layer at roughness 0.05, 0.2, 0.5), textured (checker
base colour, metallic-roughness and normal-map textures), glass (transmission at roughness 0 and
0.3), clearcoat (over a red base), punctual (point, spot and sun lights on diffuse objects), alpha
(a cut-out leaf, a fading card, a card of constant alpha), sheen (cloth-like spheres), volume (glass
slabs of three thicknesses absorbing inside, KHR_materials_volume), unlit (an unlit card standing
under the panel beside a diffuse sphere, KHR_materials_unlit).
Blender's exporter orders vertices differently from run to run (the same triangles), so a rewritten
scene has a new content hash and vs_cycles.py renders new references for it.
"""
import math
import sys
from pathlib import Path

import bpy  # first: it makes bmesh and mathutils importable
import bmesh
import numpy as np
from mathutils import Vector

from cycles_render import quiet_stdout
from io_scene_gltf2.blender.com.material_helpers import create_settings_group, get_gltf_node_name

ROOT = Path(__file__).resolve().parents[1]
TEX = 128  # texture size, texels a side
GREY = (0.5, 0.5, 0.5)


def reset():
    with quiet_stdout():
        bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 320, 240  # the exported camera's aspect
    world = bpy.data.worlds.new("black")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world


def material(name, base=GREY, **inputs):
    """A Principled BSDF material; inputs by socket name with spaces as underscores."""
    mat = bpy.data.materials.new(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1)
    for key, value in inputs.items():
        socket = bsdf.inputs[key.replace("_", " ")]
        socket.default_value = (*value, 1) if isinstance(value, tuple) else value
    return mat


def emitter(name, colour, strength):
    return material(name, (0, 0, 0), Emission_Color=colour, Emission_Strength=strength)


def add_object(name, build, mat, location=(0, 0, 0), rotation=(0, 0, 0), scale=(1, 1, 1), smooth=False):
    """An object whose mesh bmesh operator `build(bm)` makes, with one material."""
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    if any(n.type == "TEX_IMAGE" for n in mat.node_tree.nodes):  # uvs only where a texture reads them
        bm.loops.layers.uv.new("UVMap")  # calc_uvs fills the active uv layer: it must exist
    build(bm)
    bm.to_mesh(mesh)
    bm.free()
    if smooth:
        mesh.shade_smooth()
    mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    obj.location, obj.rotation_euler, obj.scale = location, rotation, scale
    bpy.context.scene.collection.objects.link(obj)
    return obj


def sphere(name, mat, location, radius, segments=32, rings=16):
    return add_object(name, lambda bm: bmesh.ops.create_uvsphere(
        bm, u_segments=segments, v_segments=rings, radius=radius, calc_uvs=True), mat, location, smooth=True)


def plane(name, mat, location, size, rotation=(0, 0, 0)):
    """A size[0] x size[1] rectangle facing +Z before the rotation, with uvs over [0, 1]."""
    return add_object(name, lambda bm: bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=0.5, calc_uvs=True),
                      mat, location, rotation, (size[0], size[1], 1))


def box(name, mat, location, size, angle=0.0):
    return add_object(name, lambda bm: bmesh.ops.create_cube(bm, size=1.0, calc_uvs=True), mat, location,
                      (0, 0, angle), size)


def look(obj, target):
    """Turns obj so that its -Z looks at target with +Y up (cameras, spots, suns)."""
    direction = Vector(target) - obj.location
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = direction.to_track_quat("-Z", "Y")


def camera(location, target, fov_y_deg):
    cam = bpy.data.cameras.new("camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(fov_y_deg)
    obj = bpy.data.objects.new("camera", cam)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)
    look(obj, target)
    bpy.context.scene.camera = obj


def light(kind, name, location, energy, colour=(1, 1, 1), target=None, **props):
    """A point (W), spot (W, as a point light's) or sun (W/m^2) light; punctual, so radius 0."""
    data = bpy.data.lights.new(name, kind)
    data.energy, data.color = energy, colour
    if kind == "SUN":
        data.angle = 0.0
    else:
        data.shadow_soft_size = 0.0
    for key, value in props.items():
        setattr(data, key, value)
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)
    if target:
        look(obj, target)


def image(name, rgb, colour_space, alpha=None):
    """A packed image from a (TEX, TEX, 3) array of 0..1 values, row 0 at the top (and its alpha)."""
    img = bpy.data.images.new(name, TEX, TEX, alpha=alpha is not None)
    img.colorspace_settings.name = colour_space  # first: it regenerates a generated image's pixels
    rgba = np.ones((TEX, TEX, 4), np.float32)
    rgba[..., :3] = rgb[::-1]  # Blender's rows run bottom-up
    if alpha is not None:
        rgba[..., 3] = alpha[::-1]
    img.pixels.foreach_set(rgba.ravel())
    img.update()
    img.file_format = "PNG"
    img.pack()
    return img


def textures():
    """Checker base colour, metallic-roughness (G roughness, B metalness) and a normal map of bumps."""
    y, x = np.mgrid[0:TEX, 0:TEX] + 0.5
    cell = TEX // 8
    check = ((x // cell + y // cell) % 2)[..., None]
    base = check * np.array([0.85, 0.75, 0.55]) + (1 - check) * np.array([0.15, 0.3, 0.55])
    # Columns of four: metal, dielectric alternating; roughness rising down the rows.
    mr = np.zeros((TEX, TEX, 3))
    mr[..., 1] = 0.15 + 0.7 * (y // (TEX // 4)) / 3
    mr[..., 2] = (x // (TEX // 4)) % 2 == 0
    # Tangent-space normals (OpenGL: +Y green up) of a hemispherical bump in each of 8x8 cells.
    u, v = (x % cell) / cell * 2 - 1, -((y % cell) / cell * 2 - 1)
    r2 = u * u + v * v
    inside = r2 < 0.64
    h = np.sqrt(np.where(inside, 0.64 - r2, 1.0))
    n = np.stack([np.where(inside, u / h * 0.5, 0), np.where(inside, v / h * 0.5, 0), np.ones_like(u)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return base, mr, n * 0.5 + 0.5


def textured_material(name):
    base, mr, normal = textures()
    mat = material(name)
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]

    def tex(img):
        node = nodes.new("ShaderNodeTexImage")
        node.image = img
        return node

    links.new(tex(image(f"{name} base colour", base, "sRGB")).outputs["Color"], bsdf.inputs["Base Color"])
    split = nodes.new("ShaderNodeSeparateColor")
    links.new(tex(image(f"{name} metallic-roughness", mr, "Non-Color")).outputs["Color"], split.inputs["Color"])
    links.new(split.outputs["Green"], bsdf.inputs["Roughness"])
    links.new(split.outputs["Blue"], bsdf.inputs["Metallic"])
    nmap = nodes.new("ShaderNodeNormalMap")
    links.new(tex(image(f"{name} normal", normal, "Non-Color")).outputs["Color"], nmap.inputs["Color"])
    links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    return mat


def checker_material(name):
    mat = material(name)
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image(f"{name} checker", textures()[0], "sRGB")
    mat.node_tree.links.new(node.outputs["Color"], mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def stage(floor=None, panel=12.0, wall=True):
    """A floor, a back wall and a 3 x 2 m emissive panel overhead, facing down."""
    floor = floor or material("floor", GREY, Roughness=0.8)
    plane("floor", floor, (0, 0, 0), (20, 20))
    if wall:
        plane("back wall", floor, (0, 4, 4), (20, 8), (math.radians(90), 0, 0))
    plane("panel", emitter("panel", (1.0, 0.95, 0.85), panel), (0, -1, 4.5), (3, 2), (math.pi, 0, 0))


def mr_grid():
    """metallic 0..1 down the image (far row 0), roughness 0..1 across; an orange-ish base colour."""
    stage()
    for row in range(5):
        for col in range(5):
            metallic, roughness = row / 4, col / 4
            mat = material(f"m{metallic:g} r{roughness:g}", (0.9, 0.55, 0.3), Metallic=metallic, Roughness=roughness)
            sphere(f"sphere m{metallic:g} r{roughness:g}", mat, ((col - 2) * 1.0, 2 - row * 1.0, 0.4), 0.4)
    camera((0, -6.5, 5.5), (0, 0, 0.3), 45)


def plastic():
    stage()
    for i, roughness in enumerate((0.05, 0.2, 0.5)):
        mat = material(f"plastic r{roughness:g}", (0.1, 0.25, 0.7), Metallic=0.0, Roughness=roughness)
        sphere(f"plastic r{roughness:g}", mat, ((i - 1) * 1.3, 0, 0.55), 0.55)
    camera((0, -4.5, 2.2), (0, 0, 0.5), 40)


def textured():
    stage()
    mat = textured_material("textured")
    sphere("textured sphere", mat, (-0.8, 0, 0.7), 0.7, 48, 24)
    box("textured box", mat, (0.9, 0.2, 0.6), (1.2, 1.2, 1.2), math.radians(30))
    sun = dict(angle=0.0)
    light("SUN", "sun", (3, -3, 5), 2.0, (1, 0.98, 0.95), target=(0, 0, 0), **sun)
    camera((0, -4.5, 2.4), (0, 0, 0.6), 40)


def glass():
    stage(checker_material("checker floor"), wall=False)
    plane("backdrop", material("backdrop", (0.7, 0.3, 0.2)), (0, 3, 2), (12, 4), (math.radians(90), 0, 0))
    for i, roughness in enumerate((0.0, 0.3)):
        mat = material(f"glass r{roughness:g}", (1, 1, 1), Roughness=roughness, Transmission_Weight=1.0, IOR=1.5)
        sphere(f"glass r{roughness:g}", mat, ((i - 0.5) * 1.5, 0, 0.6), 0.6, 48, 24)
    camera((0, -4.5, 2.0), (0, 0, 0.5), 40)


def clearcoat():
    stage()
    # Coat roughness 0.05, not Blender's default 0.03: the exporter omits 0.03, which glTF then reads as 0.
    looks = (("no coat", 0.0, 0.05), ("coat r0.05", 1.0, 0.05), ("coat r0.3", 1.0, 0.3))
    for i, (name, weight, coat_roughness) in enumerate(looks):
        mat = material(name, (0.8, 0.05, 0.05), Roughness=0.5, Coat_Weight=weight, Coat_Roughness=coat_roughness)
        sphere(name, mat, ((i - 1) * 1.3, 0, 0.55), 0.55)
    camera((0, -4.5, 2.2), (0, 0, 0.5), 40)


def alpha():
    """Cards standing on the floor under the panel: a leaf cut out (MASK, as Blender's 1 - (alpha <
    0.5) writes it), a card whose alpha fades across it (BLEND), one of constant alpha 0.4 (BLEND)."""
    stage()
    y, x = np.mgrid[0:TEX, 0:TEX] + 0.5
    u, v = x / TEX * 2 - 1, y / TEX * 2 - 1
    leaf = ((u / 0.55) ** 2 + (v / 0.95) ** 2 < 1) & (np.abs(u) > 0.04)  # an ellipse split by its vein
    green = np.zeros((TEX, TEX, 3)) + np.array([0.15, 0.5, 0.1])
    fade = np.broadcast_to(x / TEX, (TEX, TEX))
    orange = np.zeros((TEX, TEX, 3)) + np.array([0.8, 0.35, 0.1])
    cards = (("leaf", green, leaf.astype(float), True), ("fade", orange, fade, False))
    for i, (name, rgb, a, clip) in enumerate(cards):
        mat = material(name)
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        bsdf = nodes["Principled BSDF"]
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image(f"{name} texture", rgb, "sRGB", a)
        links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
        alpha_out = tex.outputs["Alpha"]
        if clip:
            less, one_minus = nodes.new("ShaderNodeMath"), nodes.new("ShaderNodeMath")
            less.operation, one_minus.operation = "LESS_THAN", "SUBTRACT"
            less.inputs[1].default_value = 0.5
            one_minus.inputs[0].default_value = 1.0
            links.new(alpha_out, less.inputs[0])
            links.new(less.outputs[0], one_minus.inputs[1])
            alpha_out = one_minus.outputs[0]
        links.new(alpha_out, bsdf.inputs["Alpha"])
        plane(f"{name} card", mat, ((i - 1) * 1.4, 0, 0.8), (1.2, 1.6), (math.radians(90), 0, 0))
    plane("glass card", material("constant alpha", (0.2, 0.3, 0.8), Alpha=0.4), (1.4, 0, 0.8), (1.2, 1.6),
          (math.radians(90), 0, 0))
    camera((0.4, -4.5, 2.0), (0, 0, 0.6), 40)


def sheen():
    """Sheen (Blender's Sheen Weight 1, glTF's KHR_materials_sheen) on dark cloth-like spheres."""
    stage()
    looks = (("no sheen", (0, 0, 0), 0.3), ("sheen r0.3", (1.0, 0.85, 0.7), 0.3), ("sheen r0.8", (0.6, 0.8, 1.0), 0.8))
    for i, (name, tint, sheen_roughness) in enumerate(looks):
        weight = 1.0 if max(tint) > 0 else 0.0
        mat = material(name, (0.25, 0.04, 0.08), Roughness=0.9, Sheen_Weight=weight, Sheen_Tint=tint,
                       Sheen_Roughness=sheen_roughness)
        sphere(name, mat, ((i - 1) * 1.3, 0, 0.55), 0.55)
    camera((0, -4.5, 2.2), (0, 0, 0.5), 40)


def punctual():
    """Diffuse objects under a point, a spot and a sun: no emissive surface."""
    white = material("white", (0.75, 0.75, 0.75), Roughness=1.0)
    plane("floor", white, (0, 0, 0), (12, 12))
    plane("back wall", white, (0, 3, 3), (12, 6), (math.radians(90), 0, 0))
    box("red box", material("red", (0.7, 0.1, 0.08), Roughness=1.0), (-1.3, 0.5, 0.5), (1, 1, 1), math.radians(20))
    sphere("green sphere", material("green", (0.15, 0.6, 0.15), Roughness=1.0), (0.2, 0, 0.6), 0.6)
    box("blue box", material("blue", (0.1, 0.2, 0.7), Roughness=1.0), (1.6, 0.8, 0.75), (0.8, 0.8, 1.5), -0.3)
    light("POINT", "point", (-1.5, -1.5, 2.5), 150.0, (1.0, 0.9, 0.8))
    light("SPOT", "spot", (2.5, -2.5, 3.5), 600.0, (0.8, 0.9, 1.0), target=(1.2, 0.5, 0.3),
          spot_size=math.radians(40), spot_blend=0.3)
    light("SUN", "sun", (0, 0, 6), 1.5, (1.0, 1.0, 0.95), target=(1, 2, 0))
    camera((0, -5.5, 2.5), (0, 0.5, 0.6), 45)


def volume():
    """KHR_materials_volume: upright slabs of smooth glass 0.1, 0.25 and 0.5 m thick (along the view),
    sharing one material whose Volume Absorption (amber, density 2 /m) feeds the output's Volume
    socket. The exporter writes the extension only from a glTF Material Output group with a
    non-zero Thickness (Add > Output > glTF Material Output): attenuationDistance = 1 / density."""
    stage()
    mat = material("amber glass", (1, 1, 1), Roughness=0.0, Transmission_Weight=1.0, IOR=1.5)
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    absorb = nodes.new("ShaderNodeVolumeAbsorption")
    absorb.inputs["Color"].default_value = (0.9, 0.55, 0.2, 1)
    absorb.inputs["Density"].default_value = 2.0
    links.new(absorb.outputs["Volume"], nodes["Material Output"].inputs["Volume"])
    settings = nodes.new("ShaderNodeGroup")  # as the add-on's menu operator makes it
    settings.node_tree = bpy.data.node_groups.get(get_gltf_node_name()) or create_settings_group(get_gltf_node_name())
    settings.inputs["Thickness"].default_value = 0.25
    for i, thickness in enumerate((0.1, 0.25, 0.5)):
        box(f"slab {thickness:g} m", mat, ((i - 1) * 1.3, 0, 0.51), (0.9, thickness, 1.0))
    camera((0, -4.5, 2.0), (0, 0, 0.5), 40)


def unlit():
    """KHR_materials_unlit: an orange card standing under the panel, made as the exporter detects it
    (Mix Shader of Light Path 'Is Camera Ray': Transparent BSDF, else Emission of the colour), beside
    a diffuse sphere; the card's shadow (if any) falls on the floor towards the camera."""
    stage()
    mat = bpy.data.materials.new("unlit orange")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.remove(nodes["Principled BSDF"])
    path, mix = nodes.new("ShaderNodeLightPath"), nodes.new("ShaderNodeMixShader")
    transparent, emission = nodes.new("ShaderNodeBsdfTransparent"), nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (0.9, 0.35, 0.05, 1)
    links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    links.new(transparent.outputs[0], mix.inputs[1])
    links.new(emission.outputs[0], mix.inputs[2])
    links.new(mix.outputs[0], nodes["Material Output"].inputs["Surface"])
    plane("unlit card", mat, (-0.7, -2.8, 0.5), (1.2, 1.0), (math.radians(90), 0, 0))
    sphere("diffuse sphere", material("white", (0.75, 0.75, 0.75), Roughness=1.0), (0.8, -1.5, 0.55), 0.55)
    camera((0, -6.5, 2.4), (0, -1.8, 0.4), 40)


SCENES = {"mr_grid": mr_grid, "plastic": plastic, "textured": textured, "glass": glass, "clearcoat": clearcoat,
          "punctual": punctual, "alpha": alpha, "sheen": sheen,
          "volume": volume, "unlit": unlit}


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "build" / "cycles-scenes"
    names = sys.argv[2:] or list(SCENES)
    unknown = [n for n in names if n not in SCENES]
    if unknown:
        sys.exit(f"blender_scenes: unknown scene {unknown[0]} (known: {', '.join(SCENES)})")
    out.mkdir(parents=True, exist_ok=True)
    for name in names:
        build = SCENES[name]
        reset()
        build()
        path = out / f"{name}.glb"
        with quiet_stdout():  # the exporter's log lines
            bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB", export_cameras=True,
                                      export_lights=True, export_yup=True)
        print(f"blender_scenes: {path} ({path.stat().st_size // 1024} KiB)")


if __name__ == "__main__":
    main()
