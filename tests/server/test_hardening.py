"""One test per class of attack in docs/reliability.md ("What the server guarantees"): text that is
not UTF-8, multi-range requests, images that do not read back, a second server, descriptor floods,
cross-site pages, DNS rebinding, encodings shared by every client, the scene list's cache, and the
smaller defects (focus on a broken scene, odd headers, FIFOs and links in the data folder, a request
line over the limit, Expect: 100-continue, a read-only data folder). Each fails on a server
without its fix."""
import json
import os
import socket
import subprocess
import threading
import time

import pytest
import requests

from images import decode_png
from support import CORNELL, ENDLESS, RENDER_SERVER, TINY, RawConnection, cannot_run, raw_request

IEND = b"\x00\x00\x00\x00IEND\xaeB`\x82"


def scene_with_bad_count(array_id):
    """cornell.dae with its floor's position array renamed to `array_id` (bytes) and a count that
    disagrees with the data: the loader fails at that element, quoting its id."""
    text = CORNELL.read_bytes()
    text = text.replace(b'id="floor-mesh-positions-array" count="12"', b'id="' + array_id + b'" count="13"')
    return text.replace(b"#floor-mesh-positions-array", b"#" + array_id)


def head(port, path, host):
    """(status, headers, body) of a GET with the given Host header."""
    return raw_request(port, f"GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n".encode())


# ---- text that is not UTF-8 ----
@pytest.mark.parametrize("array_id, quoted", [
    # A Blender export's long Japanese name: the message clips it at 60 bytes, inside a character.
    ("x" + "\u5e8a" * 30, "x" + "\u5e8a" * 19 + "..."),
    # A scene file in Latin-1: its bytes are not UTF-8 at all.
    (b"sol-\xe9t\xe9", "sol-\ufffdt\ufffd"),
])
def test_error_text_that_is_not_utf8_is_refused_or_fails_the_job_not_the_server(server, array_id, quoted):
    raw = array_id.encode() if isinstance(array_id, str) else array_id
    (server.scenes / "odd.dae").write_bytes(scene_with_bad_count(raw))
    api = server.api
    err = api.error(api.post("/api/jobs", dict(TINY, scene="odd")), 422, "scene")
    assert "count says 13" in err["message"] and quoted in err["message"], err["message"]
    # A scene that breaks after its job was accepted fails the job, saying why.
    (server.scenes / "odd.dae").write_bytes(CORNELL.read_bytes())
    blocker = api.submit(ENDLESS)
    api.wait(blocker["id"], "running")
    job = api.submit(dict(TINY, scene="odd"))
    (server.scenes / "odd.dae").write_bytes(scene_with_bad_count(raw))
    api.delete(f"/api/jobs/{blocker['id']}", expect=200)
    assert server.events(job["id"]).until_end()[-1].data == {"state": "failed"}
    failed = api.job(job["id"])
    assert failed["state"] == "failed" and "count says 13" in failed["message"], failed
    assert quoted in failed["message"], failed["message"]
    on_disk = json.loads((server.data / "jobs" / job["id"] / "job.json").read_text())
    assert on_disk["state"] == "failed"  # recorded, so a restart does not run it again
    # A later watcher of the failed job, the job list and the scene list answer too.
    assert server.events(job["id"]).until_end()[-1].data == {"state": "failed"}
    assert any(j["id"] == job["id"] for j in api.get("/api/jobs").json()["jobs"])
    listed = {s["name"]: s for s in api.get("/api/scenes").json()["scenes"]}
    assert quoted in listed["odd"]["error"]
    assert server.alive()


# ---- ranges ----
def test_more_than_one_range_is_416_on_every_route(server):
    api = server.api
    job = api.submit(TINY)
    api.wait(job["id"], "done")
    many = "bytes=" + ",".join(["0-"] * 2000)
    for path in ("/", "/index.html", "/app.js", "/api/health", f"/api/jobs/{job['id']}/image.png",
                 f"/api/jobs/{job['id']}/image.exr"):
        resp = api.request("GET", path, headers={"Range": many})
        assert resp.status_code == 416 and len(resp.content) < 1000, (path, resp.status_code, len(resp.content))
    api.request("GET", "/api/health", 416, headers={"Range": "bytes=0-1, 5-9"})
    one = api.request("GET", "/index.html", headers={"Range": "bytes=0-9"})
    assert one.status_code == 206 and len(one.content) == 10
    assert server.alive()


