"""Hostile and malformed requests: each gets its exact 4xx status and the JSON error shape naming
the offending field where there is one; afterwards the server is healthy and still renders."""
import json
import os
import socket
import time

import pytest

from support import CORNELL, TINY, RawConnection, Server, raw_request

INT_FIELDS = ["max_depth", "spp", "light_samples", "width", "height", "seed", "adaptive_batch", "tile_size"]
NUM_FIELDS = ["aperture", "focal_distance", "adaptive_tolerance", "time_limit", "target_error"]
BOOL_FIELDS = ["adaptive", "hemisphere", "file_camera", "keep_fov", "caustic_tracing"]
READ_TIMEOUT = 120


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
    # A read timeout far beyond any answer's time, so that "answered at once, not at the read
    # timeout" holds with a bound no load reaches (test_post_without_content_length_is_411_at_once).
    server = Server(root, contract, scenes=scenes, args=["--read-timeout", str(READ_TIMEOUT)]).start()
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
    ("tile_size", 257), ("aperture", 1e6 + 1), ("focal_distance", 1.5e12), ("adaptive_tolerance", 1.01),
    ("time_limit", 1e9 + 1), ("target_error", 1.5), ("width", 10 ** 30)]]
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
    # No Content-Type is not JSON: a form or a text/plain body a page of another site may send
    # without asking must never be read as a job (CSRF).
    srv.api.error(srv.api.request("POST", "/api/jobs/check", data=json.dumps(TINY), headers={"Content-Type": None}), 415)


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
                                                  b"Content-Type: application/json\r\n\r\n", timeout=READ_TIMEOUT)
    assert time.monotonic() - t0 < READ_TIMEOUT / 4  # not after the read timeout (it takes milliseconds)
    check_raw_error(contract, status, headers, body, 411)


def test_garbage_request_line_is_400(srv, contract):
    status, headers, body = raw_request(srv.port, b"\x16\x03\x01 hello\r\n\r\n")
    check_raw_error(contract, status, headers, body, 400)


