"""Cycles renders of a glTF file for bench/vs_cycles.py and bench/denoise_bench.py, through Blender
as a Python module (bpy, in build/cycles-venv): the file is read by Blender's own glTF importer, as a
user's would be, and rendered with the settings of issue #52 (configure), with or without Cycles'
denoiser (set_denoising). Also reads EXRs with the OpenImageIO module that the bpy wheel bundles,
and offers scene variants that test one convention at a time (VARIANTS).
"""
import contextlib
import os
import re
import sys
import time
from pathlib import Path

import bpy
import numpy as np

# What each --cycles-variant changes in the imported scene, to measure one convention at a time.
VARIANTS = {
    "front-emission": "every emissive material emits from its front (counter-clockwise) side only (doubleSided false ones always do)",
    "emission-only": "emissive materials are a bare Emission shader: they reflect nothing, as the course's emitters",
    "lambert": "opaque dielectrics (metallic 0, transmission 0) are a Lambert Diffuse BSDF of the base colour",
    "no-specular": "Principled 'Specular IOR Level' 0 on opaque dielectrics: no F0 0.04 layer, diffuse alone",
}


def import_oiio():
    """The OpenImageIO module shipped inside the bpy wheel (bpy/<version>/python/lib/.../site-packages)."""
    base = Path(bpy.__file__).resolve().parents[3] / "python" / "lib"
    sys.path.extend(str(p) for p in base.glob("python3*/site-packages"))
    import OpenImageIO
    return OpenImageIO


def read_exr(path):
    """An EXR's first three channels as a float32 (height, width, 3) array, top row first."""
    oiio = import_oiio()
    inp = oiio.ImageInput.open(str(path))
    if not inp:
        raise RuntimeError(f"{path}: {oiio.geterror()}")
    pixels = inp.read_image(0, 0, 0, 3, "float")
    inp.close()
    return np.asarray(pixels, dtype=np.float32)


@contextlib.contextmanager
def quiet_stdout():
    """Blender's log lines (import steps, "Saved: ...") off stdout, which carries only results."""
    sys.stdout.flush()
    saved, null = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(null)


