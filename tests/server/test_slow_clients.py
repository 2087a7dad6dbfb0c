"""Slow and flooding clients: slowloris heads and bodies trickled a byte at a time are cut off at
the read timeout (408) however steadily they trickle, while other clients are served meanwhile;
connections over the cap are answered 503 before they send a byte; header floods, chunked floods
and huge bodies are refused before they cost memory. The server runs with --read-timeout 1.5
--max-connections 12. Where the timeout is the requirement, the bound is ten times it (LIMIT): a
trickle that the server let live would go on that long, a cut one ends at 1.5 s, and load only
delays the cut by far less than the 13.5 s between."""
import socket
import threading
import time

import pytest

from support import TINY, RawConnection, Server

TIMEOUT = 1.5
LIMIT = 10 * TIMEOUT
CAP = 12
H = b"Host: 127.0.0.1\r\n"


@pytest.fixture(scope="module")
def srv(tmp_path_factory, contract):
    server = Server(tmp_path_factory.mktemp("slow"), contract,
                    args=["--read-timeout", str(TIMEOUT), "--max-connections", str(CAP)]).start()
    yield server
    server.kill()
    print(server.log_text()[-4000:])


class Trickler:
    """Connections that each send `start`, then one more byte every `every` seconds (never
    finishing), until the server drops them or `limit` seconds pass; records when each was dropped."""

    def __init__(self, port, count, start, byte=b"X", every=0.2, limit=LIMIT):
        self.t0 = time.monotonic()
        self.conns = [RawConnection(port) for _ in range(count)]
        for c in self.conns:
            c.send(start)
        self.dropped = [None] * count
        self.answers = [None] * count
        self.threads = [threading.Thread(target=self._run, args=(i, byte, every, limit)) for i in range(count)]
        for t in self.threads:
            t.start()

    def _run(self, i, byte, every, limit):
        conn = self.conns[i]
        while time.monotonic() - self.t0 < limit:
            if conn.closed_by_server(every):
                self.dropped[i] = time.monotonic() - self.t0
                self.answers[i] = conn.answer()[0] if conn.buf else None
                return
            try:
                conn.send(byte)
            except OSError:
                self.dropped[i] = time.monotonic() - self.t0
                return

    def join(self):
        for t in self.threads:
            t.join(15)
        for c in self.conns:
            c.close()


def test_slowloris_heads_are_cut_at_the_read_timeout_while_others_are_served(srv):
    slow = Trickler(srv.port, 8, b"GET /api/health HTTP/1.1\r\n" + H + b"X-Slow: ")
    answered = []  # when each other request was answered
    while any(d is None for d in slow.dropped) and time.monotonic() - slow.t0 < LIMIT:
        srv.api.get("/api/health")
        answered.append(time.monotonic() - slow.t0)
        time.sleep(0.05)
    slow.join()
    # Every byte arrived well within the read timeout, yet the whole head did not: each cut with 408
    # (never before the read timeout; a server that let them live leaves them open until LIMIT).
    for when, status in zip(slow.dropped, slow.answers):
        assert when is not None and TIMEOUT - 0.2 < when < LIMIT, slow.dropped
        assert status == 408, slow.answers
    # Other clients were served while all eight still held their connections.
    assert answered and answered[0] < min(slow.dropped), (answered[:3], slow.dropped)


def test_slow_body_is_cut_at_the_read_timeout(srv):
    head = b"POST /api/jobs/check HTTP/1.1\r\n" + H + b"Content-Type: application/json\r\nContent-Length: 1000\r\n\r\n{"
    slow = Trickler(srv.port, 3, head, byte=b" ")
    slow.join()
    assert all(w is not None and w < LIMIT for w in slow.dropped), slow.dropped
    assert slow.answers == [408] * 3


