"""Cancelling and deleting: a running job stops long before its sample budget and its event stream
ends, and the answer says cancelled; a queued job is cancelled at once and never runs; DELETE on a
finished job deletes it and its files. Waits
are on states and events; their timeouts (10 s: ten times the poll interval of the job queue and
a pass's tiles) only stop a broken server from hanging the test."""
import time

from images import decode_png
from support import ENDLESS, TINY, health_counts


def test_cancel_stops_a_running_job(server):
    api = server.api
    job = api.submit(ENDLESS)  # 65536 spp: hours of work
    api.wait(job["id"], "running", samples=1)
    stream = server.events(job["id"])
    assert stream.next().kind in ("image", "status")

    answer = api.delete(f"/api/jobs/{job['id']}", expect=200).json()
    assert answer["state"] == "cancelled" and answer["eta"] is None  # the state after the request
    done = api.job(job["id"])
    # Stopped mid-render: a tiny share of the budget done, not the render run out.
    assert done["finished_at"] is not None and done["progress"] < 0.5, done

    # The stream ends with the cancelled state.
    events = stream.until_end()
    assert events[-1].data == {"state": "cancelled"}
    assert [e for e in events if e.kind == "status"][-1].data["state"] == "cancelled"

    # Nothing keeps rendering: the sample count stays put.
    samples = api.job(job["id"])["samples"]
    time.sleep(0.2)
    assert api.job(job["id"])["samples"] == samples
    assert health_counts(api.get("/api/health").json()) == {"status": "ok", "queued": 0, "running": 0, "paused": 0, "rendering": "embedded"}

    # What it had rendered can be downloaded, as from its viewer.
    _, _, pixels = decode_png(api.get(f"/api/jobs/{job['id']}/image.png").content)
    assert any(pixels), "the cancelled job's image is black"
    assert (server.data / "jobs" / job["id"] / "image.exr").is_file()

    # Deleting it now deletes it.
    assert api.delete(f"/api/jobs/{job['id']}", expect=200).json() == {"id": job["id"], "state": "deleted"}
    api.error(api.get(f"/api/jobs/{job['id']}", expect=None), 404)


def test_cancel_queued_job(server):
    api = server.api
    running = api.submit(ENDLESS)
    api.wait(running["id"], "running")
    queued = api.submit(TINY)
    assert queued["state"] == "queued"
    stream = server.events(queued["id"])
    assert stream.next().data["state"] == "queued"

    answer = api.delete(f"/api/jobs/{queued['id']}", expect=200).json()
    assert answer["state"] == "cancelled" and answer["started_at"] is None
    assert stream.until_end()[-1].data == {"state": "cancelled"}
    assert api.get("/api/health").json()["queued"] == 0

    # Freeing the worker does not start the cancelled job.
    api.delete(f"/api/jobs/{running['id']}", expect=200)
    api.wait(running["id"], "cancelled", timeout=10)
    after = api.submit(TINY)
    api.wait(after["id"], "done", timeout=20)
    again = api.job(queued["id"])
    assert again["state"] == "cancelled" and again["samples"] == 0 and again["started_at"] is None
    api.error(api.get(f"/api/jobs/{queued['id']}/image.png", expect=None), 404)


def test_delete_finished_or_unknown_job(server):
    api = server.api
    job = api.submit(TINY)
    api.wait(job["id"], "done", timeout=20)
    folder = server.data / "jobs" / job["id"]
    assert (folder / "image.png").is_file()
    assert api.delete(f"/api/jobs/{job['id']}", expect=200).json() == {"id": job["id"], "state": "deleted"}
    assert not folder.exists(), "its files stayed"
    api.error(api.get(f"/api/jobs/{job['id']}", expect=None), 404)
    api.error(api.get(f"/api/jobs/{job['id']}/image.png", expect=None), 404)
    assert job["id"] not in [j["id"] for j in api.get("/api/jobs").json()["jobs"]]
    api.error(api.delete(f"/api/jobs/{job['id']}"), 404)  # gone
    api.error(api.delete("/api/jobs/0123456789abcdef"), 404)
    api.error(api.delete("/api/jobs/not-a-job"), 404)
