"""Long renders that survive: a job killed mid-render (kill -9) continues from its checkpoint to the
uninterrupted job's image, bit for bit; a paused job keeps its film and gives its threads to the
next job, and resumed ends on the same image; continue takes a finished job to a larger budget
without rendering again what it has. Images are compared as EXR floats (every bit), never PNGs.
Waits are on states and files; their timeouts only stop a broken server from hanging the test."""
import json
import signal

from images import read_exr
from support import ENDLESS, TINY

# Adaptive sampling on (the default), so its stops are part of what must come out the same.
SPEC = {"scene": "cornell", "width": 64, "height": 48, "spp": 2048, "max_depth": 4, "seed": 5,
        "adaptive_tolerance": 0.02}


def pixels(api, job_id):
    _, _, channels, _ = read_exr(api.get(f"/api/jobs/{job_id}/image.exr").content)
    return channels


def on_disk(srv, job_id):
    return json.loads((srv.data / "jobs" / job_id / "job.json").read_text())


def test_kill_9_mid_job_resumes_from_its_checkpoint_to_the_same_image(servers):
    args = ["--checkpoint-interval", "0"]  # a checkpoint after every pass
    srv = servers("node", threads=2, args=args)
    api = srv.api
    reference = api.submit(SPEC)
    api.wait(reference["id"], "done", timeout=120)
    spec = SPEC
    for _ in range(5):
        job = api.submit(spec)
        # Frozen (SIGSTOP) once a checkpoint holds samples; still running on disk, then killed.
        while True:
            doc = on_disk(srv, job["id"])
            if doc["state"] == "done" or doc["checkpoint"]["samples"] > 0:
                break
        srv.proc.send_signal(signal.SIGSTOP)
        doc = on_disk(srv, job["id"])
        if doc["state"] == "running":
            break
        srv.proc.send_signal(signal.SIGCONT)
        spec = dict(spec, spp=spec["spp"] * 2)  # finished before the freeze: a longer one
        reference = api.submit(spec)
        api.wait(reference["id"], "done", timeout=240)
    else:
        raise AssertionError("no job was mid-render when the server was frozen")
    kept = doc["checkpoint"]["samples"]
    assert 0 < kept < 64 * 48 * spec["spp"]
    srv.kill()

    srv2 = servers("node", threads=2, args=args)
    api = srv2.api
    first = api.job(job["id"])
    assert first["state"] in ("queued", "running")
    assert first["samples"] >= kept, "spp_done started again from 0"
    done = api.wait(job["id"], "done", timeout=240)
    assert "resuming from its checkpoint" in srv2.log_text()
    assert done["samples"] > kept
    assert pixels(api, job["id"]) == pixels(api, reference["id"]), "the resumed image differs"


def test_pause_keeps_the_film_frees_the_worker_and_resume_ends_on_the_same_image(servers):
    srv = servers("pause", threads=2)
    api = srv.api
    spec = dict(SPEC, spp=1024, adaptive=False)  # 3M samples: it cannot finish before the pause lands
    reference = api.submit(spec)
    api.wait(reference["id"], "done", timeout=240)
    job = api.submit(spec)
    api.wait(job["id"], "running", samples=1)
    paused = api.post(f"/api/jobs/{job['id']}/pause", expect=200).json()
    assert paused["state"] == "paused" and paused["eta"] is None, paused
    assert (srv.data / "jobs" / job["id"] / "checkpoint.bin").is_file()
    # Its threads go to the next job, which finishes while it waits.
    other = api.submit(TINY)
    api.wait(other["id"], "done", timeout=60)
    samples = api.job(job["id"])["samples"]
    assert api.job(job["id"])["state"] == "paused" and samples == paused["samples"]
    api.post(f"/api/jobs/{job['id']}/pause", expect=200)  # pausing a paused job changes nothing
    api.error(api.post(f"/api/jobs/{other['id']}/resume"), 409)
    api.error(api.post(f"/api/jobs/{other['id']}/pause"), 409)
    resumed = api.post(f"/api/jobs/{job['id']}/resume", expect=200).json()
    assert resumed["state"] in ("queued", "running")
    done = api.wait(job["id"], "done", timeout=240)
    assert done["samples"] > samples
    assert pixels(api, job["id"]) == pixels(api, reference["id"]), "the resumed image differs"