def test_half_a_request_line_then_silence_is_cut(srv, contract):
    with RawConnection(srv.port) as conn:
        conn.send(b"GET /api/hea")
        assert conn.closed_by_server(LIMIT)
        # httplib answers nothing when the request line itself never ends: just closed.
        assert conn.answer()[0] is None


def test_idle_connection_is_closed_without_an_answer(srv):
    with RawConnection(srv.port) as conn:
        assert conn.closed_by_server(LIMIT)  # the keep-alive timeout (1 s)
        assert conn.answer()[0] is None


def test_connections_over_the_cap_get_503_at_once(srv, contract):
    slow = Trickler(srv.port, CAP, b"GET /api/health HTTP/1.1\r\n" + H + b"X-Slow: ")
    # Connections over the cap are answered 503 before they send anything: the answer cannot wait
    # for a request. (Until the server has taken all twelve, a probe may still be served.)
    for _ in range(5):
        deadline = time.monotonic() + LIMIT
        while True:
            with RawConnection(srv.port, timeout=LIMIT) as conn:
                status, headers, body = conn.answer()  # nothing sent
            if status == 503 or time.monotonic() > deadline:
                break
        assert status == 503 and headers["retry-after"] == "1" and headers["connection"] == "close", status
        contract.validate_component(__import__("json").loads(body), "Error")
    slow.join()
    # The slow ones are gone: served again, once the server has reaped their connections (a
    # moment later under the sanitizers).
    deadline = time.monotonic() + LIMIT
    while True:
        with RawConnection(srv.port) as conn:
            conn.send(b"GET /api/health HTTP/1.1\r\n" + H + b"\r\n")
            status = conn.answer()[0]
        if status == 200 or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    assert status == 200
    assert srv.api.get("/api/health").json()["status"] == "ok"


def send_flood(port, head, chunk, total):
    """Sends `head`, then `chunk` repeatedly up to `total` bytes or until the server stops reading;
    returns (answer status, bytes sent, seconds)."""
    t0 = time.monotonic()
    sent = 0
    with RawConnection(port, timeout=10) as conn:
        conn.send(head)
        try:
            while sent < total:
                conn.sock.sendall(chunk)
                sent += len(chunk)
        except OSError:
            pass  # the server answered, closed and stopped reading
        return conn.answer()[0], sent, time.monotonic() - t0


def test_header_flood_is_431_before_it_costs_memory(srv):
    before = srv.rss_kib()
    status, sent, seconds = send_flood(srv.port, b"GET /api/health HTTP/1.1\r\n", b"X-Flood: " + b"a" * 90 + b"\r\n",
                                       50 << 20)
    assert status == 431
    assert sent < (50 << 20)  # it stopped reading
    assert srv.rss_kib() - before < 20 * 1024  # KiB


def test_chunked_flood_is_411_before_it_costs_memory(srv):
    # httplib 0.11 alone reads a chunked body whole, whatever the payload limit: 200 MB went to RAM.
    before = srv.rss_kib()
    chunk = b"10000\r\n" + b"x" * 0x10000 + b"\r\n"
    status, sent, seconds = send_flood(
        srv.port, b"POST /api/jobs HTTP/1.1\r\n" + H + b"Content-Type: application/json\r\n"
                  b"Transfer-Encoding: chunked\r\n\r\n", chunk, 200 << 20)
    assert status == 411
    assert sent < (200 << 20)
    assert srv.rss_kib() - before < 20 * 1024


def test_huge_content_length_is_413_unread(srv):
    status, sent, seconds = send_flood(
        srv.port, b"POST /api/jobs HTTP/1.1\r\n" + H + b"Content-Type: application/json\r\n"
                  b"Content-Length: 10000000000\r\n\r\n", b"x" * 65536, 200 << 20)
    assert status == 413 and sent < (200 << 20)


def test_still_healthy_and_rendering_afterwards(srv):
    assert srv.alive()
    job = srv.api.submit(TINY)
    assert srv.api.wait(job["id"], "done", timeout=30)["state"] == "done"
