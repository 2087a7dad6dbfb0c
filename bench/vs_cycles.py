#!/usr/bin/env python3
"""glTF scenes as Blender renders them (issue #52): each .glb rendered by our `pathtracer` and by
Cycles (Blender as a Python module, its own glTF importer), compared on brightness and efficiency.

    python3 bench/vs_cycles.py [SCENE.glb ...] [--spp 256] [--cycles-spp 512] [--ref-spp 4096]
                               [--res 320 240] [--depth 8] [--threads 2] [--runs 3] [--cells]
                               [--cycles-variant front-emission,emission-only,lambert,no-specular]
                               [--ours=--no-caustic-tracing]

Without scenes: scenes/cornell_gltf.glb and every .glb of build/cycles-scenes (written first by
bench/blender_scenes.py when that folder is absent). Per scene it prints a markdown row: the mean
luminance of our converged render over Cycles' (1.00 = as bright), the 4x4 cell of the image whose
mean luminance ratio deviates most from 1 (signed, with its row and column from the top left), and
each renderer's efficiency 1/(relMSE x seconds), relMSE as the renderer's own (luminance, eps 0.01)
against that renderer's own reference (--ref-spp, another seed), scaled by ref/(ref + spp) to take
out the reference's own noise. Seconds are rendering only: our summary line's (no scene load),
Cycles' first to last sample as its progress reports them (no sync, BVH build or saving).

Cycles (bench/cycles_render.py): CPU, --threads threads, no clamping, blur_glossy 0, light
threshold 0, one-pixel box filter, Standard view, linear float EXR, no denoising, no adaptive
sampling, no path guiding, fixed seeds; max bounces (every kind) = our -m - 1, since -m 1 is direct
light and Cycles' 0 bounces is too. The world is black, or uniform white unseen by the camera for a
file without lights (our default light). Ours: --no-adaptive, same threads, size, depth and seeds.
--cycles-variant changes the imported scene to test one convention at a time (cycles_render.py's
VARIANTS). References are cached in build/bench-cache, keyed on the scene's and the binary's content.

bpy comes from PyPI into build/cycles-venv (bpy 5.0.1 for Python 3.11, with numpy); EXRs are read
with the OpenImageIO module the bpy wheel bundles.
"""
import argparse
import hashlib
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from host import host_description
from progress import clear, progress

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build"
VENV = BUILD / "cycles-venv"
BPY_VERSION = "5.0.1"
BPY = f"bpy=={BPY_VERSION}"
LUMA = (0.2126, 0.7152, 0.0722)
EPS = 0.01  # relative MSE's denominator floor, as renderer/util/image.cpp's


def ensure_venv():
    """Re-runs this script inside build/cycles-venv, creating it when missing."""
    py = VENV / "bin" / "python"
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    check = f"import bpy, numpy; assert bpy.app.version_string == '{BPY_VERSION}'"
    if not py.exists() or subprocess.run([str(py), "-c", check], capture_output=True).returncode:
        print(f"vs_cycles: installing {BPY} into {VENV}", file=sys.stderr)
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
        subprocess.run([str(py), "-m", "pip", "install", "-q", BPY, "numpy"], check=True)
    os.execv(str(py), [str(py), *sys.argv])


# ---------------------------------------------------------------------------------------------
# The report's arithmetic: plain Python on luminance images given as lists of rows (top row first).


def luminance_rows(rgb_rows):
    """Rec. 709 luminance of an image of (r, g, b) rows."""
    return [[LUMA[0] * p[0] + LUMA[1] * p[1] + LUMA[2] * p[2] for p in row] for row in rgb_rows]


def mean(lum):
    return sum(sum(row) for row in lum) / sum(len(row) for row in lum)


