"""Hostile and malformed requests: each gets its exact 4xx status and the JSON error shape naming
the offending field where there is one; afterwards the server is healthy and still renders."""
import json
import os
import time

import pytest

from support import CORNELL, TINY, Server, raw_request

INT_FIELDS = ["max_depth", "spp", "light_samples", "width", "height", "seed", "adaptive_batch", "tile_size"]
NUM_FIELDS = ["aperture", "focal_distance", "adaptive_tolerance", "time_limit", "target_error"]
BOOL_FIELDS = ["adaptive", "hemisphere", "file_camera", "keep_fov"]


@pytest.fixture(scope="module")
def srv(tmp_path_factory, contract):
    root = tmp_path_factory.mktemp("hostile")
    scenes = root / "scenes"
    scenes.mkdir()
    (scenes / "cornell.dae").write_bytes(CORNELL.read_bytes())
    (scenes / "broken.dae").write_text("<COLLADA><library_geometries><geometry")
    outside = root / "outside"
    outside.mkdir()
    (outside / "secret.dae").write_bytes(CORNELL.read_bytes())
    os.symlink(outside / "secret.dae", scenes / "escape.dae")  # points out of the scenes folder
    server = Server(root, contract, scenes=scenes).start()
    server.done_job = server.api.submit(TINY)
    server.api.wait(server.done_job["id"], "done", timeout=20)
    yield server
    server.kill()
    print(server.log_text()[-4000:])


def spec(**fields):
    return dict({"scene": "cornell", "width": 32, "height": 24, "spp": 2}, **fields)


# (name, body: bytes sent as is or an object sent as JSON, status, field)
BODIES = [
    ("truncated JSON", b'{"scene": "cornell",', 400, None),
    ("trailing garbage", b'{"scene": "cornell"} x', 400, None),
    ("empty body", b"", 400, None),
    ("array", b"[]", 400, None),
    ("string", b'"cornell"', 400, None),
    ("null", b"null", 400, None),
    ("number", b"42", 400, None),
    ("NaN literal", b'{"scene": "cornell", "aperture": NaN}', 400, None),
    ("Infinity literal", b'{"scene": "cornell", "focal_distance": Infinity}', 400, None),
    ("-Infinity literal", b'{"scene": "cornell", "time_limit": -Infinity}', 400, None),
    ("number overflow", b'{"scene": "cornell", "aperture": 1e400}', 400, None),
    ("integer overflow", b'{"scene": "cornell", "width": 1e400}', 400, None),
    ("invalid UTF-8", b'{"scene": "corn\xffell"}', 400, None),
    ("missing scene", {}, 400, "scene"),
    ("null scene", {"scene": None}, 400, "scene"),
    ("numeric scene", {"scene": 42}, 400, "scene"),
    ("list scene", {"scene": ["cornell"]}, 400, "scene"),
    ("object scene", {"scene": {"name": "cornell"}}, 400, "scene"),
]
# Wrong types, for every field.
BODIES += [(f"{f} as string", spec(**{f: "64"}), 400, f) for f in INT_FIELDS + NUM_FIELDS]
BODIES += [(f"{f} as number", spec(**{f: 1}), 400, f) for f in BOOL_FIELDS]
BODIES += [(f"{f} as list", spec(**{f: [1]}), 400, f) for f in INT_FIELDS + NUM_FIELDS + BOOL_FIELDS]
BODIES += [
    ("integer as float", spec(width=64.0), 400, "width"),
    ("fractional integer", spec(spp=2.5), 400, "spp"),
    ("integer as bool", spec(max_depth=True), 400, "max_depth"),
    ("number as bool", spec(aperture=False), 400, "aperture"),
    ("bool as string", spec(adaptive="true"), 400, "adaptive"),
    ("bool as null-ish string", spec(hemisphere="null"), 400, "hemisphere"),
]
# Negative and too-large numbers.
BODIES += [(f"{f}={v}", spec(**{f: v}), 400, f) for f, v in [
    ("width", -1), ("width", 0), ("height", 0), ("spp", 0), ("spp", -5), ("seed", -1), ("max_depth", -1),
    ("light_samples", 0), ("aperture", -0.001), ("focal_distance", -1), ("adaptive_batch", 0),
    ("adaptive_tolerance", -0.1), ("tile_size", 7), ("time_limit", -1), ("target_error", -0.5),
    ("width", 4097), ("height", 100000), ("spp", 65537), ("max_depth", 10001), ("light_samples", 65),
    ("seed", 2 ** 53 + 1), ("seed", 2 ** 64 - 1), ("seed", 2 ** 64), ("seed", -2 ** 63), ("adaptive_batch", 65537),
    ("tile_size", 257), ("aperture", 1000.5), ("focal_distance", 1e7), ("adaptive_tolerance", 1.01),
    ("time_limit", 604801), ("target_error", 1.5), ("width", 10 ** 30)]]
