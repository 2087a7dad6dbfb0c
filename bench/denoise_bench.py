#!/usr/bin/env python3
"""Time to a relative MSE of 1e-2 and 1e-3, raw and denoised, for our pathtracer and for Cycles.

Our `pathtracer` with and without --denoise (Intel Open Image Denoise) and Cycles with and without
its own Open Image Denoise, on the same scenes, on this machine, in one run.

    python3 bench/denoise_bench.py [SCENE.glb ...] [--scenes CBspheres,CBbunny,CBdragon,dof,cornell_gltf]
                                   [--res 200 150] [--depth M] [--threads 2] [--spp 1024] [--ref-spp 1024]
                                   [--cycles-max-spp 256] [--curves] [--quick] [--pathtracer PATH]

Scenes: vs_mitsuba.py's course scenes (CBspheres, CBbunny, CBdragon and our dof.dae, with its flags:
-l 1, -m 5, the thin lens of dof) and scenes/cornell_gltf.glb (-m 8), plus any .glb given. Course
scenes are framed as vs_mitsuba.py's course crop at its 480x360; at another size that crop would
shrink, so --frame-scene fits the same view direction to the box instead. Cycles reads only glTF,
so its columns are filled for .glb scenes alone (vs_cycles.py's settings, cycles_render.py).

Ours: one run of --spp samples, --no-adaptive (passes of 1, 2, 4, ... spp), --seed 1, --denoise,
--error-log and --reference: each pass's row gives the render time so far (the per-pass denoising
not included) and the relative MSE of the raw image, and the time to denoise that pass's film with
the final-quality filter (albedo and normal cleaned first, as Cycles' ACCURATE prefilter) and the
denoised image's relative MSE. Raw time = seconds; denoised time = seconds + that row's
denoise_seconds. Our first denoise also creates the OIDN device (the filters are kept between
passes), which the report shows beside the median.

Cycles: separate renders at 1, 2, 4, ... --cycles-max-spp spp, seed 1, once with denoising off and
once with Blender's final-render denoising (cycles_render.set_denoising). Raw time is Cycles' first
to last sample, as vs_cycles.py measures it. Cycles in bpy reports its progress rarely and says
nothing when denoising starts, so the denoised time runs from its first sample to its "Finished"
(the status it sets when the session's work, denoising included, is done): path tracing with the
albedo and normal passes, plus the denoising; sync, BVH build, kernel loading and saving excluded
on both sides. The report gives the median extra time of a denoised render over the raw one.

Errors: relative MSE (luminance, eps 0.01, renderer/util/image.cpp's) against each renderer's own
reference (--ref-spp, another seed: ours --seed 7, Cycles vs_cycles.py's 7919; cached in
build/bench-cache, keyed on the scene's and the binary's bytes and the flags). A reference of R spp
adds its own noise, s/R of an s-spp raw image's variance: raw errors are scaled by R/(R + s), as
vs_cycles.py does, and the same estimate of the reference's noise (raw error x s/(R + s), from the
raw image of the same spp) is subtracted from the denoised error of that spp, whose own error does
not shrink as 1/s. A denoised error at or below that estimate is below what the reference can
measure: it counts as reached, at that row's time, not interpolated.

Time to an error E: the first two rows whose errors bracket E, interpolated linearly in log(time)
against log(error); "> T" when no row reaches E (T the last row's time), "<= T" when the first does.
"""
import argparse
import csv
import hashlib
import io
import math
import os
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import vs_cycles as vc  # noqa: E402
import vs_mitsuba as vm  # noqa: E402
from host import host_description  # noqa: E402
from progress import clear, progress  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build"
CACHE = BUILD / "bench-cache"
GLB_SCENES = {"cornell_gltf": ROOT / "scenes" / "cornell_gltf.glb"}
GLB_DEPTH = 8
TARGETS = (1e-2, 1e-3)
REF_SEED, RUN_SEED, CYCLES_REF_SEED = 7, 1, 7919
LOG_COLUMNS = ("seconds", "spp", "rel_mse", "denoise_seconds", "denoised_rel_mse")
QUICK = dict(res=(64, 48), spp=64, ref_spp=64, cycles_max_spp=8)
DEFAULTS = dict(res=(200, 150), spp=1024, ref_spp=1024, cycles_max_spp=256)


