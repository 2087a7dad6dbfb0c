"""Scene upload (PUT /api/scenes/{name}): a scene is loaded before it is stored and then renders
like a bundled one, here and through the Redis backend's workers; a file that does not load is
refused with the loader's message and never listed; bundled scenes are read-only; the upload's
own size limit, media types and cross-site refusal hold."""
import pytest

from support import CORNELL, TINY
from test_scale_out import Redis, Worker, wait_for

COLLADA = {"Content-Type": "model/vnd.collada+xml"}


def upload(api, name, data, expect=None, headers=COLLADA):
    return api.request("PUT", f"/api/scenes/{name}", expect, data=data, headers=headers)


def listed(api):
    return {s["name"]: s for s in api.get("/api/scenes").json()["scenes"]}


def test_an_uploaded_scene_renders_and_can_be_replaced_and_deleted(server):
    api = server.api
    created = upload(api, "mine", CORNELL.read_bytes(), expect=201).json()
    assert created["name"] == "mine" and created["source"] == "uploaded" and created["summary"]["triangles"] > 0
    assert (server.data / "scenes" / "mine.dae").read_bytes() == CORNELL.read_bytes()
    scenes = listed(api)
    assert scenes["mine"]["source"] == "uploaded" and scenes["cornell"]["source"] == "bundled"
    assert api.get("/api/scenes/mine").json() == scenes["mine"]
    job = api.submit(dict(TINY, scene="mine"))
    assert api.wait(job["id"], ("done", "failed"), timeout=30)["state"] == "done"
    assert upload(api, "mine", CORNELL.read_bytes(), expect=200).json()["source"] == "uploaded"  # replaced

    busy = api.submit(dict(TINY, scene="mine", spp=65536, adaptive=False))
    api.wait(busy["id"], "running")
    api.error(api.request("DELETE", "/api/scenes/mine"), 409, "name")  # a live job renders it
    api.delete(f"/api/jobs/{busy['id']}", expect=200)
    assert api.request("DELETE", "/api/scenes/mine", 200).json() == {"name": "mine", "state": "deleted"}
    assert "mine" not in listed(api) and not list((server.data / "scenes").iterdir())
    api.error(api.post("/api/jobs", dict(TINY, scene="mine")), 404, "scene")
    api.error(api.request("DELETE", "/api/scenes/mine"), 404, "name")
    api.error(api.get("/api/scenes/mine", expect=None), 404, "name")


def test_a_scene_that_does_not_load_is_refused_with_the_loaders_message(server):
    api = server.api
    broken = CORNELL.read_bytes().replace(b"</COLLADA>", b"")
    err = api.error(upload(api, "broken", broken), 422, "body")
    assert err["message"].startswith("broken.dae")
    assert "broken" not in listed(api) and not list((server.data / "scenes").iterdir())
    api.error(upload(api, "cornell", CORNELL.read_bytes()), 403, "name")  # bundled: read-only
    api.error(api.request("DELETE", "/api/scenes/cornell"), 403, "name")
    api.error(upload(api, "-dash", CORNELL.read_bytes()), 400, "name")


@pytest.mark.parametrize("headers,status", [
    ({"Content-Type": "text/plain"}, 415),  # what a page of another site may send without asking
    ({"Content-Type": "application/x-www-form-urlencoded"}, 415),
    ({}, 415),
    (dict(COLLADA, Origin="https://evil.example"), 403),
    (dict(COLLADA, **{"Sec-Fetch-Site": "cross-site"}), 403),
])
def test_media_types_and_cross_site_uploads_are_refused(server, headers, status):
    api = server.api
    api.error(upload(api, "mine", CORNELL.read_bytes(), headers=headers), status)
    assert "mine" not in listed(api)


def test_an_upload_over_max_scene_mb_is_refused_before_it_is_read(servers):
    srv = servers(args=["--max-scene-mb", "1"])
    big = CORNELL.read_bytes() + b"<!--" + b"x" * (1 << 20) + b"-->"
    err = srv.api.error(upload(srv.api, "big", big), 413)
    assert "1 MiB" in err["message"]
    # Under the limit and over the 64 KiB of other bodies: taken.
    padded = CORNELL.read_bytes() + b"<!--" + b"x" * (200 << 10) + b"-->"
    upload(srv.api, "padded", padded, expect=201)
    srv.api.error(srv.api.post("/api/jobs", {"scene": "cornell", "pad": "x" * (100 << 10)}), 413)


def test_an_uploaded_scene_renders_through_the_redis_workers(tmp_path, servers):
    redis = Redis(tmp_path)
    worker = Worker(tmp_path, redis.url, "w1")
    try:
        srv = servers("scaled", args=["--queue", redis.url])
        wait_for(lambda: srv.api.get("/api/health").json()["workers"] == 1, "the worker announced itself")
        upload(srv.api, "mine", CORNELL.read_bytes(), expect=201)
        job = srv.api.submit(dict(TINY, scene="mine"))
        done = srv.api.wait(job["id"], ("done", "failed"), timeout=60)
        assert done["state"] == "done" and done["samples"] == 64 * 48 * 4, done
    finally:
        worker.stop()
        redis.stop()