BODIES += [
    # width x height x spp over the cap of 2^32 pixel samples (4096 x 4096 x 256 is exactly the cap)
    ("absurd size", {"scene": "cornell", "width": 4096, "height": 4096, "spp": 257}, 400, "spp"),
    ("absurd size, max spp", {"scene": "cornell", "width": 4096, "height": 4096, "spp": 65536}, 400, "spp"),
    ("absurd size, defaults", {"scene": "cornell", "width": 4096, "height": 4096, "spp": 65536, "adaptive": True}, 400, "spp"),
    # unknown fields
    ("unknown field", spec(samples=4), 400, "samples"),
    ("threads are the server's", spec(threads=64), 400, "threads"),
    ("field names are case-sensitive", spec(Width=64), 400, "Width"),
    ("CLI flag as field", spec(**{"-s": 4}), 400, "-s"),
    # unknown scenes
    ("unknown scene", spec(scene="nosuch"), 404, "scene"),
    ("scene with extension", spec(scene="cornell.dae"), 404, "scene"),
    ("scene names are case-sensitive", spec(scene="CORNELL"), 404, "scene"),
    ("symlink out of the scene folder", spec(scene="escape"), 404, "scene"),
]
# Path tricks in the scene name.
BODIES += [(f"scene {name!r}", spec(scene=name), 400, "scene") for name in [
    "../cornell", "/etc/passwd", "a/b", "%2e%2e", "..", ".cornell", "cornell/", "cornell\\x", "cornell\0",
    "", "a" * 129, "a..b", "~root", " cornell", "c:\\cornell", "\u0107ornell", "..%2fcornell", "cornell?x=1"]]


@pytest.mark.parametrize("name,body,status,field", BODIES, ids=[b[0] for b in BODIES])
@pytest.mark.parametrize("endpoint", ["/api/jobs", "/api/jobs/check"])
def test_bad_job_body(srv, endpoint, name, body, status, field):
    data = body if isinstance(body, bytes) else json.dumps(body).encode()
    resp = srv.api.request("POST", endpoint, data=data, headers={"Content-Type": "application/json"})
    srv.api.error(resp, status, field)


def test_cap_boundary_is_accepted(srv):
    # Exactly 2^32 pixel samples is allowed (checked, not rendered).
    ok = srv.api.post("/api/jobs/check", {"scene": "cornell", "width": 4096, "height": 4096, "spp": 256}, expect=200)
    assert ok.json()["spec"]["spp"] == 256


@pytest.mark.parametrize("content_type", ["text/plain", "application/x-www-form-urlencoded", "application/xml",
                                          "text/json", "application/octet-stream"])
def test_wrong_content_type_is_415(srv, content_type):
    resp = srv.api.request("POST", "/api/jobs", data=json.dumps(TINY), headers={"Content-Type": content_type})
    srv.api.error(resp, 415)