# ---------------------------------------------------------------------------------------------
# The report's arithmetic: pure functions on the error log's rows and (seconds, error) points.


def parse_error_log(text):
    """The rows of `pathtracer --error-log F --reference R --denoise` as dicts of floats (the columns
    LOG_COLUMNS); a missing or unparsable value reads NaN."""
    reader = csv.DictReader(io.StringIO(text))
    missing = [c for c in LOG_COLUMNS if c not in (reader.fieldnames or ())]
    if missing:
        raise ValueError(f"the error log has no column {missing[0]} (header: {','.join(reader.fieldnames or [])}): "
                         "a pathtracer with --denoise, run with --reference, writes it")

    def number(v):
        try:
            return float(v)
        except (TypeError, ValueError):
            return math.nan

    return [{c: number(row.get(c)) for c in LOG_COLUMNS + ("preview_denoise_seconds", "preview_rel_mse")}
            for row in reader]


def reference_noise(raw_err, spp, ref_spp):
    """The reference's share of a raw error measured at spp against an ref_spp reference of the same
    renderer (both unbiased, independent): the measured error is v/spp + v/ref_spp."""
    return raw_err * spp / (ref_spp + spp)


def corrected(raw_err, den_err, spp, ref_spp):
    """(raw, denoised) errors with the reference's noise taken out, as estimated from the raw error."""
    noise = reference_noise(raw_err, spp, ref_spp)
    return raw_err - noise, den_err - noise


def curves(rows, ref_spp):
    """Our raw and denoised (seconds, corrected relative MSE) points, one a pass, from the log's rows."""
    raw, den = [], []
    for r in rows:
        e_raw, e_den = corrected(r["rel_mse"], r["denoised_rel_mse"], r["spp"], ref_spp)
        raw.append((r["seconds"], e_raw))
        den.append((r["seconds"] + r["denoise_seconds"], e_den))
    return raw, den


def fast_curve(rows, ref_spp):
    """The fast-quality denoise's (seconds, corrected relative MSE) points (a job's denoise
    "preview"), from the log's preview columns; empty for a log without them."""
    out = []
    for r in rows:
        d, e = r.get("preview_denoise_seconds", math.nan), r.get("preview_rel_mse", math.nan)
        if not (math.isnan(d) or math.isnan(e)):
            out.append((r["seconds"] + d, corrected(r["rel_mse"], e, r["spp"], ref_spp)[1]))
    return out


FAST_HEAD = ("| scene | ours fast-denoised t(1e-2) | speed-up over raw | ours fast-denoised t(1e-3) | speed-up over raw |\n"
             "|---|---|---|---|---|")


def fast_row(name, raw, fast):
    """One markdown row of the fast-quality table: its times to each target and its speed-up over raw."""
    cols = [name]
    for target in TARGETS:
        r, f = time_to_error(raw, target), time_to_error(fast, target)
        cols += [format_time(f), speed_up(r, f)]
    return "| " + " | ".join(cols) + " |"


def time_to_error(points, target):
    """(bound, seconds) at which the (seconds, error) points first reach `target`: bound "" when
    interpolated in log-log between the first two points that bracket it, "<=" when the first point
    is already there, ">" (seconds of the last point) when none is; None without points. A point
    with a non-positive error (below what the reference can tell) counts as reached at its time."""
    prev = None
    for t, e in points:
        if math.isnan(e):
            continue
        if e <= target:
            if prev is None:
                return ("<=", t)
            t0, e0 = prev
            if e <= 0 or t0 <= 0 or t <= 0:
                return ("", t)
            f = math.log(target / e0) / math.log(e / e0)
            return ("", math.exp(math.log(t0) + f * math.log(t / t0)))
        prev = (t, e)
    return (">", points[-1][0]) if points else None


