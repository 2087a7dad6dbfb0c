"""Persistence: after kill -9 a new server on the same data directory runs the interrupted job
again to done and keeps finished jobs (state, images byte for byte, idempotency keys); SIGTERM
stops cleanly (exit 0), ends event streams and puts the running job back in the queue. No test
reads a clock: the server is frozen (SIGSTOP) to check a job is mid-render before the kill, and
waits are on states; their timeouts only stop a broken server from hanging the test."""
import base64
import json
import signal

from images import decode_png
from support import ENDLESS, TINY

# Mid-render when killed, finishes by its time limit once restarted.
LONG = {"scene": "cornell", "width": 96, "height": 72, "spp": 65536, "adaptive": False, "max_depth": 3,
        "time_limit": 1.5, "seed": 8}


def freeze_mid_render(srv, spec, tries=5):
    """Submits `spec` and freezes the server (SIGSTOP) while the job renders, as its job.json on disk
    says. A job that reached its time limit before the freeze (a test process starved for that long)
    is followed by one with twice the limit. Returns (job, its job.json, the spec that ran)."""
    for _ in range(tries):
        job = srv.api.submit(spec)
        srv.api.wait(job["id"], "running", samples=1)
        srv.proc.send_signal(signal.SIGSTOP)
        on_disk = json.loads((srv.data / "jobs" / job["id"] / "job.json").read_text())
        if on_disk["state"] == "running":
            return job, on_disk, spec
        srv.proc.send_signal(signal.SIGCONT)
        srv.api.wait(job["id"], "done", timeout=60)
        spec = dict(spec, time_limit=2 * spec["time_limit"])
    raise AssertionError(f"no job was still running when the server was frozen, {tries} tries")


def test_kill_9_then_restart_recovers(servers):
    srv = servers("node")
    api = srv.api
    a = api.submit(dict(TINY, seed=21), key="job-a")
    a_done = api.wait(a["id"], "done", timeout=20)
    a_png = api.get(f"/api/jobs/{a['id']}/image.png").content
    a_exr = api.get(f"/api/jobs/{a['id']}/image.exr").content
    assert (srv.data / "jobs" / a["id"] / "image.png").read_bytes() == a_png
    b, on_disk, _ = freeze_mid_render(srv, LONG)
    srv.kill()  # SIGKILL in the middle of B
    assert json.loads((srv.data / "jobs" / b["id"] / "job.json").read_text()) == on_disk

    srv2 = servers("node")  # same data directory, new process, new port
    api = srv2.api
    jobs = {j["id"]: j for j in api.get("/api/jobs").json()["jobs"]}
    assert list(jobs)[0] == b["id"] and list(jobs)[-1] == a["id"]  # newest first
    assert jobs[a["id"]]["state"] == "done"
    assert jobs[b["id"]]["state"] in ("queued", "running")
    b_done = api.wait(b["id"], "done", timeout=60)
    assert b_done["samples"] > 0 and b_done["started_at"] > on_disk["started_at"]
    w, h, _ = decode_png(api.get(f"/api/jobs/{b['id']}/image.png").content)
    assert (w, h) == (96, 72)

    # A is untouched: status, images byte for byte, its idempotency key.
    a_now = api.job(a["id"])
    for field in ("state", "samples", "rays", "created_at", "started_at", "finished_at", "spec", "features"):
        assert a_now[field] == a_done[field], field
    assert api.get(f"/api/jobs/{a['id']}/image.png").content == a_png
    assert api.get(f"/api/jobs/{a['id']}/image.exr").content == a_exr
    again = api.post("/api/jobs", dict(TINY, seed=21), expect=200, headers={"Idempotency-Key": "job-a"})
    assert again.json()["id"] == a["id"]
    # Its event stream still starts with its picture (read back from disk).
    events = srv2.events(a["id"]).until_end()
    assert [e.kind for e in events] == ["image", "status", "end"]
    assert base64.b64decode(events[0].data["png"]) == a_png
    assert api.delete(f"/api/jobs/{a['id']}", expect=200).json() == {"id": a["id"], "state": "deleted"}
    assert not (srv2.data / "jobs" / a["id"]).exists()


def test_sigterm_stops_cleanly_and_requeues(servers):
    srv = servers("node")
    api = srv.api
    job = api.submit(ENDLESS)
    api.wait(job["id"], "running", samples=1)
    stream = srv.events(job["id"])
    assert stream.next() is not None

    # Open keep-alive and event-stream connections do not hold it up (a generous 30 s to exit).
    assert srv.terminate(timeout=30) == 0
    assert "SIGTERM, stopping" in srv.log_text()
    # The watcher's stream closed without an end event: the job did not end.
    assert all(ev.kind != "end" for ev in stream)
    assert stream.ended
    on_disk = json.loads((srv.data / "jobs" / job["id"] / "job.json").read_text())
    assert on_disk["state"] == "queued"

    srv2 = servers("node")
    api = srv2.api
    assert api.job(job["id"])["state"] in ("queued", "running")
    api.wait(job["id"], "running", samples=1, timeout=20)
    api.delete(f"/api/jobs/{job['id']}", expect=200)
    api.wait(job["id"], "cancelled", timeout=10)
    assert srv2.terminate(timeout=30) == 0
    assert json.loads((srv.data / "jobs" / job["id"] / "job.json").read_text())["state"] == "cancelled"
