#!/usr/bin/env python3
"""Render throughput under client load: 20 queued jobs rendered alone, then the same 20 jobs with
50 event-stream watchers and 4 clients polling status, each run on a fresh server. Prints samples
per second over the whole batch (first start to last finish), the poll latencies, and the server's
peak RSS (VmHWM) in each case. Watchers and pollers read raw bytes and parse nothing, and the
client process runs at the lowest CPU priority (nice 19): on one machine the load generator would
otherwise take its CPU from the renderer, which clients on other machines do not (--no-nice to
measure with it competing).
Run with the test venv:  build/venv/bin/python bench/load_bench.py [--threads N] [--runs N]"""
import argparse
import http.client
import json
import os
import socket
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests/server"))
from support import Contract, Server  # noqa: E402  (the tests' process helpers)

from progress import clear, progress  # noqa: E402

JOB = {"scene": "cornell", "width": 160, "height": 120, "spp": 32, "max_depth": 5, "adaptive": False, "tile_size": 16}
JOBS, WATCHERS, POLLERS = 20, 50, 4


NICE = True


def lower_priority():
    """This client thread at nice 19 (Linux priorities are per thread; the server keeps its own)."""
    if NICE:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)


def watch_raw(port, job_id, sizes, i):
    """Reads one job's event stream to its end event; records the bytes received."""
    lower_priority()
    with socket.create_connection(("127.0.0.1", port), timeout=600) as sock:
        sock.sendall(f"GET /api/jobs/{job_id}/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())
        tail, total = b"", 0
        while b"event: end" not in tail:
            chunk = sock.recv(1 << 16)
            if not chunk:
                break
            total += len(chunk)
            tail = (tail + chunk)[-256:]
        sizes[i] = total


def run_batch(tmp, name, threads, contract, loaded, seed):
    """(samples/s over the batch, poll latencies in s, MB sent to watchers, VmHWM MiB)."""
    root = Path(tmp) / name
    root.mkdir()
    srv = Server(root, contract, threads=threads, args=["--max-queue", "32"]).start()
    try:
        srv.api.post("/api/jobs/check", JOB, expect=200)  # the scene parsed once, before the clock
        ids = [srv.api.submit(dict(JOB, seed=seed * 100 + i))["id"] for i in range(JOBS)]
        stop = threading.Event()
        sizes, latencies, threads_ = [0] * WATCHERS, [], []
        if loaded:
            threads_ += [threading.Thread(target=watch_raw, args=(srv.port, ids[i % JOBS], sizes, i))
                         for i in range(WATCHERS)]

            def poll(k):
                lower_priority()
                conn = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=30)
                n = 0
                while not stop.is_set():
                    t0 = time.perf_counter()
                    conn.request("GET", "/api/jobs" if n % 3 == 0 else f"/api/jobs/{ids[(k + n) % JOBS]}")
                    resp = conn.getresponse()
                    resp.read()
                    assert resp.status == 200, resp.status
                    latencies.append(time.perf_counter() - t0)
                    n += 1
                    time.sleep(0.05)

            threads_ += [threading.Thread(target=poll, args=(k,)) for k in range(POLLERS)]
        for t in threads_:
            t.start()
        # The batch's end, watched as cheaply as the pollers watch (no schema validation here).
        deadline = time.monotonic() + 900
        watch = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=30)
        while time.monotonic() < deadline:
            watch.request("GET", "/api/jobs")
            listed = json.loads(watch.getresponse().read())["jobs"]
            if all(j["state"] == "done" for j in listed if j["id"] in ids):
                break
            time.sleep(0.25)
        watch.close()
        stop.set()
        for t in threads_:
            t.join(120)
        jobs = [srv.api.job(i) for i in ids]
        assert all(j["state"] == "done" for j in jobs), "the batch did not finish"
        span = max(j["finished_at"] for j in jobs) - min(j["started_at"] for j in jobs)
        rate = sum(j["samples"] for j in jobs) / span
        return rate, latencies, sum(sizes) / 1e6, srv.rss_kib("VmHWM") / 1024.0
    finally:
        srv.kill()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, default=2, help="render threads of the server (default 2)")
    ap.add_argument("--runs", type=int, default=3, help="batches per case, interleaved (median)")
    ap.add_argument("--no-nice", action="store_true", help="run the load generator at normal priority")
    args = ap.parse_args()
    global NICE
    NICE = not args.no_nice
    contract = Contract.load()
    results = {False: [], True: []}
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="load-bench-") as tmp:
        for i in range(args.runs):  # interleaved, so a change in the machine's load hits both alike
            for loaded in (False, True):
                progress(f"batch {'with load' if loaded else 'alone'}", (2 * i + loaded) / (2 * args.runs), started)
                results[loaded].append(run_batch(tmp, f"{'loaded' if loaded else 'alone'}-{i}", args.threads,
                                                 contract, loaded, seed=i + 1))
    clear()
    rate = {k: statistics.median(r[0] for r in v) for k, v in results.items()}
    hwm = {k: max(r[3] for r in v) for k, v in results.items()}
    lat = sorted(x for r in results[True] for x in r[1])
    print(f"batch: {JOBS} jobs of {JOB['width']}x{JOB['height']}, {JOB['spp']} spp, {args.threads} render threads; "
          f"load: {WATCHERS} watchers, {POLLERS} pollers (one request every 50 ms each)")
    for loaded in (False, True):
        runs = ", ".join(f"{r[0] / 1e6:.3f}" for r in results[loaded])
        print(f"throughput {'with load' if loaded else 'alone    '}: {rate[loaded] / 1e6:.3f} M samples/s "
              f"(median of {args.runs}: {runs}); peak RSS {hwm[loaded]:.1f} MiB")
    print(f"ratio with load / alone: {rate[True] / rate[False]:.3f}")
    if lat:
        print(f"poll latency under load: median {statistics.median(lat) * 1000:.1f} ms, "
              f"p99 {lat[int(0.99 * (len(lat) - 1))] * 1000:.1f} ms, max {lat[-1] * 1000:.1f} ms over {len(lat)} polls; "
              f"{statistics.median(r[2] for r in results[True]):.1f} MB streamed to the watchers per batch")


if __name__ == "__main__":
    main()
