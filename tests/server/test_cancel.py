"""Cancelling: a running job stops long before its sample budget and its event stream ends; a
queued job is cancelled at once and never runs; a finished job cannot be cancelled (409). Waits
are on states and events; their timeouts (10 s: ten times the poll interval of the job queue and
a pass's tiles) only stop a broken server from hanging the test."""
import time

from support import ENDLESS, TINY, health_counts


def test_cancel_stops_a_running_job(server):
    api = server.api
    job = api.submit(ENDLESS)  # 65536 spp: hours of work
    api.wait(job["id"], "running", samples=1)
    stream = server.events(job["id"])
    assert stream.next().kind in ("image", "status")

    answer = api.delete(f"/api/jobs/{job['id']}", expect=200).json()
    assert answer["state"] in ("running", "cancelled")  # told to stop; the worker marks it
    done = api.wait(job["id"], "cancelled", timeout=10, poll=0.01)
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
    assert health_counts(api.get("/api/health").json()) == {"status": "ok", "queued": 0, "running": 0, "rendering": "embedded"}

    # Cancelling again is a conflict.
    err = api.error(api.delete(f"/api/jobs/{job['id']}"), 409)
    assert "cancelled" in err["message"]


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
    err = api.error(api.delete(f"/api/jobs/{job['id']}"), 409)
    assert "done" in err["message"]
    assert api.job(job["id"])["state"] == "done"  # unchanged
    api.error(api.delete("/api/jobs/0123456789abcdef"), 404)
    api.error(api.delete("/api/jobs/not-a-job"), 404)
