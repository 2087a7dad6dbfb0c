#!/usr/bin/env python3
"""Scale-out benchmark (docs/scale-out.md): samples/s of one job rendered by the embedded server and
by 1, 2 and 3 render-workers over a local redis-server, with the server's merge cost per pass.
On one machine the workers share its cores, so this measures overhead, not speed-up.

    python3 bench/scale_out_bench.py [--build build] [--runs 3] [--spp 64] [--size 480x360]
"""
import argparse
import json
import os
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

from progress import clear, progress

ROOT = Path(__file__).resolve().parents[1]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def http(url, body=None):
    req = urllib.request.Request(url, data=json.dumps(body).encode() if body else None,
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=30) as r:
        return json.loads(r.read())


def run_job(build, tmp, spec, queue_url, workers, threads, label):
    """One job on a fresh server; returns (seconds, samples, merge line or None)."""
    port = free_port()
    log = open(tmp / f"server-{label}.log", "wb")
    args = [str(build / "render-server"), "--port", str(port), "--data", str(tmp / f"data-{label}"),
            "--threads", str(threads)]
    if queue_url:
        args += ["--queue", queue_url, "--units-in-flight", str(max(2, 2 * workers))]
    server = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=log)
    server.stdout.readline()
    procs = [subprocess.Popen([str(build / "render-worker"), "--queue", queue_url, "-t", str(threads), "--quiet",
                               "--name", f"{label}-{i}"], stderr=subprocess.DEVNULL) for i in range(workers)]
    try:
        time.sleep(0.3)  # workers connected
        base = f"http://127.0.0.1:{port}"
        t0 = time.monotonic()
        job = http(base + "/api/jobs", spec)
        while job["state"] not in ("done", "failed", "cancelled"):
            time.sleep(0.05)
            job = http(base + f"/api/jobs/{job['id']}")
            progress(label, job["progress"], t0)
        seconds = time.monotonic() - t0
        assert job["state"] == "done", job
    finally:
        for p in procs:
            p.terminate()
        server.terminate()
        server.wait(20)
        for p in procs:
            p.wait(20)
        log.close()
    text = (tmp / f"server-{label}.log").read_text()
    m = re.search(r"(\d+) passes merged in ([\d.]+) s \(([\d.]+) ms and ([\d.]+) MB a pass\).*spp a pass: ([\d ]+)",
                  text)
    return seconds, job["samples"], m.groups() if m else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=str(ROOT / "build"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--size", default="480x360")
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    a = ap.parse_args()
    build = Path(a.build)
    w, h = map(int, a.size.split("x"))
    spec = {"scene": "cornell", "width": w, "height": h, "spp": a.spp, "max_depth": 5, "adaptive": False, "seed": 1}
    if not shutil.which("redis-server"):
        sys.exit("redis-server is missing: run scripts/install-deps.sh")
    tmp = Path(tempfile.mkdtemp(prefix="scale-out-bench-"))
    rport = free_port()
    redis = subprocess.Popen(["redis-server", "--port", str(rport), "--bind", "127.0.0.1", "--save", "",
                              "--appendonly", "no", "--dir", str(tmp)], stdout=subprocess.DEVNULL)
    time.sleep(0.5)
    url = f"redis://127.0.0.1:{rport}"
    print(f"job: cornell {w}x{h}, {a.spp} spp, max depth 5, adaptive off; {a.threads} threads per process; "
          f"median of {a.runs} runs")
    print(f"{'setup':<14} {'seconds':>8} {'Msamples/s':>11} {'vs embedded':>12} {'passes':>7} {'merge ms/pass':>14} {'MB/pass':>8}")
    try:
        setups = [("embedded", 0), ("1 worker", 1), ("2 workers", 2), ("3 workers", 3)]
        runs = {label: [] for label, _ in setups}
        for _ in range(a.runs):  # interleaved, so that the machine's drift spreads over every setup
            for label, workers in setups:
                runs[label].append(run_job(build, tmp, spec, url if workers else None, workers, a.threads,
                                           label.replace(" ", "-")))
        clear()
        baseline, sizes = None, {}
        for label, _ in setups:
            sec = statistics.median(r[0] for r in runs[label])
            rate = runs[label][0][1] / sec / 1e6
            baseline = baseline or rate
            merges = [r[2] for r in runs[label] if r[2]]
            passes, merge_ms, mb = "-", "-", "-"
            if merges:
                passes = merges[len(merges) // 2][0]
                merge_ms = f"{statistics.median(float(m[2]) for m in merges):.2f}"
                mb = merges[0][3]
                sizes[label] = merges[-1][4].strip()
            print(f"{label:<14} {sec:8.2f} {rate:11.2f} {rate / baseline:11.2f}x {passes:>7} {merge_ms:>14} {mb:>8}",
                  flush=True)
        for label, s in sizes.items():
            print(f"spp a pass, {label}: {s}")
    finally:
        redis.kill()
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