def cell_means(lum, n=4):
    """Mean luminance of each of n x n cells (rows of cells, top first); cell edges at
    floor(i * size / n), so every pixel is in exactly one cell."""
    h, w = len(lum), len(lum[0])
    ys = [i * h // n for i in range(n + 1)]
    xs = [i * w // n for i in range(n + 1)]
    out = []
    for r in range(n):
        band = lum[ys[r]:ys[r + 1]]
        out.append([sum(sum(row[xs[c]:xs[c + 1]]) for row in band) / (len(band) * (xs[c + 1] - xs[c]))
                    for c in range(n)])
    return out


def ratio(a, b):
    """a / b, with 0 / 0 = 1 (both black) and a / 0 = inf."""
    if b == 0:
        return 1.0 if a == 0 else float("inf")
    return a / b


def worst_cell(ours, theirs, n=4):
    """The cell whose mean-luminance ratio ours / theirs is farthest from 1: (ratio - 1, row, column)."""
    a, b = cell_means(ours, n), cell_means(theirs, n)
    cells = [(ratio(a[r][c], b[r][c]) - 1, r, c) for r in range(n) for c in range(n)]
    return max(cells, key=lambda cell: abs(cell[0]))


def cell_ratios(ours, theirs, n=4):
    a, b = cell_means(ours, n), cell_means(theirs, n)
    return [[ratio(a[r][c], b[r][c]) for c in range(n)] for r in range(n)]


def rel_mse(img, ref, spp=None, ref_spp=None):
    """renderer/util/image.cpp's relative MSE on luminance, mean of (img - ref)^2 / (ref^2 + 0.01).
    With spp and ref_spp, scaled by ref_spp / (ref_spp + spp): the reference's own noise (the same
    renderer's, spp / ref_spp of the image's variance) taken out."""
    total, count = 0.0, 0
    for row_i, row_r in zip(img, ref):
        for a, b in zip(row_i, row_r):
            total += (a - b) ** 2 / (b * b + EPS)
        count += len(row_r)
    err = total / count
    if spp and ref_spp:
        err *= ref_spp / (ref_spp + spp)
    return err


def bounces_for_depth(depth):
    """Cycles' max bounces for our -m: ours counts ray levels (-m 1 = direct light: the camera ray
    and its hit's shadow and BSDF rays), Cycles the bounces after the first hit (0 = direct light),
    every kind alike (diffuse, glossy, transmission). -m 0 (emitters only) has no Cycles match."""
    if depth < 1:
        raise ValueError("our -m 0 (emitters only) has no Cycles equivalent: use -m 1 or more")
    return depth - 1


def efficiency(err, seconds):
    """1 / (relMSE x seconds): higher is better; a noise-free render counts as infinitely efficient."""
    return float("inf") if err * seconds == 0 else 1.0 / (err * seconds)


TABLE_HEAD = ("| scene | -m | mean luminance ours / Cycles | worst 4x4 cell (row, col) | ours: s, relMSE, efficiency "
              "| Cycles: s, relMSE, efficiency | efficiency ours / Cycles |\n|---|---|---|---|---|---|---|")


def table_row(r):
    """One markdown row from a result dict: name, depth, mean_o, mean_c, cell (dev, row, col), and
    when timed o_sec, o_err, c_sec, c_err."""
    dev, row, col = r["cell"]
    cols = [r["name"], str(r["depth"]), f"{ratio(r['mean_o'], r['mean_c']):.3f}", f"{100 * dev:+.1f}% ({row}, {col})"]
    if r.get("o_sec") is None:
        cols += ["", "", ""]
    else:
        eo, ec = efficiency(r["o_err"], r["o_sec"]), efficiency(r["c_err"], r["c_sec"])
        cols += [f"{r['o_sec']:.2f} s, {r['o_err']:.2e}, {eo:.1f}", f"{r['c_sec']:.2f} s, {r['c_err']:.2e}, {ec:.1f}",
                 f"{ratio(eo, ec):.2f}x"]
    return "| " + " | ".join(cols) + " |"


def cells_text(ours, theirs, n=4):
    """The n x n grid of cell ratios ours / Cycles, one line a row."""
    return ["  " + "  ".join(f"{v:6.3f}" for v in row) for row in cell_ratios(ours, theirs, n)]


# ---------------------------------------------------------------------------------------------
# Running the renderers.


def digest(paths):
    """A short content hash: the cached references are keyed on what made them."""
    h = hashlib.sha1()
    for p in paths:
        h.update(Path(p).read_bytes())
    return h.hexdigest()[:10]


def run_ours(args, scene, spp, out, seed, extra=()):
    """Our render's seconds, from its summary line (rendering only, not the scene's load)."""
    cmd = [str(args.pathtracer), "-t", str(args.threads), "-s", str(spp), "-m", str(args.depth),
           "-r", str(args.res[0]), str(args.res[1]), "--no-adaptive", "--quiet", "--seed", str(seed),
           *extra, "-f", str(out), str(scene)]
    text = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    m = re.search(r"([\d.]+) s, ([\d.e+]+) samples/s", text)
    if not m:
        raise SystemExit(f"vs_cycles: no summary line from {' '.join(cmd)}:\n{text}")
    return float(m.group(1))


def default_scenes():
    folder = BUILD / "cycles-scenes"
    if not folder.is_dir():
        print(f"vs_cycles: writing the Blender scenes into {folder}", file=sys.stderr)
        subprocess.run([sys.executable, str(ROOT / "bench" / "blender_scenes.py"), str(folder)], check=True)
    return [ROOT / "scenes" / "cornell_gltf.glb", *sorted(folder.glob("*.glb"))]


class Work:
    """The progress bar's account, in Cycles samples per pixel: one of ours costs OURS_COST of one
    (about what each takes on the Cornell box), so that the ETA weighs each render by its cost."""
    OURS_COST = 0.3

    def __init__(self, args, scenes):
        per_scene = (1 + self.OURS_COST) * args.ref_spp + args.runs * (args.cycles_spp + self.OURS_COST * args.spp)
        self.total, self.done, self.started = per_scene * len(scenes), 0.0, time.monotonic()

    def show(self, label, part=0.0):
        progress(label, (self.done + part) / self.total, started=self.started)

    def finish(self, amount, skipped=False):
        """A render of `amount` done, or found in the cache (then it leaves the account)."""
        if skipped:
            self.total -= amount
        else:
            self.done += amount


def compare(args, cr, np, scene, cache, ours_bin, work):
    """References (cached), timed runs and the numbers of one scene."""
    name = scene.stem
    variants = [v for v in args.cycles_variant.split(",") if v]
    w, h = args.res
    tag = f"{name}-{digest([scene])}-{w}x{h}-m{args.depth}-{args.ref_spp}"
    info = cr.load_glb(scene, variants)
    cr.configure(w, h, bounces_for_depth(args.depth), args.threads)
    lum = lambda img: (img[..., :3] @ np.array(LUMA)).tolist()  # noqa: E731

    def cycles(out, spp, seed, label):
        sec = cr.render(out, spp, seed, lambda f: work.show(label, f * spp))
        work.finish(spp)
        return sec

    def ours(out, spp, seed, label, extra=()):
        work.show(label)
        sec = run_ours(args, scene, spp, out, seed, extra)
        work.finish(work.OURS_COST * spp)
        return sec

    c_ref_path = cache / f"cycles-{BPY_VERSION}-{tag}-{'+'.join(variants) or 'plain'}.exr"
    if c_ref_path.exists():
        work.finish(args.ref_spp, skipped=True)
    else:
        cycles(c_ref_path, args.ref_spp, 7919, f"{name}: Cycles reference")
    o_ref_path = cache / f"ours-{tag}-{ours_bin}.exr"
    if o_ref_path.exists():
        work.finish(work.OURS_COST * args.ref_spp, skipped=True)
    else:
        ours(o_ref_path, args.ref_spp, 7919, f"{name}: our reference")
    c_ref, o_ref = lum(cr.read_exr(c_ref_path)), lum(cr.read_exr(o_ref_path))
    row = dict(name=name, depth=args.depth, mean_o=mean(o_ref), mean_c=mean(c_ref), cell=worst_cell(o_ref, c_ref),
               info=info, cells=cells_text(o_ref, c_ref))
    if args.runs:
        ct, ce, ot, oe = [], [], [], []
        out_c, out_o = cache / f"cycles-{name}-run.exr", cache / f"ours-{name}-run.exr"
        for k in range(args.runs):
            ct.append(cycles(out_c, args.cycles_spp, 100 + k, f"{name}: Cycles"))
            ce.append(rel_mse(lum(cr.read_exr(out_c)), c_ref, args.cycles_spp, args.ref_spp))
            ot.append(ours(out_o, args.spp, 100 + k, f"{name}: ours", args.ours.split()))
            oe.append(rel_mse(lum(cr.read_exr(out_o)), o_ref, args.spp, args.ref_spp))
        row.update(c_sec=statistics.median(ct), c_err=statistics.median(ce), o_sec=statistics.median(ot),
                   o_err=statistics.median(oe))
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", type=Path, help=".glb files (default: cornell_gltf and build/cycles-scenes)")
    ap.add_argument("--spp", type=int, default=256, help="our samples per pixel in the timed runs")
    ap.add_argument("--cycles-spp", type=int, default=512, help="Cycles' samples per pixel in the timed runs")
    ap.add_argument("--ref-spp", type=int, default=4096, help="both references' samples per pixel")
    ap.add_argument("--res", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    ap.add_argument("--depth", type=int, default=8, help="our -m (Cycles: max bounces -m - 1)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--runs", type=int, default=3, help="timed runs per renderer (medians); 0: references only")
    ap.add_argument("--cells", action="store_true", help="also print each scene's 4x4 grid of cell ratios")
    ap.add_argument("--cycles-variant", default="", help="comma-separated cycles_render.VARIANTS")
    ap.add_argument("--ours", default="", help="extra pathtracer flags for our timed runs")
    ap.add_argument("--pathtracer", type=Path, default=BUILD / "pathtracer")
    args = ap.parse_args()
    if not args.pathtracer.exists():
        sys.exit(f"vs_cycles: {args.pathtracer} is absent: build it first")
    if args.depth < 1:
        sys.exit("vs_cycles: --depth 0 (emitters only) has no Cycles equivalent")
    ensure_venv()
    import numpy as np
    import cycles_render as cr
    scenes = args.scenes or default_scenes()
    missing = [s for s in scenes if not s.exists()]
    if missing:
        sys.exit(f"vs_cycles: {missing[0]} is absent")
    cache = BUILD / "bench-cache"
    cache.mkdir(parents=True, exist_ok=True)
    print(f"vs_cycles: host {host_description()}")
    print(f"vs_cycles: {args.res[0]}x{args.res[1]}, -m {args.depth} (Cycles max bounces {bounces_for_depth(args.depth)}), "
          f"{args.threads} threads; timed: ours {args.spp} spp, Cycles {args.cycles_spp} spp, medians of {args.runs}; "
          f"references {args.ref_spp} spp; Blender {BPY_VERSION} Cycles CPU"
          + (f"; Cycles variants {args.cycles_variant}" if args.cycles_variant else "")
          + (f"; ours with {args.ours}" if args.ours else ""))
    work, rows = Work(args, scenes), []
    for scene in scenes:
        rows.append(compare(args, cr, np, scene.resolve(), cache, digest([args.pathtracer]), work))
        clear()
        r = rows[-1]
        print(f"{r['name']}: lights {', '.join(r['info']['lights']) or 'none'}; emissive "
              f"{', '.join(r['info']['emissive']) or 'none'}; world {r['info']['world']}")
        if args.cells:
            print("\n".join(r["cells"]))
    print()
    print(TABLE_HEAD)
    for r in rows:
        print(table_row(r))


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    main()
    # bpy's add-ons run update callbacks on a scene being torn down at interpreter exit: noise.
    sys.stdout.flush()
    os._exit(0)
