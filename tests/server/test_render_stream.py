"""A job from submission to image: its event stream delivers every tile (placed on the tile grid,
clipped at the edges) and ends with state done; the painted tiles are the final PNG; the server's
EXR and PNG are bit-identical to the pathtracer command's render of the same spec and seed."""
import pytest

from images import Canvas, decode_png, read_exr, render_cli, tonemap_course
from support import CORNELL, ENDLESS

SPECS = {
    # non-adaptive, 16-pixel tiles, two light samples
    "fixed": {"scene": "cornell", "width": 64, "height": 48, "spp": 8, "max_depth": 3, "light_samples": 2,
              "seed": 7, "adaptive": False, "tile_size": 16},
    # server defaults for everything else (adaptive 32/0.05, depth 5, 32-pixel tiles: 72x40 clips edge tiles)
    "defaults": {"scene": "cornell", "width": 72, "height": 40, "spp": 16, "seed": 3},
    # thin lens, hemisphere direct lighting, the file's camera
    "lens": {"scene": "cornell", "width": 48, "height": 40, "spp": 8, "max_depth": 4, "aperture": 0.05,
             "focal_distance": 4.5, "hemisphere": True, "file_camera": True, "adaptive_batch": 4,
             "adaptive_tolerance": 0.2, "seed": 11, "tile_size": 8},
}


@pytest.mark.parametrize("name", SPECS)
def test_stream_tiles_then_images_match_the_cli(server, tmp_path, name):
    api = server.api
    # A running job holds the single worker, so the stream below opens before ours starts.
    blocker = api.submit(ENDLESS)
    api.wait(blocker["id"], "running")
    job = api.submit(SPECS[name])
    assert job["state"] == "queued"
    spec = job["spec"]
    stream = server.events(job["id"])
    assert stream.status == 200 and stream.content_type.startswith("text/event-stream")
    first = stream.next()
    assert first.kind == "status" and first.data["state"] == "queued"  # no picture yet: no image event
    api.delete(f"/api/jobs/{blocker['id']}", expect=200)

    canvas = Canvas(spec["width"], spec["height"], spec["tile_size"])
    assert job["stream_tile_size"] == canvas.tile_size >= 64
    states, tiles, last_id = ["queued"], 0, first.id
    events = stream.until_end()
    for ev in events:
        assert ev.id >= last_id, "event ids never go back"
        last_id = ev.id
        if ev.kind == "status":
            if ev.data["state"] != states[-1]:
                states.append(ev.data["state"])
            assert ev.data["id"] == job["id"]
        elif ev.kind == "tile":
            canvas.paint_tile(ev.data)
            tiles += 1
        else:
            assert ev.kind == "end", ev
    assert stream.retry == 2000
    assert events[-1].data == {"state": "done"}
    assert states == ["queued", "running", "done"]
    assert tiles >= canvas.tile_count() and len(canvas.painted) == canvas.tile_count()

    final = api.job(job["id"])
    assert final["state"] == "done" and final["progress"] == 1
    assert final["samples"] > 0 and final["error_history"], final
    if not spec["adaptive"]:
        assert final["samples"] == spec["width"] * spec["height"] * spec["spp"]
        assert final["spp_done"] == spec["spp"]

    # The painted stream is the final PNG, pixel for pixel.
    png = api.get(f"/api/jobs/{job['id']}/image.png").content
    w, h, pixels = decode_png(png)
    assert (w, h) == (spec["width"], spec["height"])
    assert bytes(canvas.pixels) == pixels

    # The same spec through the pathtracer command: identical pixels in both formats.
    exr = api.get(f"/api/jobs/{job['id']}/image.exr").content
    cli_exr = render_cli(spec, CORNELL, tmp_path / "cli.exr")
    cli_png = render_cli(spec, CORNELL, tmp_path / "cli.png")
    sw, sh, server_px, attrs = read_exr(exr)
    cw, ch, cli_px, cli_attrs = read_exr(cli_exr)
    assert (sw, sh) == (cw, ch) == (spec["width"], spec["height"])
    assert sorted(server_px) == ["B", "G", "R"]
    for c in "RGB":
        assert server_px[c] == cli_px[c], f"channel {c} differs from the CLI render"
    assert decode_png(cli_png)[2] == pixels
    # The EXR decoder agrees with the PNG (same tone mapping, 1 level of float slack).
    for i in range(0, sw * sh, 97):
        assert abs(tonemap_course(server_px["R"][i]) - pixels[3 * i]) <= 1
    assert attrs["pathtracer:job"] == job["id"]
    assert attrs["pathtracer:seed"] == str(spec["seed"]) == cli_attrs["pathtracer:seed"]


def test_images_are_404_before_any_pixel_and_live_while_rendering(server):
    api = server.api
    blocker = api.submit(ENDLESS)
    queued = api.submit(dict(ENDLESS, seed=5))
    for ext in ("png", "exr"):
        api.error(api.get(f"/api/jobs/{queued['id']}/image.{ext}", expect=None), 404)
    # The running job serves its current picture before it is done.
    api.wait(blocker["id"], "running", samples=160 * 120)  # the first pass has painted every tile
    w, h, _ = decode_png(api.get(f"/api/jobs/{blocker['id']}/image.png").content)
    assert (w, h) == (160, 120)
    assert read_exr(api.get(f"/api/jobs/{blocker['id']}/image.exr").content)[:2] == (160, 120)
    api.delete(f"/api/jobs/{queued['id']}", expect=200)
    api.delete(f"/api/jobs/{blocker['id']}", expect=200)
