"""Late and reconnecting watchers start from the whole current picture: the first event is an
image of the full size (also with Last-Event-ID, and for a finished job), and painting the
stream from there ends at the final image. The job being still running when the late watcher
connects is checked from its status event, not assumed from a clock."""
import base64

from images import Canvas, decode_png
from support import TINY

# Long enough to connect in the middle, bounded by its time limit (it then finishes as done).
LONG = {"scene": "cornell", "width": 96, "height": 72, "spp": 65536, "adaptive": False, "max_depth": 3,
        "tile_size": 32, "time_limit": 2.0, "seed": 4}


def paint(canvas, events):
    for ev in events:
        if ev.kind == "image":
            canvas.paint_image(ev.data)
        elif ev.kind == "tile":
            canvas.paint_tile(ev.data)


def late_watcher_of_a_running_job(server, spec, tries=5):
    """Submits `spec` and connects once it has a picture; returns (job, stream, first two events)
    with the job still running then. A job that reached its time limit first (the test process
    starved that long) is followed by one with twice the limit: states decide, not a clock."""
    for _ in range(tries):
        job = server.api.submit(spec)
        server.api.wait(job["id"], ("running", "done"), samples=96 * 72 * 2)  # past the first passes
        late = server.events(job["id"])
        first, second = late.next(), late.next()
        if second.kind == "status" and second.data["state"] == "running":
            return job, late, first, second
        late.close()
        server.api.wait(job["id"], "done", timeout=60)
        spec = dict(spec, time_limit=2 * spec["time_limit"])
    raise AssertionError(f"no job was still running when its late watcher connected, {tries} tries")


def test_late_connect_and_reconnect_with_last_event_id(server):
    api = server.api
    # A late watcher: the first event is the full current image, then status.
    job, late, first, second = late_watcher_of_a_running_job(server, LONG)
    assert first.kind == "image" and (first.data["width"], first.data["height"]) == (96, 72)
    assert decode_png(base64.b64decode(first.data["png"]))[:2] == (96, 72)
    assert second.kind == "status" and second.data["state"] == "running" and second.id == first.id
    last_id = second.id
    for ev in late:  # read on to a tile, then drop the connection
        last_id = ev.id
        if ev.kind == "tile":
            break
    late.close()

    # Reconnecting with Last-Event-ID: again the full picture first, at least as new as before.
    again = server.events(job["id"], last_event_id=last_id)
    events = again.until_end()
    assert events[0].kind == "image" and events[0].id >= last_id
    assert (events[0].data["width"], events[0].data["height"]) == (96, 72)
    assert events[1].kind == "status"
    assert events[-1].data == {"state": "done"}
    canvas = Canvas(96, 72, 32)
    paint(canvas, events)
    final_png = api.get(f"/api/jobs/{job['id']}/image.png").content
    assert bytes(canvas.pixels) == decode_png(final_png)[2]

    # After the end: the image, the final status, the end; nothing else.
    done = server.events(job["id"], last_event_id=events[-1].id).until_end()
    assert [e.kind for e in done] == ["image", "status", "end"]
    assert done[1].data["state"] == "done" and done[2].data == {"state": "done"}
    canvas = Canvas(96, 72, 32)
    paint(canvas, done)
    assert bytes(canvas.pixels) == decode_png(final_png)[2]


def test_events_of_a_queued_then_tiny_job(server):
    api = server.api
    job = api.submit(TINY)
    api.wait(job["id"], "done", timeout=20)
    events = server.events(job["id"]).until_end()
    assert events[0].kind == "image"
    assert all(e.id == events[0].id for e in events)
    api.error(api.get("/api/jobs/0123456789abcdef/events", expect=None), 404)