def test_a_queued_job_paused_leaves_the_queue(server):
    api = server.api
    blocker = api.submit(ENDLESS)
    api.wait(blocker["id"], "running")
    queued = api.submit(TINY)
    assert api.post(f"/api/jobs/{queued['id']}/pause", expect=200).json()["state"] == "paused"
    assert api.get("/api/health").json()["paused"] == 1
    api.delete(f"/api/jobs/{blocker['id']}", expect=200)
    assert api.job(queued["id"])["state"] == "paused"  # the free worker does not take it
    api.post(f"/api/jobs/{queued['id']}/resume", expect=200)
    assert api.wait(queued["id"], "done", timeout=30)["samples"] > 0
    # A paused job is cancelled at once.
    again = api.submit(ENDLESS)
    api.wait(again["id"], "running", samples=1)
    api.post(f"/api/jobs/{again['id']}/pause", expect=200)
    assert api.delete(f"/api/jobs/{again['id']}", expect=200).json()["state"] == "cancelled"


def test_continue_takes_a_finished_job_to_the_larger_budgets_image(server):
    api = server.api
    small = dict(SPEC, spp=16, adaptive_batch=4, adaptive_tolerance=0.2)
    job = api.submit(small)
    first = api.wait(job["id"], "done", timeout=60)
    assert first["can_continue"] and first["stopped"] == "finished"
    before = pixels(api, job["id"])
    reference = api.submit(dict(small, spp=64))
    api.wait(reference["id"], "done", timeout=60)

    answer = api.post(f"/api/jobs/{job['id']}/continue", {"spp": 64}, expect=200).json()
    assert answer["state"] in ("queued", "running") and answer["spec"]["spp"] == 64
    done = api.wait(job["id"], "done", timeout=60)
    assert done["samples"] > first["samples"] and done["created_at"] == first["created_at"]
    after = pixels(api, job["id"])
    assert after != before
    assert after == pixels(api, reference["id"]), "the continued image differs from the 64 spp render"

    # What cannot continue, and why.
    assert "spent" in api.error(api.post(f"/api/jobs/{job['id']}/continue", {}), 400, "spp")["message"]
    assert "shrink" in api.error(api.post(f"/api/jobs/{job['id']}/continue", {"spp": 8}), 400, "spp")["message"]
    api.error(api.post(f"/api/jobs/{job['id']}/continue", {"max_depth": 9}), 400, "max_depth")
    api.error(api.post(f"/api/jobs/{job['id']}/continue", {"spp": "many"}), 400, "spp")
    live = api.submit(ENDLESS)
    api.wait(live["id"], "running")
    api.error(api.post(f"/api/jobs/{live['id']}/continue", {"spp": 70000}), 409)
    api.error(api.post("/api/jobs/0123456789abcdef/continue", {}), 404)

    # A cancelled job continues where it stopped, here for half a second more.
    cancelled = api.delete(f"/api/jobs/{live['id']}", expect=200).json()
    assert cancelled["state"] == "cancelled" and cancelled["can_continue"]
    api.post(f"/api/jobs/{live['id']}/continue", {"time_limit": 0.5}, expect=200)
    timed = api.wait(live["id"], "done", timeout=60)
    assert timed["stopped"] == "time limit reached" and timed["samples"] > cancelled["samples"]
    assert timed["spec"]["time_limit"] > 0.5  # counted from the time it had rendered
    # A spent budget given only a limit may take up to the server's largest spp; the limit decides.
    more = api.post(f"/api/jobs/{job['id']}/continue", {"target_error": 1e-9, "time_limit": 0.5}, expect=200).json()
    assert more["spec"]["spp"] == 65536  # the server's largest (render-server's SpecLimits)
    assert api.wait(job["id"], "done", timeout=60)["samples"] > done["samples"]
