#!/usr/bin/env python3
"""What watching a render costs it: samples/s of a 1024x1024 job with 0, 10 and 50 event-stream
watchers at render tile sizes 8, 32 and 128, each against the unloaded rate at the same tile size
(docs/reliability.md quotes the table; the target is at least 0.9 in every cell). The watchers read
raw bytes and parse nothing, at nice 19, so that the client's own CPU on this 2-core machine stays
out of the figure as far as it can. Run with the test venv:
    build/venv/bin/python bench/watcher_bench.py [--runs N] [--spp N] [--threads N]"""
import argparse
import os
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests/server"))
sys.path.insert(0, str(ROOT / "bench"))
from support import Contract, Server  # noqa: E402
from progress import clear, progress  # noqa: E402
from server_bench import BLOCKER, watch_raw  # noqa: E402

TILE_SIZES = (8, 32, 128)
WATCHERS = (0, 10, 50)


def run(srv, tile_size, watchers, spp, seed):
    """(samples/s, median MB received by a watcher) of one 1024x1024 job."""
    blocker = srv.api.submit(BLOCKER)
    srv.api.wait(blocker["id"], "running")
    job = srv.api.submit({"scene": "cornell", "width": 1024, "height": 1024, "spp": spp, "max_depth": 5,
                          "adaptive": False, "tile_size": tile_size, "seed": seed})
    counts = [0] * watchers
    threads = [threading.Thread(target=watch_raw, args=(srv.port, job["id"], counts, i)) for i in range(watchers)]
    for t in threads:
        t.start()
    time.sleep(0.3)  # every watcher connected before the job starts
    srv.api.delete(f"/api/jobs/{blocker['id']}")
    status = srv.api.wait(job["id"], "done", timeout=600, poll=0.2)
    for t in threads:
        t.join(120)
    return status["samples"] / status["elapsed"], (statistics.median(counts) / 1e6 if counts else 0.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3, help="runs per cell (median; default 3)")
    ap.add_argument("--spp", type=int, default=8, help="samples per pixel of the job (default 8)")
    ap.add_argument("--threads", type=int, default=2, help="render threads of the server (default 2)")
    args = ap.parse_args()
    os.nice(19)  # this process and its watcher threads: the server keeps its priority
    contract = Contract.load()
    cells = [(ts, w) for ts in TILE_SIZES for w in WATCHERS]
    rates = {c: [] for c in cells}
    sent = {c: [] for c in cells}
    started, total = time.monotonic(), len(cells) * args.runs
    with tempfile.TemporaryDirectory(prefix="watcher-bench-") as tmp:
        root = Path(tmp) / "server"
        root.mkdir()
        srv = Server(root, contract, threads=args.threads).start()
        try:
            for i in range(args.runs):  # interleaved: a change in the machine's load hits every cell alike
                for k, cell in enumerate(cells):
                    progress(f"tile {cell[0]}, {cell[1]} watchers", (i * len(cells) + k) / total, started)
                    rate, mb = run(srv, *cell, args.spp, seed=100 + i)
                    rates[cell].append(rate)
                    sent[cell].append(mb)
        finally:
            srv.kill()
    clear()
    print(f"1024x1024, {args.spp} spp, depth 5, cornell, {args.threads} render threads; median of {args.runs}")
    print("| tile size | watchers | M samples/s | of unloaded | MB to each watcher |")
    print("|---|---|---|---|---|")
    worst = 1.0
    for ts, w in cells:
        rate = statistics.median(rates[(ts, w)])
        ratio = rate / statistics.median(rates[(ts, 0)])
        worst = min(worst, ratio)
        mb = f"{statistics.median(sent[(ts, w)]):.1f}" if w else "-"
        print(f"| {ts} | {w} | {rate / 1e6:.3f} | {ratio:.2f} | {mb} |")
    print(f"worst cell: {worst:.2f} of the unloaded rate (target: at least 0.90)")


if __name__ == "__main__":
    main()