def test_multipart_upload_is_415(srv):
    resp = srv.api.request("POST", "/api/jobs", files={"spec": ("spec.json", json.dumps(TINY), "application/json")})
    srv.api.error(resp, 415)
    # A body that is not the multipart its Content-Type announces is malformed: 400.
    resp = srv.api.request("POST", "/api/jobs", data=json.dumps(TINY),
                           headers={"Content-Type": "multipart/form-data; boundary=x"})
    srv.api.error(resp, 400)


def test_content_type_variants_that_are_json(srv):
    for ct in ("application/json; charset=utf-8", "Application/JSON"):
        srv.api.request("POST", "/api/jobs/check", 200, data=json.dumps(TINY), headers={"Content-Type": ct})
    srv.api.request("POST", "/api/jobs/check", 200, data=json.dumps(TINY))  # no Content-Type: read as JSON


@pytest.mark.parametrize("endpoint", ["/api/jobs", "/api/jobs/check"])
def test_oversized_body_is_413(srv, endpoint):
    body = json.dumps(dict(TINY, pad="x" * (65 * 1024))).encode()
    srv.api.error(srv.api.request("POST", endpoint, data=body, headers={"Content-Type": "application/json"}), 413)


def test_long_idempotency_key(srv):
    srv.api.error(srv.api.post("/api/jobs", TINY, headers={"Idempotency-Key": "k" * 201}), 400, "Idempotency-Key")


def check_raw_error(contract, status, headers, body, expected):
    assert status == expected, body[:300]
    assert headers.get("content-type", "").startswith("application/json")
    doc = json.loads(body)
    contract.validate_component(doc, "Error")
    assert doc["error"]["status"] == expected


