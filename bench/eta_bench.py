#!/usr/bin/env python3
"""How honest the pathtracer's ETA is under adaptive sampling (issue 41): for each scene, rendered
with the default settings (adaptive sampling on), the ETA's relative error against the time the run
actually had left, at 10%, 25%, 50% and 75% of its wall time; before (the sample budget's fraction
p: elapsed x (1 - p) / p) and after (ProgressEstimate, renderer/driver.h).

    python3 bench/eta_bench.py [--scenes CBspheres_lambertian,cornell] [--spp 1024] [--runs 1]
                               [--size 240 180] [--threads 2] [--keep-logs DIR]

Each run writes `--progress-log` (seconds, progress, ETA, the budget's fraction, samples taken and
predicted still to take at the last pass's end); the ETA read at a mark is the last row's at or
before it, as the bar showed it then. `work` is the samples predicted in all at 25% of the run
(taken + left) against those the run took. Course scenes come from ../shared/scenes-cs184/
(skipped with a line when absent), ours from scenes/. With --runs N each cell is the median.
"""
import argparse
import csv
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from host import host_description
from progress import clear, progress

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "scenes-cs184"
# name: (file, extra flags); depth 5 everywhere
SCENES = {
    "CBspheres_lambertian": (SHARED / "CBspheres_lambertian.dae", []),
    "CBspheres": (SHARED / "CBspheres.dae", []),
    "CBbunny": (SHARED / "CBbunny.dae", []),
    "CBdragon": (SHARED / "CBdragon.dae", []),
    "cornell": (ROOT / "scenes" / "cornell.dae", []),
    "dof": (ROOT / "scenes" / "dof.dae", ["-b", "0.12", "-d", "4.7"]),
}
MARKS = (0.10, 0.25, 0.50, 0.75)
GOAL = 0.25  # |relative error| from the 25% mark on


def read_log(path):
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def errors(rows):
    """Relative ETA errors (old, new) at each mark, and the work predicted at 25% over the work done."""
    end = rows[-1]["seconds"]
    taken = rows[-1]["samples"]
    out = []
    for mark in MARKS:
        at = [r for r in rows if r["seconds"] <= mark * end]
        if not at:
            out.append((None, None))
            continue
        r = at[-1]
        left = end - r["seconds"]
        b = r["budget_progress"]
        old = r["seconds"] * (1 - b) / b if b > 0 else None
        new = r["eta"] if r["eta"] >= 0 else None
        out.append(tuple(None if e is None or left <= 0 else e / left - 1 for e in (old, new)))
    at25 = [r for r in rows if r["seconds"] <= 0.25 * end and r["pass_end"] == 1]
    work = (at25[-1]["samples"] + at25[-1]["samples_left"]) / taken - 1 if at25 and taken > 0 else None
    return end, out, work


def run_scene(args, name, path, extra, log):
    cmd = [str(ROOT / "build" / "pathtracer"), "-t", str(args.threads), "-s", str(args.spp), "-m", "5",
           "-r", str(args.size[0]), str(args.size[1]), "--quiet", "--progress-log", str(log),
           "-f", str(log.with_suffix(".png")), *extra, str(path)]
    subprocess.run(cmd, check=True, capture_output=True)
    return errors(read_log(log))


def pct(v):
    return "?" if v is None else f"{100 * v:+.0f}%"


def median(vs):
    vs = [v for v in vs if v is not None]
    return statistics.median(vs) if vs else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--size", type=int, nargs=2, default=[240, 180])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--keep-logs", default="", help="keep each run's progress log and image in this folder")
    args = ap.parse_args()
    names = [n for n in args.scenes.split(",") if n]
    for n in names:
        if n not in SCENES:
            sys.exit(f"eta_bench: unknown scene {n} (known: {', '.join(SCENES)})")
    if not SHARED.exists():
        print("eta_bench: skipping the course scenes: ../shared/scenes-cs184 is absent")
        names = [n for n in names if not str(SCENES[n][0]).startswith(str(SHARED))]
    print(f"eta_bench: host {host_description()}")
    print(f"eta_bench: -t {args.threads} -s {args.spp} -m 5 -r {args.size[0]} {args.size[1]}, adaptive sampling on "
          f"(defaults), {args.runs} run(s) a scene; ETA error = ETA / time actually left - 1")
    folder = Path(args.keep_logs) if args.keep_logs else Path(tempfile.mkdtemp(prefix="eta_bench."))
    folder.mkdir(parents=True, exist_ok=True)
    started = time.monotonic()
    results = {}
    for i, name in enumerate(names):
        path, extra = SCENES[name]
        runs = []
        for k in range(args.runs):
            progress(f"{name} ({k + 1}/{args.runs})", (i * args.runs + k) / (len(names) * args.runs), started)
            runs.append(run_scene(args, name, path, extra, folder / f"{name}.{k}.csv"))
        results[name] = runs
    clear()
    marks = " ".join(f"{int(100 * m):>13}%" for m in MARKS)
    print(f"{'scene':<22} {'seconds':>7} {marks}  work@25%")
    print(f"{'':<22} {'':>7} " + " ".join(f"{'old / new':>14}" for _ in MARKS))
    worst = (0.0, "")
    for name, runs in results.items():
        cells = []
        for j, mark in enumerate(MARKS):
            old, new = median([r[1][j][0] for r in runs]), median([r[1][j][1] for r in runs])
            cells.append(f"{pct(old):>6} / {pct(new):>5}")
            if mark >= 0.25:
                bad = 1.0 if new is None else abs(new)
                if bad > worst[0]:
                    worst = (bad, f"{name} at {int(100 * mark)}%")
        seconds = median([r[0] for r in runs])
        print(f"{name:<22} {seconds:>7.1f} {' '.join(cells)}  {pct(median([r[2] for r in runs])):>7}")
    verdict = "met" if worst[0] <= GOAL else "not met"
    print(f"target: ETA within {int(100 * GOAL)}% of the time left from 25% of the run on: {verdict} on this host"
          + (f" (worst {100 * worst[0]:.0f}%: {worst[1]})" if worst[1] else ""))
    if not args.keep_logs:
        for f in folder.iterdir():
            f.unlink()
        folder.rmdir()


if __name__ == "__main__":
    main()
