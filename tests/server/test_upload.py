"""Scene upload (PUT /api/scenes/{name}): a scene is loaded before it is stored and then renders
like a bundled one, here and through the Redis backend's workers; a file that does not load is
refused with the loader's message and never listed; bundled scenes are read-only; the upload's
own size limit, media types and cross-site refusal hold."""
import pytest

from support import CORNELL, SOURCE_DIR, TINY
from test_scale_out import Redis, Worker, wait_for

COLLADA = {"Content-Type": "model/vnd.collada+xml"}
GLB = {"Content-Type": "model/gltf-binary"}
GLTF = {"Content-Type": "model/gltf+json"}
CORNELL_GLB = SOURCE_DIR / "scenes/cornell_gltf.glb"
SHOWCASE = SOURCE_DIR / "scenes/showcase.gltf"


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
    api.error(upload(api, "mine", CORNELL.read_bytes()), 409, "name")  # nor is it replaced under the job
    api.delete(f"/api/jobs/{busy['id']}", expect=200)
    assert api.request("DELETE", "/api/scenes/mine", 200).json() == {"name": "mine", "state": "deleted"}
    assert "mine" not in listed(api) and not list((server.data / "scenes").iterdir())
    api.error(api.post("/api/jobs", dict(TINY, scene="mine")), 404, "scene")
    api.error(api.request("DELETE", "/api/scenes/mine"), 404, "name")
    api.error(api.get("/api/scenes/mine", expect=None), 404, "name")


def test_a_finished_job_continues_only_over_the_scene_it_was_rendered_from(server):
    api = server.api
    upload(api, "mine", CORNELL.read_bytes(), expect=201)
    job = api.submit(dict(TINY, scene="mine"))
    assert api.wait(job["id"], ("done", "failed"), timeout=30)["state"] == "done"
    upload(api, "mine", CORNELL.read_bytes() + b"<!-- another version -->", expect=200)
    err = api.error(api.post(f"/api/jobs/{job['id']}/continue", {"spp": 8}), 409, "scene")
    assert "changed" in err["message"], err
    upload(api, "mine", CORNELL.read_bytes(), expect=200)  # the same content again: it goes on
    api.post(f"/api/jobs/{job['id']}/continue", {"spp": 8}, expect=200)
    assert api.wait(job["id"], ("done", "failed"), timeout=30)["spec"]["spp"] == 8


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


def test_gltf_and_glb_uploads_load_render_and_are_stored_by_their_content(server):
    api = server.api
    glb = upload(api, "box", CORNELL_GLB.read_bytes(), expect=201, headers=GLB).json()
    assert glb["summary"]["triangles"] > 0 and "pbr" in glb["summary"]["materials"], glb
    assert (server.data / "scenes" / "box.glb").read_bytes() == CORNELL_GLB.read_bytes()
    # A glTF with its buffers and images as data: URIs, sent as octet-stream: the content decides.
    shown = upload(api, "show", SHOWCASE.read_bytes(), expect=201,
                   headers={"Content-Type": "application/octet-stream"}).json()
    assert shown["summary"]["has_camera"] and "glass" in shown["summary"]["materials"], shown
    assert (server.data / "scenes" / "show.gltf").exists()
    for name in ("box", "show"):
        job = api.submit(dict(TINY, scene=name))
        done = api.wait(job["id"], ("done", "failed"), timeout=60)
        assert done["state"] == "done", done
    # The same name as COLLADA replaces the GLB: a name is one scene.
    upload(api, "box", CORNELL.read_bytes(), expect=200)
    assert sorted(p.name for p in (server.data / "scenes").iterdir()) == ["box.dae", "show.gltf"]


def test_broken_and_external_gltf_uploads_are_refused_at_their_json_path(server):
    api = server.api
    err = api.error(upload(api, "cut", CORNELL_GLB.read_bytes()[:5000], headers=GLB), 422, "body")
    assert err["message"].startswith("cut.glb"), err
    # Workers receive one file's bytes: a buffer in a file beside the scene cannot reach them.
    external = b'{"asset": {"version": "2.0"}, "buffers": [{"uri": "mesh.bin", "byteLength": 36}]}'
    err = api.error(upload(api, "ext", external, headers=GLTF), 422, "body")
    assert err["message"].startswith("ext.gltf") and "/buffers/0" in err["message"], err
    err = api.error(upload(api, "json", b'{"asset": {"version": "2.0"', headers=GLTF), 422, "body")
    assert err["message"].startswith("json.gltf"), err
    assert not list((server.data / "scenes").iterdir())


@pytest.mark.parametrize("scene,headers", [(CORNELL, COLLADA), (CORNELL_GLB, GLB)], ids=["dae", "glb"])
def test_an_uploaded_scene_renders_through_the_redis_workers(tmp_path, servers, scene, headers):
    redis = Redis(tmp_path)
    worker = Worker(tmp_path, redis.url, "w1")
    try:
        srv = servers("scaled", args=["--queue", redis.url])
        wait_for(lambda: srv.api.get("/api/health").json()["workers"] == 1, "the worker announced itself")
        upload(srv.api, "mine", scene.read_bytes(), expect=201, headers=headers)
        job = srv.api.submit(dict(TINY, scene="mine"))
        done = srv.api.wait(job["id"], ("done", "failed"), timeout=60)
        assert done["state"] == "done" and done["samples"] == 64 * 48 * 4, done
    finally:
        worker.stop()
        redis.stop()
