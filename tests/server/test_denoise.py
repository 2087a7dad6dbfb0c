"""A job's denoise field (issue: denoising): denoised pictures at pass ends on the event stream, a
denoised finished image with its raw render beside it (?raw=1), the raw error estimate kept and the
denoised halves' noise reported apart; a server without the denoiser refuses the field with 422 and
says so in /api/health; a denoiser that fails leaves the job rendering raw with a warning; the
scale-out server denoises the workers' merged passes."""
import base64
import os

import pytest

from images import decode_png, read_exr
from support import TINY, cannot_run
from test_scale_out import Redis, Worker

SPEC = dict(TINY, width=96, height=72, spp=64, max_depth=4, adaptive=False)
FAKE_OIDN = os.environ.get("PT_FAKE_OIDN", "")


def need_denoiser(api):
    health = api.get("/api/health").json()["denoiser"]
    if not health["available"]:
        cannot_run(f"the denoiser is not installed: {health['description']}")
    return health


def finished(api, spec, timeout=120):
    job = api.submit(spec)
    done = api.wait(job["id"], {"done", "failed"}, timeout=timeout)
    assert done["state"] == "done", done
    return done


def lum_of_exr(data):
    w, h, ch, attrs = read_exr(data)
    return [0.2126 * r + 0.7152 * g + 0.0722 * b for r, g, b in zip(ch["R"], ch["G"], ch["B"])], attrs


def neighbour_roughness(lum, w, h):
    """Mean squared difference of horizontal neighbours: noise shows as roughness."""
    return sum((lum[y * w + x] - lum[y * w + x + 1]) ** 2 for y in range(h) for x in range(w - 1)) / (h * (w - 1))


def test_a_denoised_job_streams_denoised_frames_and_keeps_its_raw_render(servers):
    srv = servers("denoise", threads=2)
    api = srv.api
    health = need_denoiser(api)
    assert "Open Image Denoise" in health["description"] and "/" not in health["description"]  # no server paths
    job = api.submit(dict(SPEC, denoise="final"))
    kinds = []
    denoised_events = []
    stream = srv.events(job["id"], timeout=120)
    while (ev := stream.next()) is not None:
        kinds.append(ev.kind)
        if ev.kind == "denoised":
            denoised_events.append(ev.data)
        if ev.kind == "end":
            break
    assert denoised_events, kinds
    assert denoised_events[-1]["final"] is True
    for d in denoised_events:
        w, h, _ = decode_png(base64.b64decode(d["png"]))
        assert (w, h) == (96, 72)
    done = api.job(job["id"])
    den = done["denoise"]
    assert den["mode"] == "final" and den["final"] and den["frames"] >= 1 and "warning" not in den
    assert den["noise_estimate"] is not None and den["noise_estimate"] < done["error_estimate"]
    assert "raw render's" in den["noise_estimate_of"]

    denoised, attrs = lum_of_exr(api.get(f"/api/jobs/{job['id']}/image.exr").content)
    raw, raw_attrs = lum_of_exr(api.get(f"/api/jobs/{job['id']}/image.exr?raw=1").content)
    assert "Open Image Denoise" in attrs["pathtracer:denoised"] and "pathtracer:denoised" not in raw_attrs
    # The same picture, less noisy: the mean within a few percent, the pixel-to-pixel noise far lower.
    assert abs(sum(denoised) / sum(raw) - 1) < 0.05
    assert neighbour_roughness(denoised, 96, 72) < 0.5 * neighbour_roughness(raw, 96, 72)
    png = api.get(f"/api/jobs/{job['id']}/image.png").content
    raw_png = api.get(f"/api/jobs/{job['id']}/image.png?raw=1").content
    assert png != raw_png
    api.error(api.get(f"/api/jobs/{job['id']}/image.png?raw=yes", expect=400), 400, "raw")

    # A job without denoising has none of it, and ?raw=1 is its one image.
    plain = finished(api, SPEC)
    assert plain["denoise"] is None
    assert api.get(f"/api/jobs/{plain['id']}/image.png?raw=1").content == api.get(f"/api/jobs/{plain['id']}/image.png").content

    # The record survives a restart, and /pixels (the page's tools) stays the raw render's.
    pixels = api.get(f"/api/jobs/{job['id']}/pixels").content
    srv.terminate()
    srv = servers("denoise", threads=2)
    again = srv.api.job(job["id"])
    assert again["denoise"]["noise_estimate"] == den["noise_estimate"] and again["denoise"]["frames"] == den["frames"]
    assert srv.api.get(f"/api/jobs/{job['id']}/pixels").content == pixels