def principled(mat):
    if not mat.node_tree:
        return None, None
    nodes = mat.node_tree.nodes
    bsdf = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
    out = next((n for n in nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
    return bsdf, out


def is_emissive(bsdf):
    strength = bsdf.inputs["Emission Strength"]
    colour = bsdf.inputs["Emission Color"]
    return (strength.is_linked or strength.default_value > 0) and (
        colour.is_linked or max(colour.default_value[:3]) > 0)


def plain_value(socket):
    return None if socket.is_linked else socket.default_value


def link_or_copy(links, src, dst):
    """dst takes what feeds src: its link, else its value."""
    if src.is_linked:
        links.new(src.links[0].from_socket, dst)
    else:
        dst.default_value = src.default_value


def rewire_emitter(mat, bsdf, out, front_only, bare):
    """front-emission and emission-only on one emissive material."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    strength = bsdf.inputs["Emission Strength"]
    if bare:
        emit = nodes.new("ShaderNodeEmission")
        link_or_copy(links, bsdf.inputs["Emission Color"], emit.inputs["Color"])
        link_or_copy(links, strength, emit.inputs["Strength"])
        links.new(emit.outputs[0], out.inputs["Surface"])
        strength = emit.inputs["Strength"]
    if front_only:  # strength x (1 - Backfacing): Cycles' emission closure is two-sided
        geo = nodes.new("ShaderNodeNewGeometry")
        flip = nodes.new("ShaderNodeMath")
        flip.operation = "SUBTRACT"
        flip.inputs[0].default_value = 1.0
        links.new(geo.outputs["Backfacing"], flip.inputs[1])
        scale = nodes.new("ShaderNodeMath")
        scale.operation = "MULTIPLY"
        link_or_copy(links, strength, scale.inputs[0])
        links.new(flip.outputs[0], scale.inputs[1])
        links.new(scale.outputs[0], strength)
        mat.cycles.emission_sampling = "FRONT"


def rewire_dielectric(mat, bsdf, out, variants):
    """lambert and no-specular on one opaque dielectric (metallic 0, transmission 0)."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    if "lambert" in variants:
        diffuse = nodes.new("ShaderNodeBsdfDiffuse")
        link_or_copy(links, bsdf.inputs["Base Color"], diffuse.inputs["Color"])
        if bsdf.inputs["Normal"].is_linked:
            links.new(bsdf.inputs["Normal"].links[0].from_socket, diffuse.inputs["Normal"])
        links.new(diffuse.outputs[0], out.inputs["Surface"])
    elif "no-specular" in variants:
        bsdf.inputs["Specular IOR Level"].default_value = 0.0


def load_glb(path, variants=()):
    """A fresh scene holding the glTF file as Blender's importer makes it, with its camera made the
    scene's; the world is black, or a uniform white not seen by camera rays when the file has no
    light and no emissive material (our renderer's default light). Returns what the file holds."""
    unknown = [v for v in variants if v not in VARIANTS]
    if unknown:
        raise SystemExit(f"cycles_render: unknown variant {unknown[0]} (known: {', '.join(VARIANTS)})")
    with quiet_stdout():
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.import_scene.gltf(filepath=str(path))
    scene = bpy.context.scene
    cameras = sorted((o for o in scene.objects if o.type == "CAMERA"), key=lambda o: o.name)
    if not cameras:
        raise SystemExit(f"cycles_render: {path} has no camera")
    scene.camera = cameras[0]
    lights = [o for o in scene.objects if o.type == "LIGHT"]
    emissive = []
    for mat in bpy.data.materials:
        bsdf, out = principled(mat)
        if bsdf is None:
            continue
        if is_emissive(bsdf):
            emissive.append(mat.name)
            # glTF's doubleSided false culls the back face, so nothing leaves it; the importer only
            # sets use_backface_culling, which Cycles' emission ignores (docs/gltf.md).
            front = "front-emission" in variants or mat.use_backface_culling
            rewire_emitter(mat, bsdf, out, front, "emission-only" in variants)
        elif plain_value(bsdf.inputs["Metallic"]) == 0 and plain_value(bsdf.inputs["Transmission Weight"]) == 0:
            rewire_dielectric(mat, bsdf, out, variants)
    world = bpy.data.worlds.new("vs_cycles world")
    background = world.node_tree.nodes["Background"]
    lit = bool(lights or emissive)
    background.inputs["Color"].default_value = (0, 0, 0, 1) if lit else (1, 1, 1, 1)
    background.inputs["Strength"].default_value = 0.0 if lit else DEFAULT_ENVIRONMENT
    scene.world = world  # before the visibility: Cycles' update callback reads the scene's world
    world.cycles_visibility.camera = False
    if not lit:
        add_default_sun(scene)
    return {"lights": [f"{o.data.type.lower()} {o.data.energy:g} W" for o in lights], "emissive": emissive,
            "world": "black" if lit else "our default light: white 0.5 (not seen by camera rays) and a sun of 2 W/m^2"}


# Our default light for a glTF scene without lights (renderer/render_scene.h, kDefault*): a white
# environment of radiance 0.5 and a sun of 2 W/m^2 towards glTF's normalize(0.25, 0.85, 0.45).
DEFAULT_ENVIRONMENT = 0.5
DEFAULT_SUN = 2.0
DEFAULT_SUN_TOWARDS_GLTF = (0.25, 0.85, 0.45)


def add_default_sun(scene):
    from mathutils import Vector
    x, y, z = DEFAULT_SUN_TOWARDS_GLTF
    towards = Vector((x, -z, y)).normalized()  # glTF's +Y up is Blender's +Z (the importer's axes)
    sun = bpy.data.lights.new("vs_cycles default sun", "SUN")
    sun.energy = DEFAULT_SUN
    sun.angle = 0.0
    obj = bpy.data.objects.new("vs_cycles default sun", sun)
    obj.rotation_euler = towards.to_track_quat("Z", "Y").to_euler()  # a sun shines along its -Z
    scene.collection.objects.link(obj)


def configure(width, height, bounces, threads):
    """Issue #52's settings: CPU, no clamping, glossy filter 0, light threshold 0, one-pixel box
    filter, Standard view, linear float EXR, no denoising, adaptive sampling or path guiding; every
    kind of bounce limited alike (vs_cycles.bounces_for_depth)."""
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.light_sampling_threshold = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.use_animated_seed = False
    c.use_guiding = False
    c.caustics_reflective = c.caustics_refractive = True
    c.max_bounces = bounces
    for kind in ("diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces"):
        setattr(c, kind, bounces)
    c.transparent_max_bounces = bounces
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGB"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"


def set_denoising(on):
    """Cycles' denoiser on or off (configure leaves it off). On: Blender's defaults for a final
    render, Open Image Denoise on the CPU with albedo and normal passes, prefilter ACCURATE (the
    passes denoised first) and quality HIGH; the EXR's combined pass is then the denoised image."""
    scene = bpy.context.scene
    c = scene.cycles
    c.use_denoising = on
    bpy.context.view_layer.cycles.use_denoising = True
    if on:
        c.denoiser = "OPENIMAGEDENOISE"
        c.denoising_input_passes = "RGB_ALBEDO_NORMAL"
        c.denoising_prefilter = "ACCURATE"
        c.denoising_quality = "HIGH"
        c.denoising_use_gpu = False


def render(out, spp, seed, on_progress=None):
    """Renders to the EXR `out`; returns the path-tracing seconds (from the first sample to the
    last, as Cycles' progress reports them: without the scene's sync, BVH build and saving).
    With denoising on, to Cycles' "Finished" instead, so that the denoising after the last sample
    is counted (the denoiser's kernels load before the first sample, as the render's do).
    on_progress(fraction) follows Cycles' sample count."""
    scene = bpy.context.scene
    denoising = scene.cycles.use_denoising
    scene.cycles.samples = spp
    scene.cycles.seed = seed
    scene.render.filepath = str(out)
    marks = {}

    def on_stats(text):
        now = time.perf_counter()
        m = re.search(r"Sample (\d+)/(\d+)", text)
        if m:
            marks.setdefault("start", now)
            if on_progress:
                on_progress(int(m.group(1)) / int(m.group(2)))
        if "Finished" in text or (not denoising and f"Sample {spp}/{spp}" in text):
            marks.setdefault("end", now)

    bpy.app.handlers.render_stats.append(on_stats)
    t0 = time.perf_counter()
    try:
        with quiet_stdout():
            bpy.ops.render.render(write_still=True)
    finally:
        bpy.app.handlers.render_stats.remove(on_stats)
    t1 = time.perf_counter()
    return marks.get("end", t1) - marks.get("start", t0)