def test_overlong_uri_is_414(srv, contract):
    status, headers, body = raw_request(
        srv.port, b"GET /api/jobs/" + b"a" * 10000 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    check_raw_error(contract, status, headers, body, 414)


# ---- raw requests: malformed request lines, headers and framing, truncations, pipelining ----
H = b"Host: 127.0.0.1\r\n"
CHECK = b"POST /api/jobs/check HTTP/1.1\r\n" + H + b"Content-Type: application/json\r\n"
VALID = json.dumps({"scene": "cornell", "width": 8, "height": 8, "spp": 1}).encode()
# (name, bytes, status: an int, or None for "closed without an answer"). A refused request closes
# its connection (its unread bytes must not be parsed as a next request): checked for every 4xx here.
RAW = [
    ("lower-case method", b"get /api/health HTTP/1.1\r\n" + H + b"\r\n", 400),
    ("unknown method", b"FOO /api/health HTTP/1.1\r\n" + H + b"\r\n", 405),
    ("TRACE", b"TRACE /api/health HTTP/1.1\r\n" + H + b"\r\n", 405),
    ("CONNECT", b"CONNECT 127.0.0.1:80 HTTP/1.1\r\n" + H + b"\r\n", 400),
    ("HTTP/2.0 preface", b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n", 400),
    ("HTTP/2.0 version", b"GET /api/health HTTP/2.0\r\n" + H + b"\r\n", 400),
    ("HTTP/1.2 version", b"GET /api/health HTTP/1.2\r\n" + H + b"\r\n", 400),
    ("HTTP/0.9 (no version)", b"GET /api/health\r\n\r\n", 400),
    ("tab separator", b"GET\t/api/health HTTP/1.1\r\n" + H + b"\r\n", 400),
    ("empty request line", b"\r\n", 400),
    ("NUL in the request line", b"GET /api/he\x00alth HTTP/1.1\r\n" + H + b"\r\n", 400),
    ("bare LF line ends", b"GET /api/health HTTP/1.1\nHost: x\n\n", 400),
    ("binary garbage", bytes(range(256)) + b"\r\n\r\n", 400),
    ("header line over 8 KiB", b"GET /api/health HTTP/1.1\r\nX-A: " + b"a" * 9000 + b"\r\n" + H + b"\r\n", 400),
    ("1500 headers (over 16 KiB)",
     b"GET /api/health HTTP/1.1\r\n" + b"".join(b"X-%d: aaaaaaaaaa\r\n" % i for i in range(1500)) + H + b"\r\n", 431),
    ("one 15 KiB header of many short values", b"GET /api/health HTTP/1.1\r\n" + b"X-A: b\r\n" * 2400 + b"\r\n", 431),
    ("Content-Length -1", CHECK + b"Content-Length: -1\r\n\r\n{}", 400),
    ("Content-Length not a number", CHECK + b"Content-Length: abc\r\n\r\n{}", 400),
    ("Content-Length with a sign", CHECK + b"Content-Length: +2\r\n\r\n{}", 400),
    ("Content-Length 20 digits", CHECK + b"Content-Length: 99999999999999999999\r\n\r\n{}", 400),
    ("two Content-Lengths (smuggling)", CHECK + b"Content-Length: 2\r\nContent-Length: 20\r\n\r\n{}", 400),
    ("Content-Length over 64 KiB, body never sent", CHECK + b"Content-Length: 99999999999999999\r\n\r\n", 413),
    ("Content-Length over 64 KiB, 100 KB sent", CHECK + b"Content-Length: 100000\r\n\r\n" + b"x" * 100000, 413),
    ("chunked body", CHECK + b"Transfer-Encoding: chunked\r\n\r\n2\r\n{}\r\n0\r\n\r\n", 411),
    ("chunked and Content-Length", CHECK + b"Content-Length: 2\r\nTransfer-Encoding: chunked\r\n\r\n{}", 411),
    ("gzip, chunked", CHECK + b"Transfer-Encoding: gzip, chunked\r\n\r\n0\r\n\r\n", 411),
    ("absolute-form target", b"GET http://127.0.0.1/api/health HTTP/1.1\r\n" + H + b"\r\n", 404),
    ("asterisk-form target", b"OPTIONS * HTTP/1.1\r\n" + H + b"\r\n", 404),
    ("JSON nested 30000 deep", CHECK + b"Content-Length: 60000\r\n\r\n" + b"[" * 30000 + b"]" * 30000, 400),
    ("object nested 5000 deep", CHECK + b"Content-Length: 35001\r\n\r\n" + b'{"a":' * 5000 + b"1" + b"}" * 5000, 400),
    ("3000 unknown keys", CHECK + b"Content-Length: %d\r\n\r\n" % (len(json.dumps({f"k{i}": i for i in range(3000)}))) +
     json.dumps({f"k{i}": i for i in range(3000)}).encode(), 400),
    ("lone surrogate", CHECK + b'Content-Length: 20\r\n\r\n{"scene": "\\ud800"}', 400),
    ("raw control character in a string", CHECK + b'Content-Length: 18\r\n\r\n{"scene": "a\x01b"}', 400),
    ("UTF-16 body", CHECK + b"Content-Length: %d\r\n\r\n" % len(VALID.decode().encode("utf-16")) +
     VALID.decode().encode("utf-16"), 400),
    ("body shorter than Content-Length, then EOF", CHECK + b"Content-Length: 100\r\n\r\n{\"scene\"", 400),
    ("head cut off, then EOF", b"GET /api/health HTTP/1.1\r\nHost: x", 400),
    ("request line only, then EOF", b"GET /api/health HTTP/1.1\r\n", 400),
    ("half a request line, then EOF", b"GET /api/hea", 400),
    ("nothing, then EOF", b"", None),
]


@pytest.mark.parametrize("name,data,status", RAW, ids=[r[0] for r in RAW])
def test_raw_request_is_refused(srv, contract, name, data, status):
    with RawConnection(srv.port) as conn:
        conn.send(data)
        conn.sock.shutdown(socket.SHUT_WR)  # everything is sent: truncated requests end here
        got, headers, body = conn.answer()
        assert got == status, body[:300]
        if status is not None and status >= 400 and status != 404:
            check_raw_error(contract, got, headers, body, status)
            assert headers.get("connection") == "close"
        assert conn.closed_by_server(20), "the server kept a refused connection open"


# (name, bytes, statuses of the answers in order; None: the connection then closed)
ACCEPTED = [
    ("two spaces after the method", b"GET  /api/health HTTP/1.1\r\n" + H + b"\r\n", [200]),
    ("header without a colon", b"GET /api/health HTTP/1.1\r\nFoo\r\n" + H + b"\r\n", [200]),
    ("obsolete line folding", b"GET /api/health HTTP/1.1\r\nX-A: 1\r\n  folded\r\n" + H + b"\r\n", [200]),
    ("NUL in a header value", b"GET /api/health HTTP/1.1\r\nX-A: a\x00b\r\n" + H + b"\r\n", [200]),
    ("HTTP/1.0 without Host", b"GET /api/health HTTP/1.0\r\n\r\n", [200, None]),
    ("HEAD", b"HEAD /api/health HTTP/1.1\r\n" + H + b"\r\n", [200]),
    ("HEAD of an unknown job", b"HEAD /api/jobs/0123456789abcdef HTTP/1.1\r\n" + H + b"\r\n", [404]),
    ("CRLF smuggled into a job id", b"GET /api/jobs/x%0d%0aSet-Cookie:%20a=b HTTP/1.1\r\n" + H + b"\r\n", [404]),
    ("two pipelined requests", b"GET /api/health HTTP/1.1\r\n" + H + b"\r\nGET /api/jobs HTTP/1.1\r\n" + H + b"\r\n",
     [200, 200]),
    ("a request, then garbage", b"GET /api/health HTTP/1.1\r\n" + H + b"\r\nxyz\r\n\r\n", [200, 400, None]),
    ("GET with a body: answered, then closed", b"GET /api/health HTTP/1.1\r\n" + H +
     b"Content-Length: 5\r\n\r\nhelloGET /api/health HTTP/1.1\r\n\r\n", [200, None]),
    ("Expect: 100-continue", CHECK + b"Expect: 100-continue\r\nContent-Length: %d\r\n\r\n" % len(VALID) + VALID,
     [100, 200]),
    ("UTF-8 byte order mark", CHECK + b"Content-Length: %d\r\n\r\n\xef\xbb\xbf" % (len(VALID) + 3) + VALID, [200]),
    ("DELETE with a body", b"DELETE /api/jobs/0123456789abcdef HTTP/1.1\r\n" + H + b"Content-Length: 5\r\n\r\nhello",
     [404]),
    ("query of 2000 parameters", b"GET /api/jobs?" + b"a=1&" * 2000 + b" HTTP/1.1\r\n" + H + b"\r\n", [200]),
    ("bad percent-escapes in the query", b"GET /api/jobs?x=%zz&%=%%&y HTTP/1.1\r\n" + H + b"\r\n", [200]),
]


@pytest.mark.parametrize("name,data,statuses", ACCEPTED, ids=[r[0] for r in ACCEPTED])
def test_odd_but_valid_request(srv, name, data, statuses):
    with RawConnection(srv.port) as conn:
        conn.send(data)
        for status in statuses:
            got, headers, body = conn.answer()
            assert got == status, (got, body[:300])
            assert "set-cookie" not in headers
        if statuses[-1] is None:
            assert conn.closed_by_server(20)


# Static files (the page): nothing outside web/ is ever served.
TRAVERSAL = ["/../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/..%2f..%2fetc%2fpasswd", "//etc/passwd",
             "/web/../server/main.cpp", "/../server/main.cpp", "/%2e%2e%2fserver%2fmain.cpp", "/index.html%00.js",
             "/.%2e/.%2e/etc/passwd", "/....//....//etc/passwd", "/%252e%252e/etc/passwd", "/app.js/..%5c..%5cREADME.md",
             "/./../README.md", "/api/../../etc/passwd", "/\\..\\..\\etc\\passwd"]


@pytest.mark.parametrize("path", TRAVERSAL)
def test_path_traversal_serves_nothing_outside_web(srv, path):
    status, headers, body = raw_request(srv.port, b"GET " + path.encode() + b" HTTP/1.1\r\n" + H + b"\r\n")
    assert status in (400, 404), (status, body[:200])  # "%00": 400, not index.html
    assert b"root:" not in body and b"#include" not in body and b"render-job" not in body.lower()


UNKNOWN = "0123456789abcdef"
NOT_FOUND = [
    ("GET", f"/api/jobs/{UNKNOWN}"), ("GET", "/api/jobs/NOT-HEX"), ("GET", "/api/jobs/%FF"),
    ("GET", "/api/jobs/" + "a" * 41), ("GET", "/api/jobs/%2e%2e"), ("DELETE", f"/api/jobs/{UNKNOWN}"),
    ("DELETE", "/api/jobs/%FF%FE"), ("GET", f"/api/jobs/{UNKNOWN}/image.png"), ("GET", f"/api/jobs/{UNKNOWN}/image.exr"),
    ("GET", f"/api/jobs/{UNKNOWN}/events"), ("GET", f"/api/jobs/{UNKNOWN}/focus?x=1&y=1"),
    ("GET", "/api/jobs/check"),  # a job id that is not one
    ("GET", "/api/nope"), ("GET", "/api/%FF"), ("GET", "/api/"), ("POST", "/api/nope"),
    ("GET", f"/api/jobs/{UNKNOWN}/image.gif"), ("GET", f"/api/jobs/{UNKNOWN}/nope"),
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


def test_a_broken_scene_is_refused_at_submit_with_its_error(srv):
    listed = {s["name"]: s for s in srv.api.get("/api/scenes").json()["scenes"]}
    assert "summary" in listed["cornell"] and "error" in listed["broken"]
    assert "escape" not in listed or "summary" not in listed["escape"]
    jobs_before = len(srv.api.get("/api/jobs").json()["jobs"])
    for path in ("/api/jobs", "/api/jobs/check"):
        err = srv.api.error(srv.api.post(path, dict(TINY, scene="broken")), 422, "scene")
        assert "broken.dae" in err["message"] and err["message"] == "scene 'broken' does not load: " + listed["broken"]["error"]
    assert len(srv.api.get("/api/jobs").json()["jobs"]) == jobs_before, "a job was made of a broken scene"


def test_still_healthy_and_rendering_afterwards(srv):
    assert srv.alive()
    health = srv.api.get("/api/health").json()
    assert health["status"] == "ok"
    # No Nagle / delayed-ACK stall between the header and body writes on a kept-alive connection.
    # That stall is a kernel timer (TCP_DELACK_MIN, 40 ms) that every request pays once the
    # connection leaves quick-ACK mode (the first requests), so after those, one request of 20
    # faster than 35 ms shows there is none; load only lengthens requests, it cannot shorten one.
    for _ in range(20):
        srv.api.get("/api/health")
    times = []
    for _ in range(20):
        t0 = time.monotonic()
        srv.api.get("/api/health")
        times.append(time.monotonic() - t0)
    assert min(times) < 0.035, times
    job = srv.api.submit(dict(TINY, seed=99))
    assert srv.api.wait(job["id"], "done", timeout=30)["state"] == "done"
    # Only the jobs the valid requests made exist.
    assert {j["state"] for j in srv.api.get("/api/jobs").json()["jobs"]} <= {"done", "failed"}