def test_without_the_denoiser_the_field_is_refused_with_422(servers):
    srv = servers("no-denoiser", env={"PT_OIDN_LIB": "/nonexistent/libOpenImageDenoise.so.2"})
    api = srv.api
    health = api.get("/api/health").json()["denoiser"]
    assert health["available"] is False and "scripts/install-oidn.sh" in health["description"]
    resp = api.post("/api/jobs", dict(TINY, denoise="preview"))
    api.error(resp, 422, "denoise")
    assert "not installed" in resp.json()["error"]["message"]
    assert "/nonexistent" not in resp.json()["error"]["message"]
    finished(api, dict(TINY, denoise="off"))  # everything else works


def test_a_failing_denoiser_leaves_the_job_rendering_raw_with_a_warning(servers):
    if not FAKE_OIDN:
        pytest.skip("PT_FAKE_OIDN is not set (ctest sets it)")
    srv = servers("failing", threads=2, env={"PT_OIDN_LIB": FAKE_OIDN, "FAKE_OIDN_FAIL": "1"})
    api = srv.api
    done = finished(api, dict(SPEC, denoise="final"))
    assert "out of memory" in done["denoise"]["warning"] and "raw render" in done["denoise"]["warning"]
    assert done["denoise"]["frames"] == 0
    assert done["spp_done"] == 64  # the render itself was not cut short
    # Its image is the raw render, and no raw twin pretends otherwise.
    assert api.get(f"/api/jobs/{done['id']}/image.png?raw=1").content == api.get(f"/api/jobs/{done['id']}/image.png").content
    _, attrs = lum_of_exr(api.get(f"/api/jobs/{done['id']}/image.exr").content)
    assert "pathtracer:denoised" not in attrs


def test_the_scale_out_server_denoises_the_workers_merged_passes(servers, tmp_path):
    redis = Redis(tmp_path)
    workers = []
    try:
        srv = servers("scaled-denoise", threads=2, args=["--queue", redis.url, "--units-in-flight", "4"])
        api = srv.api
        need_denoiser(api)
        workers = [Worker(tmp_path, redis.url, f"w{i}") for i in (1, 2)]
        done = finished(api, dict(SPEC, denoise="final"))
        assert done["denoise"]["final"] and done["denoise"]["noise_estimate"] is not None
        denoised, attrs = lum_of_exr(api.get(f"/api/jobs/{done['id']}/image.exr").content)
        raw, _ = lum_of_exr(api.get(f"/api/jobs/{done['id']}/image.exr?raw=1").content)
        assert attrs["pathtracer:backend"] == redis.url
        assert neighbour_roughness(denoised, 96, 72) < 0.5 * neighbour_roughness(raw, 96, 72)
        # The raw render is the one a single process renders: the features changed no sample.
        local = servers("single", threads=2)
        single = finished(local.api, dict(SPEC, denoise="final"))
        raw_single, _ = lum_of_exr(local.api.get(f"/api/jobs/{single['id']}/image.exr?raw=1").content)
        assert max(abs(a - b) / (abs(b) + 1e-3) for a, b in zip(raw, raw_single)) < 1e-3
    finally:
        for w in workers:
            w.stop()
        redis.stop()
