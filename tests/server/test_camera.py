"""A job's camera field (issue: move the camera): every job shows the camera it renders from
('view'); that view posted back as 'camera' renders the same image, another pose another one, the
CLI's --camera the same bits; the same vfov at half size is a smaller copy of the view, not a crop;
bad poses are refused by name; the view survives a restart and is in the EXR; focus off the image
centre finds the surface under that pixel (no flipped axis)."""
import base64
import json
import math
import struct

from images import read_exr, render_cli
from support import CORNELL, TINY

SPEC = dict(TINY, width=64, height=48, spp=16, adaptive=False)


def exr(api, job_id):
    w, h, ch, attrs = read_exr(api.get(f"/api/jobs/{job_id}/image.exr").content)
    return w, h, [(r + g + b) / 3 for r, g, b in zip(ch["R"], ch["G"], ch["B"])], attrs


def cells(w, h, lum, n=4):
    """Mean luminance of an n x n grid of cells."""
    sums = [0.0] * (n * n)
    for y in range(h):
        for x in range(w):
            sums[(y * n // h) * n + x * n // w] += lum[y * w + x]
    return [s / (w * h / (n * n)) for s in sums]


def render(api, spec):
    job = api.submit(spec)
    done = api.wait(job["id"], {"done", "failed"}, timeout=90)
    assert done["state"] == "done", done
    return done


def orbit(view, angle):
    """The view turned by `angle` around world +Y about its target (the page's horizontal drag)."""
    p, t = view["position"], view["target"]
    dx, dz = p[0] - t[0], p[2] - t[2]
    c, s = math.cos(angle), math.sin(angle)
    return dict(view, position=[t[0] + c * dx + s * dz, p[1], t[2] - s * dx + c * dz])


def test_the_view_posted_back_renders_the_same_image_and_a_new_pose_a_new_one(servers, tmp_path):
    srv = servers("camera", threads=2)
    api = srv.api
    framed = render(api, SPEC)
    view = framed["view"]
    assert framed["spec"]["camera"] is None
    assert math.dist(view["position"], view["target"]) > 1 and 1 < view["vfov"] < 90
    # /check answers the same view for the same spec, before any job exists.
    assert api.post("/api/jobs/check", SPEC, expect=200).json()["view"] == view

    again = render(api, dict(SPEC, camera=view))
    assert again["view"] == view and again["spec"]["camera"] == view
    w, h, a, _ = exr(api, framed["id"])
    _, _, b, attrs = exr(api, again["id"])
    mean = sum(a) / len(a)
    assert max(abs(x - y) for x, y in zip(cells(w, h, a), cells(w, h, b))) < 0.01 * mean
    assert json.loads(attrs["pathtracer:view"]) == view
    assert json.loads(attrs["pathtracer:spec"])["camera"] == view

    # A quarter turn around the box: another picture (the red and green walls trade places).
    turned = dict(orbit(view, math.pi / 2), up=[0, 1, 0])
    moved = render(api, dict(SPEC, camera=turned))
    assert moved["view"]["target"] == view["target"]
    assert math.isclose(math.dist(moved["view"]["position"], view["target"]),
                        math.dist(view["position"], view["target"]), rel_tol=1e-5)
    _, _, c, _ = exr(api, moved["id"])
    diff = sum(abs(x - y) for x, y in zip(cells(w, h, a), cells(w, h, c))) / 16
    assert diff > 0.1 * mean, f"a quarter turn changed the 4x4 cells by only {diff:.4f} (mean {mean:.4f})"

    # The CLI's --camera renders the same bits as the job.
    cli = read_exr(render_cli(moved["spec"], CORNELL, tmp_path / "cli.exr"))
    srv_exr = read_exr(api.get(f"/api/jobs/{moved['id']}/image.exr").content)
    assert cli[2] == srv_exr[2]

    # The view survives a restart, and the pose checks the server made still hold.
    srv.kill()
    srv = servers("camera", threads=2)
    assert srv.api.job(moved["id"])["view"] == moved["view"]


def test_the_same_vfov_at_half_size_is_a_smaller_copy_not_a_crop(servers):
    srv = servers("half", threads=2)
    api = srv.api
    spec = dict(SPEC, width=96, height=72, spp=32)
    full = render(api, spec)
    half_spec = dict(spec, width=48, height=36)
    copy = render(api, dict(half_spec, camera=full["view"]))
    crop = render(api, half_spec)  # the course keeps a pixel's angle: the centre of the view
    assert math.isclose(copy["view"]["vfov"], full["view"]["vfov"], rel_tol=1e-6)
    assert crop["view"]["vfov"] < 0.6 * full["view"]["vfov"]
    fw, fh, f, _ = exr(api, full["id"])
    hw, hh, c, _ = exr(api, copy["id"])
    _, _, r, _ = exr(api, crop["id"])
    mean = sum(f) / len(f)
    near = max(abs(x - y) for x, y in zip(cells(fw, fh, f), cells(hw, hh, c)))
    far = max(abs(x - y) for x, y in zip(cells(fw, fh, f), cells(hw, hh, r)))
    assert near < 0.15 * mean < far, (near, far, mean)


def test_bad_poses_are_refused_by_name(server):
    api = server.api
    base = {"position": [0, 1, 5], "target": [0, 1, 0]}
    cases = [
        ([1, 2, 3], "camera"),
        ({"target": [0, 0, 0]}, "camera.position"),
        ({"position": [0, 0, 1]}, "camera.target"),
        (dict(base, position=[0, 1]), "camera.position"),
        (dict(base, position=[0, "1", 5]), "camera.position"),
        (dict(base, target=[0, 1e8, 0]), "camera.target"),
        (dict(base, target=[0, 1, 5]), "camera.target"),
        (dict(base, up=[0, 0, 0]), "camera.up"),
        (dict(base, up=[0, 0, 3]), "camera.up"),
        (dict(base, vfov=0), "camera.vfov"),
        (dict(base, vfov=180), "camera.vfov"),
        (dict(base, vfov="wide"), "camera.vfov"),
        (dict(base, fov=30), "camera.fov"),
    ]
    for camera, field in cases:
        for path in ("/api/jobs/check", "/api/jobs"):
            resp = api.post(path, dict(TINY, camera=camera))
            err = api.error(resp, 400, field)
            assert field in err["message"], err
    # null is no camera: the scene's framing.
    assert api.post("/api/jobs/check", dict(TINY, camera=None), expect=200).json()["spec"]["camera"] is None
    job = api.submit(dict(TINY, camera=dict(base, up=None, vfov=None)))
    assert job["spec"]["camera"]["up"] == [0, 1, 0] and job["spec"]["camera"]["vfov"] is None
    assert job["view"]["position"] == [0, 1, 5] and job["view"]["vfov"] > 0


def planes_gltf():
    """Three quads facing +Z, seen from (0, 0, 10): the left half of the view at depth 10, the top
    right quarter at 15, the bottom right at 20. A flipped axis of the focus query shows."""
    quads = [(-20, 0, -20, 20, 0.0), (0, 20, 0, 20, -5.0), (0, 20, -20, 0, -10.0)]
    pos = []
    for x0, x1, y0, y1, z in quads:
        for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y0), (x1, y1), (x0, y1)):
            pos += [x, y, z]
    data = struct.pack(f"<{len(pos)}f", *pos)
    return json.dumps({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos) // 3, "type": "VEC3",
                       "min": [-20, -20, -10], "max": [20, 20, 0]}],
        "bufferViews": [{"buffer": 0, "byteLength": len(data)}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }).encode()


def test_focus_off_the_image_centre_finds_the_surface_under_that_pixel(server):
    api = server.api
    api.request("PUT", "/api/scenes/planes", 201, data=planes_gltf(), headers={"Content-Type": "model/gltf+json"})
    job = api.submit({"scene": "planes", "width": 64, "height": 48, "spp": 1,
                      "camera": {"position": [0, 0, 10], "target": [0, 0, 0], "vfov": 40}})
    api.wait(job["id"], "done", timeout=60)
    # x from the left, y from the top, as the page's clicks: depth along the view axis.
    for x, y, depth in ((16, 12, 10), (16, 36, 10), (48, 12, 15), (48, 36, 20), (63, 47, 20), (1, 1, 10)):
        got = api.get(f"/api/jobs/{job['id']}/focus?x={x}&y={y}").json()["distance"]
        assert math.isclose(got, depth, rel_tol=1e-3), f"focus at ({x}, {y}): {got}, expected {depth}"
