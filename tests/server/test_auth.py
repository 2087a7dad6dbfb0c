"""Access: with --token (or RENDER_SERVER_TOKEN) every /api call but /api/health needs
'Authorization: Bearer <token>' (401 with a JSON error and WWW-Authenticate otherwise); the
event-stream and image URLs also take ?token= (EventSource and links cannot send headers), no other
URL does; the page itself loads without it. Scene names resolve only inside the scene folders."""
import json
import os
import socket

import pytest
import requests

from images import decode_png
from support import CORNELL, TINY, RawConnection, Server

TOKEN = "s3cret-t0ken_with.symbols~"


@pytest.fixture(scope="module")
def srv(tmp_path_factory, contract):
    server = Server(tmp_path_factory.mktemp("auth"), contract, token=TOKEN).start()
    yield server
    server.kill()
    print(server.log_text()[-4000:])


def bare(srv, method, path, **kw):
    """A request with no token (or the headers given), checked against the contract."""
    resp = requests.request(method, srv.url + path, timeout=15, **kw)
    srv.contract.check_response(method, path, resp)
    return resp


def expect_401(resp, invalid):
    assert resp.status_code == 401, resp.text[:300]
    err = resp.json()["error"]
    assert err["status"] == 401 and err["message"]
    challenge = resp.headers["WWW-Authenticate"]
    assert challenge.startswith('Bearer realm="render-server"')
    assert ('error="invalid_token"' in challenge) == invalid


PROTECTED = [("GET", "/api/jobs"), ("GET", "/api/scenes"), ("GET", "/api/openapi.json"), ("POST", "/api/jobs"),
             ("POST", "/api/jobs/check"), ("GET", "/api/jobs/0123456789abcdef"),
             ("DELETE", "/api/jobs/0123456789abcdef"), ("GET", "/api/jobs/0123456789abcdef/events"),
             ("GET", "/api/jobs/0123456789abcdef/image.png"), ("GET", "/api/nope"), ("PUT", "/api/jobs")]


@pytest.mark.parametrize("method,path", PROTECTED, ids=[f"{m} {p}" for m, p in PROTECTED])
def test_no_token_is_401(srv, method, path):
    expect_401(bare(srv, method, path, json=TINY if method in ("POST", "PUT") else None), invalid=False)


BAD = [("wrong token", {"Authorization": "Bearer nope"}), ("a prefix of it", {"Authorization": "Bearer " + TOKEN[:-1]}),
       ("it and more", {"Authorization": "Bearer " + TOKEN + "x"}), ("empty", {"Authorization": "Bearer "}),
       ("another case", {"Authorization": "Bearer " + TOKEN.upper()})]


@pytest.mark.parametrize("name,headers", BAD, ids=[b[0] for b in BAD])
def test_wrong_token_is_401_invalid_token(srv, name, headers):
    expect_401(bare(srv, "GET", "/api/jobs", headers=headers), invalid=True)


@pytest.mark.parametrize("value", ["Basic " + TOKEN, TOKEN, "Token " + TOKEN])
def test_other_schemes_are_401(srv, value):
    resp = bare(srv, "GET", "/api/jobs", headers={"Authorization": value})
    assert resp.status_code == 401 and "Bearer" in resp.json()["error"]["message"]


def test_health_and_the_page_need_no_token(srv):
    assert bare(srv, "GET", "/api/health").json()["status"] == "ok"
    page = requests.get(srv.url + "/", timeout=15)
    assert page.status_code == 200 and "<html" in page.text.lower()
    assert requests.get(srv.url + "/app.js", timeout=15).status_code == 200