def format_time(x):
    """A time_to_error result for the table: "1.23 s", "> 4.56 s", "<= 0.0123 s", or "-"."""
    if x is None:
        return "-"
    bound, t = x
    return f"{bound + ' ' if bound else ''}{t:.0f} s" if t >= 100 else f"{bound + ' ' if bound else ''}{t:.3g} s"


def speed_up(raw, den):
    """raw / denoised time as "3.2x"; "> 3.2x" or "< 3.2x" when a bound makes it one; "?" when the
    bounds pull both ways or a time is missing."""
    if raw is None or den is None or den[1] <= 0:
        return "?"
    more = raw[0] == ">" or den[0] == "<="
    less = raw[0] == "<=" or den[0] == ">"
    if more and less:
        return "?"
    return f"{'> ' if more else '< ' if less else ''}{raw[1] / den[1]:.2f}x"


TABLE_HEAD = ("| scene | ours raw t(1e-2) | ours denoised t(1e-2) | speed-up | ours raw t(1e-3) | ours denoised t(1e-3) "
              "| speed-up | Cycles t(1e-2) | Cycles+OIDN t(1e-2) | Cycles t(1e-3) | Cycles+OIDN t(1e-3) |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|")


def table_row(name, ours, cycles=None):
    """One markdown row. ours and cycles: (raw points, denoised points), cycles None for a scene
    Cycles cannot read."""
    cols = [name]
    for target in TARGETS:
        raw, den = (time_to_error(p, target) for p in ours)
        cols += [format_time(raw), format_time(den), speed_up(raw, den)]
    for target in TARGETS:
        cols += [format_time(time_to_error(p, target)) if cycles else "-" for p in (cycles or ((), ()))]
    return "| " + " | ".join(cols) + " |"


def denoise_cost(rows):
    """What our per-pass denoising costs at the run's size: the median denoise (and the first, which
    creates the device), the median pass's rendering, their ratio, and the spp that the median
    denoise would have rendered at the run's mean rate."""
    den = [r["denoise_seconds"] for r in rows]
    passes = [b["seconds"] - a["seconds"] for a, b in zip([{"seconds": 0.0}] + rows, rows)]
    d, p = statistics.median(den), statistics.median(passes)
    rate = rows[-1]["spp"] / rows[-1]["seconds"]
    return dict(median=d, first=den[0], pass_median=p, ratio=d / p if p > 0 else math.inf, spp=d * rate)


def preview_cost(rows):
    """The fast-quality denoise of a pass end (the window's and the page's pictures) against that
    pass's rendering: (spp, pass seconds, preview seconds) per pass with the log's
    preview_denoise_seconds, and the first spp from which the preview costs under a tenth of its pass
    (None: never)."""
    out, first = [], None
    for a, b in zip([{"seconds": 0.0}] + rows, rows):
        p, d = b["seconds"] - a["seconds"], b.get("preview_denoise_seconds", math.nan)
        if math.isnan(d):
            continue
        out.append((b["spp"], p, d))
        if first is None and d < 0.1 * p:
            first = b["spp"]
    return out, first


def curve_lines(label, points):
    """One line of (seconds, error) points for --curves."""
    return f"  {label:<14} " + "  ".join(f"{t:.3g}s:{e:.2e}" for t, e in points)


# ---------------------------------------------------------------------------------------------
# Running the renderers.


class Work:
    """The progress bar's account, in rendered samples per pixel weighted by each renderer's cost
    (vs_cycles.Work's: one of ours costs about OURS_COST of one of Cycles')."""
    OURS_COST = vc.Work.OURS_COST

    def __init__(self, total):
        self.total, self.done, self.started = total, 0.0, time.monotonic()

    def show(self, label, part=0.0):
        progress(label, (self.done + part) / max(self.total, 1e-9), started=self.started)

    def finish(self, amount, skipped=False):
        if skipped:
            self.total -= amount
        else:
            self.done += amount


