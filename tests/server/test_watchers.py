"""Ten watchers on one job, one of them connected but never reading (tiny receive buffer): every
reading watcher gets the whole picture and the end event, the job finishes, the server answers
API requests meanwhile (states, not latencies: a loaded machine is slow, not wrong)."""
import socket
import threading
import time

from images import Canvas, decode_png
from support import ENDLESS

JOB = {"scene": "cornell", "width": 128, "height": 96, "spp": 128, "adaptive": False, "max_depth": 3,
       "tile_size": 16, "seed": 2}


def send_queue(server_port, client_port):
    """Bytes the server has queued on its socket to client_port (from /proc/net/tcp), or None."""
    for line in open("/proc/net/tcp").read().splitlines()[1:]:
        f = line.split()
        local, remote = f[1].split(":"), f[2].split(":")
        if int(local[1], 16) == server_port and int(remote[1], 16) == client_port:
            return int(f[4].split(":")[0], 16)
    return None


def test_ten_watchers_one_stalled(server):
    api = server.api
    blocker = api.submit(ENDLESS)
    api.wait(blocker["id"], "running")
    job = api.submit(JOB)

    stalled = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1024)
    stalled.connect(("127.0.0.1", server.port))
    stalled_since = time.monotonic()
    stalled.sendall(f"GET /api/jobs/{job['id']}/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())

    streams = [server.events(job["id"], timeout=60) for _ in range(9)]
    results = [None] * len(streams)

    def watch(i):
        results[i] = streams[i].until_end()

    threads = [threading.Thread(target=watch, args=(i,)) for i in range(len(streams))]
    for t in threads:
        t.start()
    api.delete(f"/api/jobs/{blocker['id']}", expect=200)

    # While it renders to ten watchers the API answers: health requests served while the job runs.
    answered_while_running = 0
    polls = 0
    while (state := api.job(job["id"])["state"]) != "done":
        assert api.get("/api/health").json()["status"] == "ok"
        answered_while_running += state == "running" and api.job(job["id"])["state"] == "running"
        polls += 1
        assert polls < 3000, "job did not finish"
        time.sleep(0.02)
    for t in threads:
        t.join(30)
        assert not t.is_alive(), "a watcher got no end event"
    assert answered_while_running > 0, "no request was answered while the job rendered"

    final = api.job(job["id"])
    assert final["state"] == "done" and final["samples"] == 128 * 96 * 128
    _, _, pixels = decode_png(api.get(f"/api/jobs/{job['id']}/image.png").content)
    for events in results:
        assert events[-1].data == {"state": "done"}
        canvas = Canvas(128, 96, 16)
        for ev in events:
            if ev.kind == "tile":
                canvas.paint_tile(ev.data)
            elif ev.kind == "image":
                canvas.paint_image(ev.data)
        assert bytes(canvas.pixels) == pixels, "a watcher's picture is not the final image"

    # The stalled watcher really is stalled: the server has unsent bytes queued for it (unless the
    # render took so long that the server's 10 s write timeout has already dropped it).
    queued = send_queue(server.port, stalled.getsockname()[1])
    assert (queued or 0) > 0 or time.monotonic() - stalled_since > 9.5, queued

    # With it still connected, the server serves new work.
    api.get("/api/health")
    again = api.submit(dict(JOB, spp=2))
    api.wait(again["id"], "done", timeout=20)
    stalled.close()
    for s in streams:
        s.close()
    assert api.get("/api/health").json()["status"] == "ok"