def test_post_without_content_length_is_411_at_once(srv, contract):
    t0 = time.monotonic()
    status, headers, body = raw_request(srv.port, b"POST /api/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                                                  b"Content-Type: application/json\r\n\r\n")
    assert time.monotonic() - t0 < 2  # not after the 10 s read timeout
    check_raw_error(contract, status, headers, body, 411)


def test_garbage_request_line_is_400(srv, contract):
    status, headers, body = raw_request(srv.port, b"\x16\x03\x01 hello\r\n\r\n")
    check_raw_error(contract, status, headers, body, 400)


def test_overlong_uri_is_414(srv, contract):
    status, headers, body = raw_request(
        srv.port, b"GET /api/jobs/" + b"a" * 10000 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    check_raw_error(contract, status, headers, body, 414)


UNKNOWN = "0123456789abcdef"
NOT_FOUND = [
    ("GET", f"/api/jobs/{UNKNOWN}"), ("GET", "/api/jobs/NOT-HEX"), ("GET", "/api/jobs/%FF"),
    ("GET", "/api/jobs/" + "a" * 41), ("GET", "/api/jobs/%2e%2e"), ("DELETE", f"/api/jobs/{UNKNOWN}"),
    ("DELETE", "/api/jobs/%FF%FE"), ("GET", f"/api/jobs/{UNKNOWN}/image.png"), ("GET", f"/api/jobs/{UNKNOWN}/image.exr"),
    ("GET", f"/api/jobs/{UNKNOWN}/events"), ("GET", f"/api/jobs/{UNKNOWN}/focus?x=1&y=1"),
    ("GET", "/api/jobs/check"),  # a job id that is not one
    ("GET", "/api/nope"), ("GET", "/api/%FF"), ("GET", "/api/"), ("POST", "/api/nope"),
    ("GET", f"/api/jobs/{UNKNOWN}/image.gif"), ("GET", f"/api/jobs/{UNKNOWN}/nope"), ("GET", "/api/scenes/cornell"),
]


@pytest.mark.parametrize("method,path", NOT_FOUND, ids=[f"{m} {p[:40]}" for m, p in NOT_FOUND])
def test_not_found(srv, method, path):
    srv.api.error(srv.api.request(method, path, data=b"{}" if method == "POST" else None), 404)


WRONG_METHOD = [
    ("POST", "/api/health", "GET"), ("PUT", "/api/jobs", "GET, POST"), ("DELETE", "/api/jobs", "GET, POST"),
    ("PATCH", "/api/jobs/JOB", "GET, DELETE"), ("POST", "/api/jobs/JOB", "GET, DELETE"),
    ("POST", "/api/jobs/JOB/image.png", "GET"), ("DELETE", "/api/jobs/JOB/events", "GET"),
    ("PUT", "/api/scenes", "GET"), ("DELETE", "/api/openapi.json", "GET"), ("PUT", "/api/jobs/check", "POST"),
    ("OPTIONS", "/api/jobs", "GET, POST"),
]


@pytest.mark.parametrize("method,path,allow", WRONG_METHOD, ids=[f"{m} {p}" for m, p, _ in WRONG_METHOD])
def test_wrong_method_is_405(srv, method, path, allow):
    path = path.replace("JOB", srv.done_job["id"])
    # httplib reads no body of an OPTIONS request (it would be taken for the next request): none here.
    resp = srv.api.request(method, path, data=None if method == "OPTIONS" else b"{}")
    srv.api.error(resp, 405)
    assert resp.headers["Allow"] == allow


FOCUS = [
    ("", "x"), ("?y=1", "x"), ("?x=1", "y"), ("?x=abc&y=1", "x"), ("?x=1&y=abc", "y"), ("?x=nan&y=1", "x"),
    ("?x=inf&y=1", "x"), ("?x=1e400&y=1", "x"), ("?x=&y=1", "x"), ("?x=1&y=", "y"), ("?x=-1&y=1", "x"),
    ("?x=1&y=-1", "y"), ("?x=65&y=1", "x"), ("?x=1&y=49", "y"), ("?x=1px&y=1", "x"), ("?x=1&y=2,3", "y"),
]


@pytest.mark.parametrize("query,field", FOCUS, ids=[q or "(none)" for q, _ in FOCUS])
def test_bad_focus_query(srv, query, field):
    srv.api.error(srv.api.get(f"/api/jobs/{srv.done_job['id']}/focus{query}", expect=None), 400, field)


def test_focus_inside_the_image(srv):
    got = srv.api.get(f"/api/jobs/{srv.done_job['id']}/focus?x=32&y=24").json()
    assert got["x"] == 32 and got["y"] == 24 and 0 < got["distance"] < 100
    srv.api.get(f"/api/jobs/{srv.done_job['id']}/focus?x=0&y=48")  # the edges are inside


def test_broken_scene_fails_the_job_with_its_error(srv):
    listed = {s["name"]: s for s in srv.api.get("/api/scenes").json()["scenes"]}
    assert "summary" in listed["cornell"] and "error" in listed["broken"]
    assert "escape" not in listed or "summary" not in listed["escape"]
    job = srv.api.submit(dict(TINY, scene="broken"))
    failed = srv.api.wait(job["id"], ("failed", "done"), timeout=20)
    assert failed["state"] == "failed" and "broken.dae" in failed["message"]


def test_still_healthy_and_rendering_afterwards(srv):
    assert srv.alive()
    health = srv.api.get("/api/health").json()
    assert health["status"] == "ok"
    # Requests on a kept-alive connection answer in about a millisecond (no Nagle / delayed-ACK
    # stall of 40 ms between the header and body writes).
    times = []
    for _ in range(15):
        t0 = time.monotonic()
        srv.api.get("/api/health")
        times.append(time.monotonic() - t0)
    assert sorted(times)[len(times) // 2] < 0.025, times
    job = srv.api.submit(dict(TINY, seed=99))
    assert srv.api.wait(job["id"], "done", timeout=30)["state"] == "done"
    # Only the jobs the valid requests made exist.
    assert {j["state"] for j in srv.api.get("/api/jobs").json()["jobs"]} <= {"done", "failed"}