def scene_list(args):
    """(name, path, kind) of every scene asked for: "course" (COLLADA, vs_mitsuba's flags) or "glb"."""
    known = {n: (v[0], "course") for n, v in vm.SCENES.items()}
    known.update({n: (p, "glb") for n, p in GLB_SCENES.items()})
    extra = {p.stem: (p.resolve(), "glb") for p in args.glb}
    known.update(extra)
    names = [s for s in args.scenes.split(",") if s] if args.scenes else [*vm.SCENES, *GLB_SCENES]
    names += [n for n in extra if n not in names]
    unknown = [n for n in names if n not in known]
    if unknown:
        sys.exit(f"denoise_bench: unknown scene {unknown[0]} (known: {', '.join(known)})")
    out = []
    for n in names:
        path, kind = known[n]
        if not path.exists():
            print(f"denoise_bench: skipping {n}: {path} is absent")
        elif kind == "glb" and path.suffix.lower() not in (".glb", ".gltf"):
            sys.exit(f"denoise_bench: {path}: only glTF scenes may be added")
        else:
            out.append((n, path, kind))
    return out


def depth_for(args, kind, name):
    return args.depth or (vm.SCENES[name][1] if kind == "course" else GLB_DEPTH)


def our_flags(args, name, kind, depth):
    """The flags every render of a scene shares (vs_cycles.py's for glTF, vs_mitsuba.py's for the course)."""
    w, h = args.res
    flags = ["-t", str(args.threads), "-m", str(depth), "-r", str(w), str(h), "--no-adaptive", "--quiet"]
    if kind == "course":
        _, _, lens, focus = vm.SCENES[name]
        flags += ["-l", "1", "-b", str(lens), "-d", str(focus)] + ([] if (w, h) == (480, 360) else ["--frame-scene"])
    return flags


def digest(parts):
    """A short hash of files' bytes and strings: the cached references are keyed on what made them."""
    h = hashlib.sha1()
    for p in parts:
        h.update(p.read_bytes() if isinstance(p, Path) else p.encode())
    return h.hexdigest()[:10]