# ---- images that do not read back ----
def test_a_done_job_whose_image_does_not_read_back_renders_again(servers):
    srv = servers("truncated")
    job = srv.api.submit(TINY)
    srv.api.wait(job["id"], "done")
    png = srv.data / "jobs" / job["id"] / "image.png"
    png.write_bytes(png.read_bytes()[:-12])  # what a disk that filled up left: no IEND
    assert srv.terminate() == 0
    srv = servers("truncated")
    assert srv.api.wait(job["id"], "done", timeout=30)["state"] == "done"
    assert "image.png: the file is cut short" in srv.log_text() and "rendering it again" in srv.log_text()
    served = srv.api.get(f"/api/jobs/{job['id']}/image.png").content
    assert served.endswith(IEND) and decode_png(served)[:2] == (TINY["width"], TINY["height"])


@pytest.mark.skipif(os.environ.get("PT_SANITIZED") == "1",
                    reason="a preloaded library cannot come before the AddressSanitizer runtime")
def test_an_image_writer_that_loses_bytes_fails_the_job(servers):
    shim = os.environ.get("PT_SHORT_WRITE_SHIM")
    assert shim and os.path.exists(shim), "PT_SHORT_WRITE_SHIM is set by ctest (tests/CMakeLists.txt)"
    srv = servers("short", env={"LD_PRELOAD": shim, "SHORT_WRITE_MATCH": ".image.png.tmp", "SHORT_WRITE_KEEP": "300"})
    job = srv.api.submit(dict(TINY, width=96, height=72))
    failed = srv.api.wait(job["id"], ("failed", "done"), timeout=30)
    assert failed["state"] == "failed" and "cut short" in failed["message"], failed
    assert not (srv.data / "jobs" / job["id"] / "image.png").exists()
    assert json.loads((srv.data / "jobs" / job["id"] / "job.json").read_text())["state"] == "failed"
    # What is served for the failed job is its whole preview, never the cut file.
    served = srv.api.get(f"/api/jobs/{job['id']}/image.png").content
    assert served.endswith(IEND) and decode_png(served)[:2] == (96, 72)


# ---- one server per port and per data folder ----
def test_a_second_server_on_the_same_port_or_data_folder_refuses_to_start(servers, tmp_path):
    srv = servers("first")
    other = [str(RENDER_SERVER), "--scenes", str(srv.scenes)]
    same_port = subprocess.run(other + ["--port", str(srv.port), "--data", str(tmp_path / "other")],
                               capture_output=True, text=True, timeout=30)
    assert same_port.returncode != 0 and "Address already in use" in same_port.stderr, same_port.stderr
    assert not (tmp_path / "other").exists()  # refused before touching its data folder
    same_data = subprocess.run(other + ["--port", "0", "--data", str(srv.data)], capture_output=True, text=True,
                               timeout=30)
    assert same_data.returncode != 0, same_data.stderr
    assert "in use by another render-server" in same_data.stderr and f"pid {srv.proc.pid}" in same_data.stderr
    assert srv.alive() and srv.api.get("/api/health").json()["status"] == "ok"