def test_with_the_token_everything_works(srv):
    api = srv.api  # sends the bearer token
    assert api.get("/api/scenes").json()["scenes"][0]["name"] == "cornell"
    assert api.get("/api/openapi.json").json()["components"]["securitySchemes"]
    job = api.submit(TINY)
    api.wait(job["id"], "done", timeout=30)
    # A browser's EventSource: the token in the query (support.EventStream sends it so).
    events = srv.events(job["id"]).until_end()
    assert events[-1].data == {"state": "done"}
    # Links to the images: the token in the query.
    png = requests.get(f"{srv.url}/api/jobs/{job['id']}/image.png?token={TOKEN}", timeout=15)
    assert png.status_code == 200 and decode_png(png.content)[:2] == (64, 48)
    exr = requests.get(f"{srv.url}/api/jobs/{job['id']}/image.exr?token={TOKEN}", timeout=15)
    assert exr.status_code == 200 and exr.content[:4] == b"\x76\x2f\x31\x01"
    expect_401(bare(srv, "GET", f"/api/jobs/{job['id']}/image.png?token=nope"), invalid=True)
    expect_401(bare(srv, "GET", f"/api/jobs/{job['id']}/events?token="), invalid=True)


@pytest.mark.parametrize("path", ["/api/jobs", "/api/scenes", "/api/jobs/0123456789abcdef", "/api/openapi.json"])
def test_query_token_only_on_event_and_image_urls(srv, path):
    resp = bare(srv, "GET", f"{path}?token={TOKEN}")
    assert resp.status_code == 401 and "query" in resp.json()["error"]["message"]


def test_refused_post_closes_its_connection(srv):
    # The 401 comes before the body is read: the body must not be taken for a next request.
    body = json.dumps(TINY).encode()
    with RawConnection(srv.port) as conn:
        conn.send(b"POST /api/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                  b"Content-Length: %d\r\n\r\n" % len(body) + body + b"GET /api/health HTTP/1.1\r\n\r\n")
        status, headers, _ = conn.answer()
        assert status == 401 and headers["connection"] == "close"
        assert conn.closed_by_server(2)
        assert conn.answer()[0] is None


def test_token_from_the_environment(servers):
    srv = servers("env", env={"RENDER_SERVER_TOKEN": "from-env"})
    expect_401(bare(srv, "GET", "/api/jobs"), invalid=False)
    ok = requests.get(srv.url + "/api/jobs", headers={"Authorization": "Bearer from-env"}, timeout=15)
    assert ok.status_code == 200 and ok.json() == {"jobs": [], "next_cursor": None}


def test_without_a_token_nothing_is_asked(server):
    assert server.api.get("/api/jobs").json() == {"jobs": [], "next_cursor": None}
    assert "WWW-Authenticate" not in server.api.get("/api/jobs").headers


def test_scene_names_resolve_only_inside_the_scene_folders(tmp_path, contract):
    scenes = tmp_path / "scenes"
    outside = tmp_path / "outside"
    scenes.mkdir()
    outside.mkdir()
    (scenes / "cornell.dae").write_bytes(CORNELL.read_bytes())
    (outside / "secret.dae").write_bytes(CORNELL.read_bytes())
    (outside / "dir").mkdir()
    (outside / "dir" / "deep.dae").write_bytes(CORNELL.read_bytes())
    os.symlink(scenes / "cornell.dae", scenes / "alias.dae")        # inside: allowed
    os.symlink(outside / "secret.dae", scenes / "escape.dae")       # a file outside: refused
    os.symlink(outside / "dir", scenes / "linked")                  # a folder outside: refused
    os.symlink("../outside/secret.dae", scenes / "relative.dae")    # relative, pointing out: refused
    os.symlink(scenes / "nowhere.dae", scenes / "dangling.dae")     # dangling: refused
    os.mkfifo(scenes / "fifo.dae")                                  # not a regular file: refused
    srv = Server(tmp_path, contract, scenes=scenes).start()
    try:
        api = srv.api
        api.post("/api/jobs/check", dict(TINY, scene="alias"), expect=200)
        for name in ("escape", "relative", "dangling", "fifo"):
            api.error(api.post("/api/jobs/check", dict(TINY, scene=name)), 404, "scene")
        api.error(api.post("/api/jobs/check", dict(TINY, scene="linked/deep")), 400, "scene")
        listed = {s["name"]: s for s in api.get("/api/scenes").json()["scenes"]}
        assert "summary" in listed["alias"] and "summary" in listed["cornell"]
        for name in ("escape", "relative", "dangling", "fifo"):
            assert "summary" not in listed.get(name, {}), name
        assert srv.alive()
    finally:
        srv.kill()