def run_logged(cmd, label, work, amount, progress_log):
    """Runs our pathtracer, redrawing the bar from its --progress-log; the amount joins the account."""
    progress_log.unlink(missing_ok=True)
    proc = subprocess.Popen([*cmd[:-1], "--progress-log", str(progress_log), cmd[-1]], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    while proc.poll() is None:
        try:
            last = progress_log.read_text().strip().splitlines()[-1].split(",")
            work.show(label, amount * float(last[1]))
        except (OSError, IndexError, ValueError):
            work.show(label)
        time.sleep(0.25)
    out, err = proc.communicate()
    progress_log.unlink(missing_ok=True)
    if proc.returncode:
        clear()
        sys.exit(f"denoise_bench: {shlex.join(cmd)} failed ({proc.returncode}):\n{out}{err}")
    work.finish(amount)


def run_ours(args, name, path, kind, depth, work):
    """Our reference (cached) and the measured run: the error log's rows."""
    flags = our_flags(args, name, kind, depth)
    ref_flags = [*flags, "-s", str(args.ref_spp), "--seed", str(REF_SEED)]
    ref = CACHE / f"ours-denoise-ref-{name}-{digest([path, args.pathtracer, ' '.join(ref_flags)])}.exr"
    cost = work.OURS_COST
    if ref.exists():
        work.finish(cost * args.ref_spp, skipped=True)
    else:
        tmp = ref.with_suffix(".part.exr")  # a cancelled reference never looks finished
        run_logged([str(args.pathtracer), *ref_flags, "-f", str(tmp), str(path)], f"{name}: our reference", work,
                   cost * args.ref_spp, CACHE / "denoise-progress.csv")
        tmp.with_name(tmp.name[:-4] + "_rate.png").unlink(missing_ok=True)
        tmp.rename(ref)
    log = CACHE / f"ours-denoise-{name}.csv"
    out = CACHE / f"ours-denoise-{name}-run.exr"
    run_logged([str(args.pathtracer), *flags, "-s", str(args.spp), "--seed", str(RUN_SEED), "--denoise",
                "--error-log", str(log), "--reference", str(ref), "-f", str(out), str(path)],
               f"{name}: ours", work, cost * args.spp, CACHE / "denoise-progress.csv")
    rows = parse_error_log(log.read_text())
    if not rows or any(math.isnan(r["denoised_rel_mse"]) for r in rows):
        clear()
        sys.exit(f"denoise_bench: {name}: no denoised error in {log}: is Open Image Denoise installed "
                 "(scripts/install-oidn.sh)?")
    return rows


def spp_ladder(max_spp):
    """1, 2, 4, ... up to max_spp, which ends the ladder even when it is not a power of two."""
    out = [1]
    while out[-1] * 2 <= max_spp:
        out.append(out[-1] * 2)
    return out if out[-1] == max_spp else out + [max_spp]


def run_cycles(args, cr, np, name, path, depth, work):
    """Cycles' reference (vs_cycles.py's, cached and shared with it) and its raw and denoised renders
    up the spp ladder: ((raw points, denoised points), the median extra seconds of denoising)."""
    w, h = args.res
    cr.load_glb(path)
    cr.configure(w, h, vc.bounces_for_depth(depth), args.threads)
    lum = lambda img: (img[..., :3] @ np.array(vc.LUMA)).tolist()  # noqa: E731
    tag = f"{name}-{vc.digest([path])}-{w}x{h}-m{depth}-{args.ref_spp}"
    ref_path = CACHE / f"cycles-{vc.BPY_VERSION}-{tag}-plain.exr"  # vs_cycles.py's name, without variants
    cr.set_denoising(False)
    if ref_path.exists():
        work.finish(args.ref_spp, skipped=True)
    else:
        label = f"{name}: Cycles reference"
        cr.render(ref_path, args.ref_spp, CYCLES_REF_SEED, lambda f: work.show(label, f * args.ref_spp))
        work.finish(args.ref_spp)
    ref = lum(cr.read_exr(ref_path))
    out = CACHE / f"cycles-denoise-{name}-run.exr"
    raw, den, extra = [], [], []
    for spp in spp_ladder(args.cycles_max_spp):
        runs = []
        for on in (False, True):
            cr.set_denoising(on)
            label = f"{name}: Cycles{'+OIDN' if on else ''} {spp}"
            sec = cr.render(out, spp, RUN_SEED, lambda f: work.show(label, f * spp))  # noqa: B023
            work.finish(spp)
            runs.append((sec, vc.rel_mse(lum(cr.read_exr(out)), ref)))
        (t_raw, e_raw), (t_den, e_den) = runs
        e_raw, e_den = corrected(e_raw, e_den, spp, args.ref_spp)
        raw.append((t_raw, e_raw))
        den.append((t_den, e_den))
        extra.append(t_den - t_raw)
    cr.set_denoising(False)
    return (raw, den), statistics.median(extra)


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("glb", nargs="*", type=Path, help="more glTF scenes (rendered by both)")
    ap.add_argument("--scenes", default="", help="comma-separated names (default: "
                    f"{','.join([*vm.SCENES, *GLB_SCENES])}); scenes given as files are added")
    ap.add_argument("--res", type=int, nargs=2, metavar=("W", "H"), help="size (default 200 150)")
    ap.add_argument("--depth", type=int, default=0,
                    help=f"our -m (0: {GLB_DEPTH} for glTF, vs_mitsuba's 5 for the course); Cycles' max bounces: -m - 1")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--spp", type=int, help="our samples per pixel, the last pass's (default 1024)")
    ap.add_argument("--ref-spp", type=int, help="both references' samples per pixel (default 1024)")
    ap.add_argument("--cycles-max-spp", type=int, help="Cycles' spp ladder's top (default 256)")
    ap.add_argument("--curves", action="store_true", help="also print each curve's (seconds, error) points")
    ap.add_argument("--quick", action="store_true", help="a smoke test: " +
                    ", ".join(f"{k.replace('_', '-')} {v}" for k, v in QUICK.items()) + " unless given")
    ap.add_argument("--pathtracer", type=Path, default=BUILD / "pathtracer")
    args = ap.parse_args(argv)
    for key, value in (QUICK if args.quick else DEFAULTS).items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    args.pathtracer = args.pathtracer.resolve()
    return args


def main():
    args = parse_args()
    if not args.pathtracer.exists():
        sys.exit(f"denoise_bench: {args.pathtracer} is absent: build it first")
    if args.depth < 0 or min(args.spp, args.ref_spp, args.cycles_max_spp, args.threads) < 1:
        sys.exit("denoise_bench: --depth must be >= 0 (0: the defaults), every spp and --threads >= 1")
    scenes = scene_list(args)
    if any(kind == "glb" for _, _, kind in scenes):
        vc.ensure_venv()  # re-runs this script with bpy; after it, Cycles is at hand
        import numpy as np
        import cycles_render as cr
    CACHE.mkdir(parents=True, exist_ok=True)
    print(f"denoise_bench: host {host_description()}")
    print(f"denoise_bench: command: python3 {shlex.join(sys.argv)}")
    print(f"denoise_bench: {args.res[0]}x{args.res[1]}, {args.threads} threads; ours up to {args.spp} spp "
          f"(passes of 1, 2, 4, ...), Cycles {', '.join(map(str, spp_ladder(args.cycles_max_spp)))} spp; references "
          f"{args.ref_spp} spp; relative MSE, the references' noise taken out")
    cyc_cost = sum(spp_ladder(args.cycles_max_spp)) * 2 + args.ref_spp
    work = Work(sum(Work.OURS_COST * (args.spp + args.ref_spp) + (cyc_cost if kind == "glb" else 0)
                    for _, _, kind in scenes))
    rows, notes, fast_rows = [], [], []
    for name, path, kind in scenes:
        depth = depth_for(args, kind, name)
        log_rows = run_ours(args, name, path, kind, depth, work)
        ours = curves(log_rows, args.ref_spp)
        fast = fast_curve(log_rows, args.ref_spp)
        if fast:
            fast_rows.append(fast_row(name, ours[0], fast))
        cost = denoise_cost(log_rows)
        notes.append(f"{name} (-m {depth}): our denoise {cost['median']:.3g} s a pass (median of {len(log_rows)}; the "
                     f"first {cost['first']:.3g} s, device set-up included) = {cost['ratio']:.2f} x the median pass's "
                     f"rendering ({cost['pass_median']:.3g} s), or {cost['spp']:.3g} spp at the run's rate")
        passes, first = preview_cost(log_rows)
        if passes:
            notes.append(f"{name}: a preview (fast) denoise costs " + ", ".join(
                f"{d / p:.0%} of the {n:g}-spp pass" for n, p, d in passes[-4:]) +
                (f"; under 10% of its pass from {first:g} spp" if first else "; never under 10% of its pass"))
        cycles = None
        if kind == "glb":
            cycles, extra = run_cycles(args, cr, np, name, path, depth, work)
            notes.append(f"{name}: a Cycles render with denoising takes {extra:.3g} s more than without (median over "
                         f"the ladder)")
        clear()
        if args.curves:
            print(f"{name}: (seconds, relative MSE) points")
            labels = ("ours raw", "ours denoised", "Cycles", "Cycles+OIDN")
            for label, points in zip(labels, [*ours, *(cycles or ())]):
                print(curve_lines(label, points))
            if fast:
                print(curve_lines("ours fast", fast))
        rows.append(table_row(name, ours, cycles))
    clear()
    print()
    print(TABLE_HEAD)
    print("\n".join(rows))
    if fast_rows:  # OIDN's fast quality, without cleaning the features first: what denoise "preview" gives
        print()
        print(FAST_HEAD)
        print("\n".join(fast_rows))
    print()
    print("\n".join(notes))


if __name__ == "__main__":
    main()
    # bpy's add-ons run update callbacks on a scene being torn down at interpreter exit: noise.
    sys.stdout.flush()
    os._exit(0)
