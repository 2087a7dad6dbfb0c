#!/usr/bin/env python3
"""Job service benchmark: prints (a) the time from POST /api/jobs to the first tile event (median
of 5), (b) render throughput (samples/s from the job's status) with 0 and with 10 event-stream
watchers, and (c) the server's peak RSS (VmHWM) during a longer job with one stalled watcher and
without. Run with the test venv:  build/venv/bin/python bench/server_bench.py [--threads N]"""
import argparse
import socket
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests/server"))
from support import Contract, Server  # noqa: E402  (the tests' process and stream helpers)

from progress import clear, progress  # noqa: E402

FIRST_TILE_JOB = {"scene": "cornell", "width": 320, "height": 240, "spp": 64, "max_depth": 5}
THROUGHPUT_JOB = {"scene": "cornell", "width": 320, "height": 240, "spp": 32, "max_depth": 5, "adaptive": False,
                  "tile_size": 32}
BLOCKER = {"scene": "cornell", "width": 64, "height": 48, "spp": 65536, "adaptive": False}  # until cancelled
LONG_JOB = {"scene": "cornell", "width": 640, "height": 480, "spp": 16, "max_depth": 5, "adaptive": False,
            "tile_size": 16}


def start(tmp, name, threads, contract):
    root = Path(tmp) / name
    root.mkdir()
    return Server(root, contract, threads=threads).start()


def first_tile_latency(srv, seed):
    """Seconds from sending the POST to receiving the job's first tile event."""
    t0 = time.perf_counter()
    job = srv.api.submit(dict(FIRST_TILE_JOB, seed=seed))
    stream = srv.events(job["id"])
    kind = None
    for ev in stream:
        if ev.kind in ("tile", "image"):
            kind = ev.kind
            break
    elapsed = time.perf_counter() - t0
    stream.close()
    srv.api.delete(f"/api/jobs/{job['id']}")
    srv.api.wait(job["id"], ("cancelled", "done"), timeout=30)
    return elapsed, kind


def watch_raw(port, job_id, counts, i):
    """A watcher that reads everything and parses nothing (the client's CPU stays out of the
    figure on this 2-core machine): bytes until the end event."""
    with socket.create_connection(("127.0.0.1", port), timeout=120) as sock:
        sock.sendall(f"GET /api/jobs/{job_id}/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())
        tail, total = b"", 0
        while b"event: end" not in tail:
            chunk = sock.recv(1 << 16)
            if not chunk:
                break
            total += len(chunk)
            tail = (tail + chunk)[-256:]
        counts[i] = total


def throughput(srv, watchers, seed):
    """samples/s of one job (from its status) and the bytes each watcher received."""
    blocker = srv.api.submit(BLOCKER)
    srv.api.wait(blocker["id"], "running")
    job = srv.api.submit(dict(THROUGHPUT_JOB, seed=seed))
    counts = [0] * watchers
    threads = [threading.Thread(target=watch_raw, args=(srv.port, job["id"], counts, i)) for i in range(watchers)]
    for t in threads:
        t.start()
    time.sleep(0.2)  # every watcher connected
    srv.api.delete(f"/api/jobs/{blocker['id']}")  # the job starts now
    status = srv.api.wait(job["id"], "done", timeout=300, poll=0.1)
    for t in threads:
        t.join(60)
    return status["samples"] / status["elapsed"], (statistics.median(counts) if counts else 0)


def peak_rss(tmp, name, threads, contract, stalled):
    """The server's VmHWM (MiB) after a longer job, with or without a watcher that never reads."""
    srv = start(tmp, name, threads, contract)
    try:
        blocker = srv.api.submit(BLOCKER)
        srv.api.wait(blocker["id"], "running")
        job = srv.api.submit(LONG_JOB)
        sock = None
        if stalled:
            sock = socket.socket()
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1024)
            sock.connect(("127.0.0.1", srv.port))
            sock.sendall(f"GET /api/jobs/{job['id']}/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())
        srv.api.delete(f"/api/jobs/{blocker['id']}")
        srv.api.wait(job["id"], "done", timeout=600, poll=0.1)
        status = (Path("/proc") / str(srv.proc.pid) / "status").read_text()
        hwm = next(int(l.split()[1]) for l in status.splitlines() if l.startswith("VmHWM:"))
        if sock:
            sock.close()
        return hwm / 1024.0
    finally:
        srv.kill()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, default=2, help="render threads of the server (default 2)")
    ap.add_argument("--runs", type=int, default=3, help="throughput runs per watcher count (median)")
    args = ap.parse_args()
    contract = Contract.load()
    started, steps, done = time.monotonic(), 5 + 2 * args.runs + 2, 0

    def step(label):
        nonlocal done
        progress(label, done / steps, started)
        done += 1

    with tempfile.TemporaryDirectory(prefix="server-bench-") as tmp:
        srv = start(tmp, "main", args.threads, contract)
        try:
            srv.api.post("/api/jobs/check", FIRST_TILE_JOB, expect=200)  # warm the scene cache
            lat = []
            for seed in range(1, 6):
                step("(a) first tile")
                lat.append(first_tile_latency(srv, seed))
            kinds = {k for _, k in lat}
            clear()
            print(f"(a) POST -> first tile event: median {statistics.median(t for t, _ in lat) * 1000:.1f} ms "
                  f"(5 runs: {', '.join(f'{t * 1000:.1f}' for t, _ in lat)} ms; first pixel event: {'/'.join(sorted(kinds))}; "
                  f"job {FIRST_TILE_JOB['width']}x{FIRST_TILE_JOB['height']}, {args.threads} threads)")
            rates, results = {}, {0: [], 10: []}
            for i in range(args.runs):  # interleaved, so a change in the machine's load hits both alike
                for watchers in results:
                    step(f"(b) {watchers} watchers")
                    results[watchers].append(throughput(srv, watchers, seed=10 + i))
            clear()
            for watchers, runs in results.items():
                rates[watchers] = statistics.median(r for r, _ in runs)
                sent = f"; {statistics.median(b for _, b in runs) / 1e6:.2f} MB to each watcher" if watchers else ""
                print(f"(b) throughput with {watchers:2d} watchers: {rates[watchers] / 1e6:.3f} M samples/s "
                      f"(median of {args.runs}: {', '.join(f'{r / 1e6:.3f}' for r, _ in runs)}{sent})")
            print(f"(b) ratio 10 watchers / 0 watchers: {rates[10] / rates[0]:.3f} "
                  f"(job {THROUGHPUT_JOB['width']}x{THROUGHPUT_JOB['height']}, {THROUGHPUT_JOB['spp']} spp, "
                  f"{THROUGHPUT_JOB['tile_size']}-pixel tiles)")
        finally:
            srv.kill()
        step("(c) peak RSS")
        plain = peak_rss(tmp, "rss-plain", args.threads, contract, stalled=False)
        step("(c) peak RSS, stalled")
        stalled = peak_rss(tmp, "rss-stalled", args.threads, contract, stalled=True)
        clear()
        print(f"(c) peak RSS (VmHWM) over a {LONG_JOB['width']}x{LONG_JOB['height']} {LONG_JOB['spp']} spp job: "
              f"{plain:.1f} MiB without a watcher, {stalled:.1f} MiB with one stalled watcher "
              f"({stalled - plain:+.1f} MiB)")


if __name__ == "__main__":
    main()