# ---- descriptor floods ----
def test_a_connection_flood_never_costs_a_finished_render_its_images(servers):
    # 128 descriptors: the old cap of 128 connections alone would use them all.
    srv = servers("fds", args=["--max-connections", "128"], limit_open_files=128)
    assert "--max-connections 128 lowered to" in srv.log_text()
    job = srv.api.submit(dict(TINY, width=160, height=120, spp=64))
    flood = []
    try:
        for _ in range(300):  # each holds its connection until the read timeout, or gets 503 at once
            try:
                s = socket.create_connection(("127.0.0.1", srv.port), timeout=5)
                s.sendall(b"GET /api/health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
                flood.append(s)
            except OSError:
                break
        job_file = srv.data / "jobs" / job["id"] / "job.json"
        deadline = time.monotonic() + 60
        while json.loads(job_file.read_text())["state"] not in ("done", "failed"):
            assert time.monotonic() < deadline, "the job did not finish"
            time.sleep(0.05)
    finally:
        for s in flood:
            s.close()
    # The flood's last connections drain (503 with Retry-After meanwhile), then the job answers.
    deadline = time.monotonic() + 60
    while (resp := srv.api.request("GET", f"/api/jobs/{job['id']}")).status_code == 503:
        assert time.monotonic() < deadline, "still refused a minute after the flood ended"
        time.sleep(0.2)
    final = resp.json()
    assert final["state"] == "done", final
    assert srv.api.get(f"/api/jobs/{job['id']}/image.png").content.endswith(IEND)


# ---- cross-site pages ----
def test_cross_site_requests_and_simple_content_types_change_nothing(server):
    api = server.api
    body = json.dumps(TINY)
    # Types a browser sends cross-site without asking first: never read as a job.
    for ct in ("text/plain; x=application/json", "text/plain", "application/x-www-form-urlencoded", None):
        api.error(api.request("POST", "/api/jobs", data=body, headers={"Content-Type": ct}), 415)
    for other in ({"Origin": "https://evil.example"}, {"Origin": "null"}, {"Sec-Fetch-Site": "cross-site"},
                  {"Origin": f"http://127.0.0.1:{server.port + 1}"}, {"Origin": f"http://localhost:{server.port}"}):
        resp = api.request("POST", "/api/jobs", data=body, headers={"Content-Type": "application/json", **other})
        api.error(resp, 403)
    assert api.get("/api/jobs").json()["jobs"] == []
    own = {"Origin": f"http://127.0.0.1:{server.port}", "Sec-Fetch-Site": "same-origin"}
    job = api.post("/api/jobs", dict(ENDLESS), expect=201, headers=own).json()
    api.error(api.request("DELETE", f"/api/jobs/{job['id']}", headers={"Origin": "https://evil.example"}), 403)
    assert api.job(job["id"])["state"] in ("queued", "running")
    api.request("DELETE", f"/api/jobs/{job['id']}", 200, headers=own)


# ---- DNS rebinding ----
def test_only_loopback_names_and_allowed_hosts_are_answered(servers):
    srv = servers("hosts", args=["--allowed-host", "render.example.org"])
    p = srv.port
    for host in ("127.0.0.1", f"127.0.0.1:{p}", f"localhost:{p}", "LOCALHOST", f"[::1]:{p}", "app.localhost",
                 "127.1.2.3", "render.example.org", f"Render.Example.org:{p}"):
        assert head(p, "/api/health", host)[0] == 200, host
    for host in ("evil.example", f"evil.example:{p}", "127.0.0.1.evil.example", "localhost.evil.example",
                 "10.0.0.1", f"[::2]:{p}", "bad host"):
        for path in ("/api/health", "/", "/api/jobs"):
            status, headers, body = head(p, path, host)
            assert status == 421 and json.loads(body)["error"]["status"] == 421, (host, path, status)


# ---- encodings shared by every client ----
def test_images_are_encoded_once_for_every_watcher_and_poller(server):
    api = server.api
    assert api.get("/api/health").json()["stream"] == {"watchers": 0, "png_encodes": 0, "tile_events": 0}
    job = api.submit(dict(TINY, width=256, height=192, spp=16, tile_size=8, adaptive=False))
    counts = [0] * 12

    def watch(i):
        for ev in server.events(job["id"], timeout=60):
            counts[i] += ev.kind == "tile"

    threads = [threading.Thread(target=watch, args=(i,)) for i in range(len(counts))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    stream = api.get("/api/health").json()["stream"]
    assert stream["tile_events"] >= sum(counts) > 0 and stream["watchers"] == 0
    assert stream["png_encodes"] * 3 <= sum(counts), (stream, counts)  # shared, not one per watcher

    # Pollers of a running job's image.png: one encoding a pass (or a second), not one a request.
    busy = api.submit(dict(ENDLESS, width=320, height=240, spp=32768))
    api.wait(busy["id"], "running")
    while not api.job(busy["id"])["error_history"]:
        time.sleep(0.02)
    before, passes = api.get("/api/health").json()["stream"]["png_encodes"], len(api.job(busy["id"])["error_history"])
    t0 = time.monotonic()
    session = requests.Session()
    for _ in range(60):
        assert session.get(f"{server.url}/api/jobs/{busy['id']}/image.png", timeout=15).content.endswith(IEND)
    seconds = time.monotonic() - t0
    after = api.get("/api/health").json()["stream"]["png_encodes"]
    passes = len(api.job(busy["id"])["error_history"]) - passes
    assert after - before <= passes + seconds + 2, (after - before, passes, seconds)
    api.delete(f"/api/jobs/{busy['id']}", expect=200)


# ---- the scene list's cache ----
def test_the_scene_list_parses_each_file_once_per_version(server):
    api = server.api
    broken = server.scenes / "broken.dae"
    first_text, second_text = b"<COLLADA><asset>", b"<notcollada/>   "
    assert len(first_text) == len(second_text)
    broken.write_bytes(first_text)
    stamp = os.stat(broken)

    def listed_error():
        return {s["name"]: s for s in api.get("/api/scenes").json()["scenes"]}["broken"]["error"]

    first = listed_error()
    broken.write_bytes(second_text)
    os.utime(broken, ns=(stamp.st_atime_ns, stamp.st_mtime_ns))
    assert listed_error() == first  # same path, size and time: the cached answer, no new parse
    os.utime(broken, ns=(stamp.st_atime_ns, stamp.st_mtime_ns + 10**9))
    assert listed_error() != first  # a new version is parsed again


# ---- smaller defects ----
def test_focus_on_a_job_whose_scene_no_longer_loads_is_422(server):
    api = server.api
    (server.scenes / "changing.dae").write_bytes(CORNELL.read_bytes())
    job = api.submit(dict(TINY, scene="changing"))
    api.wait(job["id"], "done")
    api.get(f"/api/jobs/{job['id']}/focus?x=32&y=24")
    (server.scenes / "changing.dae").write_bytes(scene_with_bad_count(b"floor"))
    err = api.error(api.request("GET", f"/api/jobs/{job['id']}/focus?x=32&y=24"), 422, "scene")
    assert "count says 13" in err["message"]


def test_an_idempotency_key_that_is_not_utf8_is_400(server):
    body = json.dumps(TINY).encode()
    status, _, answer = raw_request(server.port, b"POST /api/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                                    b"Content-Type: application/json\r\nIdempotency-Key: key-\xff\xfe\r\n"
                                    b"Content-Length: " + str(len(body)).encode() + b"\r\n\r\n" + body)
    assert status == 400 and json.loads(answer)["error"]["field"] == "Idempotency-Key"
    assert server.api.get("/api/jobs").json()["jobs"] == []


def test_fifos_and_links_in_the_data_folder_are_skipped(servers):
    srv = servers("links")
    job = srv.api.submit(TINY)
    srv.api.wait(job["id"], "done")
    assert srv.terminate() == 0
    folder = srv.data / "jobs" / job["id"]
    (folder / "image.png").unlink()
    (folder / "image.png").symlink_to("/etc/passwd")
    fifo_job = srv.data / "jobs" / "00000000000000001"
    fifo_job.mkdir()
    os.mkfifo(fifo_job / "job.json")
    srv = servers("links")  # a FIFO must not hang start-up
    assert "00000000000000001/job.json: not a regular file" in srv.log_text()
    assert srv.api.wait(job["id"], "done", timeout=30)["state"] == "done"
    served = srv.api.get(f"/api/jobs/{job['id']}/image.png").content
    assert b"root:" not in served and served.endswith(IEND)
    assert not (folder / "image.png").is_symlink()  # rendered again into a file of its own
    assert srv.terminate() == 0  # and SIGTERM is honoured


def test_a_request_line_over_the_head_limit_is_431(server):
    status, headers, body = raw_request(server.port, b"GET /" + b"a" * 20000 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    assert status == 431 and json.loads(body)["error"]["status"] == 431


def test_expect_continue_with_an_oversized_body_gets_413_and_no_invitation(server):
    with RawConnection(server.port) as conn:
        conn.send(b"POST /api/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                  b"Expect: 100-continue\r\nContent-Length: 10000000\r\n\r\n")
        status, headers, body = conn.answer()
        assert status == 413 and headers.get("connection") == "close"


@pytest.fixture
def read_only_mount(tmp_path):
    """An empty read-only tmpfs; yields (prefix, path): the command the server runs under (it must exec
    the server) and where the tmpfs is for it."""
    mnt = tmp_path / "ro"
    mnt.mkdir()
    # First choice, unprivileged: the server gets a user + mount namespace of its own, mounts there and
    # execs; the mount is private to it and goes when the server exits, so nothing stays mounted here.
    own_ns = ["unshare", "-Urm", "sh", "-c", 'mount -t tmpfs -o ro,size=64k tmpfs "$0" && exec "$@"', str(mnt)]
    plain = False
    if subprocess.run([*own_ns, "true"], capture_output=True).returncode != 0:
        plain = subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", str(mnt)],
                               capture_output=True).returncode == 0
        if not plain:
            cannot_run("neither mount nor unshare -Urm can make a read-only tmpfs here")
    yield ([] if plain else own_ns), mnt
    if plain:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def test_a_read_only_data_folder_is_reported_as_read_only(read_only_mount):
    prefix, mnt = read_only_mount
    r = subprocess.run([*prefix, str(RENDER_SERVER), "--port", "0", "--data", str(mnt / "data")],
                       capture_output=True, text=True, timeout=30)
    assert r.returncode != 0 and "Read-only file system" in r.stderr, r.stderr
