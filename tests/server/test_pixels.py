"""GET /api/jobs/{id}/pixels: the linear image as float32 with each pixel's sample count, what the
page's viewer tools read. Its values are image.exr's, its counts add up to the job's samples, and a
finished job answers the same after a restart (from image.exr and samples.bin)."""
import struct

from images import read_exr
from support import ENDLESS, TINY


def pixels(api, job_id):
    """(width, height, [(r, g, b, count)]) from /pixels."""
    resp = api.get(f"/api/jobs/{job_id}/pixels")
    w, h = int(resp.headers["X-Image-Width"]), int(resp.headers["X-Image-Height"])
    assert resp.headers["Content-Type"] == "application/octet-stream"
    assert len(resp.content) == w * h * 16
    vals = struct.unpack(f"<{w * h * 4}f", resp.content)
    return w, h, [vals[i:i + 4] for i in range(0, len(vals), 4)]


def exr_pixels(api, job_id):
    w, h, ch, _ = read_exr(api.get(f"/api/jobs/{job_id}/image.exr").content)
    return w, h, list(zip(ch["R"], ch["G"], ch["B"]))


def test_pixels_are_the_exr_and_counts_add_up(servers):
    srv = servers("pixels", threads=2)
    # Adaptive: pixels stop at different counts, so the counts are per pixel, not the budget.
    job = srv.api.submit(dict(TINY, spp=256, adaptive=True, adaptive_tolerance=0.1))
    done = srv.api.wait(job["id"], "done", timeout=60)
    w, h, px = pixels(srv.api, job["id"])
    ew, eh, exr = exr_pixels(srv.api, job["id"])
    assert (w, h) == (ew, eh) == (TINY["width"], TINY["height"])
    assert [p[:3] for p in px] == exr  # bit for bit: both are the film's float32 means
    counts = [p[3] for p in px]
    assert all(c == int(c) and 1 <= c <= 256 for c in counts)
    assert sum(counts) == done["samples"]
    assert min(counts) < max(counts), "adaptive sampling stopped no pixel early"
    # After a restart the image is no longer in memory: the files answer, with the same bytes.
    before = srv.api.get(f"/api/jobs/{job['id']}/pixels").content
    srv.kill()
    srv = servers("pixels", threads=2)
    assert srv.api.get(f"/api/jobs/{job['id']}/pixels").content == before
    # Without its counts file the answer is a 404 saying so, never made-up counts.
    (srv.data / "jobs" / job["id"] / "samples.bin").unlink()
    srv.kill()
    srv = servers("pixels", threads=2)
    err = srv.api.error(srv.api.get(f"/api/jobs/{job['id']}/pixels", expect=None), 404)
    assert "sample counts" in err["message"]


def test_pixels_of_a_running_job_and_the_404s(servers):
    srv = servers("live", threads=1)
    api = srv.api
    api.error(api.get("/api/jobs/00ff/pixels", expect=None), 404)
    running = api.submit(ENDLESS)
    queued = api.submit(TINY)  # behind the endless one: no image yet
    assert api.job(queued["id"])["state"] == "queued"
    err = api.error(api.get(f"/api/jobs/{queued['id']}/pixels", expect=None), 404)
    assert "no image yet" in err["message"]
    n = ENDLESS["width"] * ENDLESS["height"]
    api.wait(running["id"], "running", samples=n, timeout=30)  # a first pass over every pixel
    w, h, px = pixels(api, running["id"])
    assert (w, h) == (ENDLESS["width"], ENDLESS["height"])
    assert all(p[3] >= 1 for p in px) and sum(p[3] for p in px) >= n
    api.delete(f"/api/jobs/{running['id']}", expect=200)
