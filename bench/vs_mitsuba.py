#!/usr/bin/env python3
"""Side by side with Mitsuba 3: samples/s and efficiency 1/(relMSE x seconds) of our `pathtracer`
and Mitsuba's `path` integrator (llvm_ad_rgb) at its strongest, on the same scenes, camera and
depth, on this machine, in one run.

    python3 bench/vs_mitsuba.py [--scenes CBspheres,CBbunny,CBdragon,dof] [--spp 256] [--runs 3]
                                [--ref-spp 1024] [--framing course|view] [--samplers multijitter,...]
                                [--ours=--no-caustic-tracing] [--baseline OTHER_BUILD] [--profile]

The framing is the course's (`-r 480 360` is a crop of its 800x600 view, so the box fills the
image); --framing view compares the whole view scaled to 480x360 (--keep-fov), where most pixels see
background. Mitsuba renders with each of its samplers (multijitter, ldsampler, independent) and we
are compared with the best of them, the one with the highest efficiency on that scene. The scenes:
the course's CBspheres, CBbunny and CBdragon (../shared) and our dof.dae through a thin lens
(-b 0.12 -d 3.6), all at depth 5.

Mitsuba comes from PyPI into build/mitsuba-venv (mitsuba 3.9.1; its Dr.Jit emits LLVM IR that needs
LLVM 16 or newer: Debian 12's libllvm19 or libllvm16, found and handed to Dr.Jit through
DRJIT_LIBLLVM_PATH). `build/bench_export_mitsuba` writes each scene as our loader sees it (world
triangles and their shading normals as PLY, spheres, materials, area lights, and the camera of the
framing compared: the course's crop, or its whole view scaled to 480x360). Both renderers: 2 threads, one light sample, no adaptive sampling, a
box pixel filter; Mitsuba's max_depth counts the emitter hit, so our -m M is its max_depth M + 1.
Each renderer's error is measured against its own high-spp reference (cached in build/bench-cache,
keyed on the content of the pathtracer binary, or of the exported scene and Mitsuba's release),
and the two references are compared with each other to check that the conversion is faithful.
Timings exclude start-up: Mitsuba's kernel compilation (one warm-up render) and our scene load.
--ours adds flags to our timed runs only (the reference keeps the defaults): flags that change how
we sample, not what converges, such as --no-caustic-tracing (unidirectional path tracing, as
Mitsuba's `path` does). --profile also prints each renderer's share of time in ray queries (Embree
and the intersection callbacks it calls), measured with perf (query_share.py).
"""
import argparse
import hashlib
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

import query_share
from host import host_description
from progress import clear, progress

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build"
VENV = BUILD / "mitsuba-venv"
SHARED = ROOT.parent / "shared" / "scenes-cs184"
# name: (file, our -m, lens radius, focal distance)
SCENES = {"CBspheres": (SHARED / "CBspheres.dae", 5, 0.0, 4.7), "CBbunny": (SHARED / "CBbunny.dae", 5, 0.0, 4.7),
          "CBdragon": (SHARED / "CBdragon.dae", 5, 0.0, 4.7), "dof": (ROOT / "scenes" / "dof.dae", 5, 0.12, 3.6)}
SAMPLERS = ("multijitter", "ldsampler", "independent")
MITSUBA_VERSION = "3.9.1"
MITSUBA = f"mitsuba=={MITSUBA_VERSION}"


def ensure_venv():
    """Re-runs this script inside build/mitsuba-venv, creating it when missing."""
    py = VENV / "bin" / "python"
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    if not py.exists() or subprocess.run(
            [str(py), "-c", f"import mitsuba, numpy; assert mitsuba.__version__ == '{MITSUBA_VERSION}'"],
            capture_output=True).returncode:
        print(f"vs_mitsuba: installing {MITSUBA} and numpy into {VENV}", file=sys.stderr)
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
        subprocess.run([str(py), "-m", "pip", "install", "-q", MITSUBA, "numpy"], check=True)
    os.execv(str(py), [str(py), *sys.argv])


def find_libllvm():
    """A libLLVM new enough for Mitsuba's Dr.Jit (16 or newer), the newest first."""
    for pattern in ("libLLVM-19.so*", "libLLVM.so.19*", "libLLVM-16.so*", "libLLVM.so.16*"):
        for base in (Path("/usr/lib/x86_64-linux-gnu"), Path("/usr/lib/aarch64-linux-gnu")):
            hits = sorted(base.glob(pattern))
            if hits:
                return str(hits[0])
    return None


def rel_mse(np, img, ref):
    """The renderer's relative_mse: luminance, eps 0.01 (renderer/util/image.cpp)."""
    w = np.array([0.2126, 0.7152, 0.0722])
    a, b = img[..., :3] @ w, ref[..., :3] @ w
    return float(np.mean((a - b) ** 2 / (b * b + 0.01)))


def mitsuba_scene(mi, folder, depth, spp, sampler="independent"):
    d = json.loads((folder / "scene.json").read_text())
    T = mi.ScalarTransform4f
    cam = d["camera"]
    sensor = {
        "type": "perspective", "fov_axis": "x", "fov": cam["fov_x_deg"],
        "to_world": T.look_at(origin=cam["origin"], target=cam["target"], up=cam["up"]),
        "sampler": {"type": sampler, "sample_count": spp},
        "film": {"type": "hdrfilm", "width": cam["width"], "height": cam["height"],
                 "rfilter": {"type": "box"}, "pixel_format": "rgb"},
    }
    if cam.get("lens_radius", 0) > 0:  # our thin lens: the radius, and the plane in focus along the view axis
        sensor.update(type="thinlens", aperture_radius=cam["lens_radius"], focus_distance=cam["focal_distance"])
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": depth + 1}, "sensor": sensor}

    def bsdf(m):
        """Mitsuba's opaque BSDFs are one-sided; ours shade both sides, so they are wrapped."""
        out = one_bsdf(m)
        return out if out["type"] == "dielectric" else {"type": "twosided", "bsdf": out}

    def one_bsdf(m):
        rgb = lambda v: {"type": "rgb", "value": v}  # noqa: E731
        if m["type"] == "diffuse":
            return {"type": "diffuse", "reflectance": rgb(m["albedo"])}
        if m["type"] == "mirror":
            return {"type": "conductor", "material": "none", "specular_reflectance": rgb(m["albedo"])}
        if m["type"] in ("glass", "refraction"):
            out = {"type": "dielectric", "int_ior": m["ior"], "ext_ior": 1.0,
                   "specular_reflectance": rgb(m["albedo"]), "specular_transmittance": rgb(m["transmittance"])}
            if m["type"] == "refraction":
                out["specular_reflectance"] = rgb([0, 0, 0])
            return out
        if m["type"] == "microfacet":
            return {"type": "roughconductor", "distribution": "beckmann", "alpha": m["alpha"],
                    "eta": rgb(m["eta"]), "k": rgb(m["k"])}
        if m["type"] == "emission":
            return {"type": "diffuse", "reflectance": rgb([0, 0, 0])}
        raise SystemExit(f"vs_mitsuba: material kind {m['type']} has no Mitsuba mapping")

    mats = d["materials"]
    for i, part in enumerate(d["meshes"]):
        m = mats[part["material"]]
        shape = {"type": "ply", "filename": str(folder / part["file"]), "face_normals": not part["smooth"],
                 "bsdf": bsdf(m)}
        if any(m["radiance"]):
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": m["radiance"]}}
        scene[f"mesh{i}"] = shape
    for i, s in enumerate(d["spheres"]):
        scene[f"sphere{i}"] = {"type": "sphere", "center": s["center"], "radius": s["radius"],
                               "bsdf": bsdf(mats[s["material"]])}
    for i, l in enumerate(d["area_lights"]):
        x, y, n, c = l["half_x"], l["half_y"], l["normal"], l["center"]
        m = [[x[0], y[0], n[0], c[0]], [x[1], y[1], n[1], c[1]], [x[2], y[2], n[2], c[2]], [0, 0, 0, 1]]
        scene[f"light{i}"] = {"type": "rectangle", "to_world": T(m),
                              "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}},
                              "emitter": {"type": "area", "radiance": {"type": "rgb", "value": l["radiance"]}}}
    return mi.load_dict(scene)


def digest(paths):
    """A short content hash: the cached references are keyed on what made them."""
    h = hashlib.sha1()
    for p in sorted(paths):
        h.update(Path(p).read_bytes())
    return h.hexdigest()[:10]


def ours_command(args, scene_path, depth, spp, out, seed, extra=(), build=BUILD):
    _, _, lens, focus = next(v for v in SCENES.values() if v[0] == scene_path)
    cmd = [str(build / "pathtracer"), "-t", "2", "-s", str(spp), "-l", "1", "-m", str(depth), "-r", "480", "360",
           *(["--keep-fov"] if args.framing == "view" else []), "-b", str(lens), "-d", str(focus),
           "--no-adaptive", "--quiet", "--seed", str(seed), *extra, "-f", str(out), str(scene_path)]
    if args.sampler:
        cmd[1:1] = ["--sampler", args.sampler]
    return cmd


def run_ours(args, scene_path, depth, spp, out, seed, extra=(), build=BUILD):
    cmd = ours_command(args, scene_path, depth, spp, out, seed, extra, build)
    text = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    m = re.search(r"([\d.]+) s, ([\d.e+]+) samples/s", text)
    return float(m.group(1)), float(m.group(2))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="CBspheres,CBbunny,CBdragon,dof")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--depth", type=int, default=0, help="our -m for every scene (default: 5)")
    ap.add_argument("--framing", choices=("course", "view"), default="course",
                    help="course: the course's crop at 480x360 (default); view: its whole view scaled (--keep-fov)")
    ap.add_argument("--samplers", default=",".join(SAMPLERS), help="Mitsuba's samplers to time; we face the best")
    ap.add_argument("--sampler", default="", help="our sampler (sobol, independent; default ours)")
    ap.add_argument("--ours", default="", help="extra pathtracer flags for our timed runs, e.g. --ours=--no-caustic-tracing")
    ap.add_argument("--baseline", default="", help="another build folder whose pathtracer runs beside ours, "
                    "interleaved, against our reference: a change's effect on efficiency in the same run")
    ap.add_argument("--profile", action="store_true",
                    help="also measure each renderer's share of time in ray queries with perf (query_share.py)")
    args = ap.parse_args()
    names = [s for s in args.scenes.split(",") if s]
    unknown = [n for n in names if n not in SCENES]
    if unknown:
        sys.exit(f"vs_mitsuba: unknown scene {unknown[0]} (known: {', '.join(SCENES)})")
    absent = [n for n in names if not SCENES[n][0].exists()]
    for n in absent:
        print(f"vs_mitsuba: skipping {n}: {SCENES[n][0]} is absent")
    names = [n for n in names if n not in absent]
    samplers = [s for s in args.samplers.split(",") if s]
    if not names:
        return
    why_not = args.profile and query_share.available()
    if why_not:
        sys.exit(f"vs_mitsuba: --profile: {why_not}")
    llvm = find_libllvm()
    if not llvm:
        sys.exit("vs_mitsuba: no libLLVM 16 or newer found (Debian 12: apt install libllvm19); "
                 "Mitsuba's llvm variant needs it")
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", llvm)
    ensure_venv()
    import numpy as np
    import drjit as dr
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    dr.set_thread_count(2)
    cache = BUILD / "bench-cache"
    cache.mkdir(parents=True, exist_ok=True)
    pixels = 480 * 360
    framing = "course framing (the crop of its 800x600 view)" if args.framing == "course" else "whole view (keep_fov)"
    print(f"vs_mitsuba: host {host_description()}")
    print(f"vs_mitsuba: 480x360 {framing}, {args.spp} spp, 2 threads, medians of {args.runs}; each renderer "
          f"against its own {args.ref_spp}-spp reference (another seed); Mitsuba {mi.__version__} llvm_ad_rgb "
          f"({llvm}), samplers {', '.join(samplers)}" + (f"; ours with {args.ours}" if args.ours else ""))
    rows = []
    ours_binary = digest([BUILD / "pathtracer"])
    for name in names:
        path, depth, lens, focus = SCENES[name]
        depth = args.depth or depth
        tag = f"{name}-{args.framing}-m{depth}"
        folder = cache / f"mitsuba-{name}-{args.framing}"
        shutil.rmtree(folder, ignore_errors=True)  # no file of an older export stays
        folder.mkdir()
        subprocess.run([str(BUILD / "bench_export_mitsuba"), str(path), str(folder), "--aperture", str(lens),
                        "--focal-distance", str(focus), *(["--whole-view"] if args.framing == "view" else [])],
                       check=True, stdout=subprocess.DEVNULL)
        started = time.monotonic()
        steps = len(samplers) * args.runs + args.runs
        # Mitsuba: its reference (cached), then per sampler one warm-up render (kernel compilation)
        # and the timed runs.
        exported = digest(p for p in folder.iterdir() if p.is_file())
        mref_path = cache / f"mitsuba-{mi.__version__}-{tag}-{exported}-{args.ref_spp}.npy"
        if mref_path.exists():
            mref = np.load(mref_path)
        else:
            progress(f"{name}: Mitsuba reference", 0, started)
            mref = np.array(mi.render(mitsuba_scene(mi, folder, depth, args.ref_spp), seed=7919))
            np.save(mref_path, mref)
        mitsuba = {}  # sampler: (seconds, relMSE), medians
        done = 0
        for sampler in samplers:
            scene = mitsuba_scene(mi, folder, depth, args.spp, sampler)
            np.array(mi.render(scene, seed=1))
            mt, me = [], []
            for k in range(args.runs):
                progress(f"{name}: Mitsuba {sampler}", done / steps, started)
                done += 1
                t0 = time.perf_counter()
                img = np.array(mi.render(scene, seed=100 + k))
                mt.append(time.perf_counter() - t0)
                me.append(rel_mse(np, img, mref))
            mitsuba[sampler] = (statistics.median(mt), statistics.median(me))
        best = max(mitsuba, key=lambda s: 1 / (mitsuba[s][0] * mitsuba[s][1]))
        # Ours: its reference (cached EXR), the timed runs.
        oref_path = cache / f"ours-{tag}-{ours_binary}-{args.ref_spp}-{args.sampler or 'default'}.exr"
        if not oref_path.exists():
            progress(f"{name}: our reference", done / steps, started)
            run_ours(args, path, depth, args.ref_spp, oref_path, 7919)
        oref = np.array(mi.Bitmap(str(oref_path)))
        ot, orate, oe, bt, be = [], [], [], [], []
        out = cache / f"ours-{name}-run.exr"
        for k in range(args.runs):
            progress(f"{name}: ours", done / steps, started)
            done += 1
            sec, rate = run_ours(args, path, depth, args.spp, out, 100 + k, args.ours.split())
            ot.append(sec)
            orate.append(rate)
            oe.append(rel_mse(np, np.array(mi.Bitmap(str(out))), oref))
            if args.baseline:
                sec, _ = run_ours(args, path, depth, args.spp, out, 100 + k, args.ours.split(),
                                  Path(args.baseline).resolve())
                bt.append(sec)
                be.append(rel_mse(np, np.array(mi.Bitmap(str(out))), oref))
        shares = None
        if args.profile:
            # After the timed runs, so that perf's own cost never enters a timing. Ours renders 4x the
            # samples so that its start-up (scene load, image writing) weighs little in its share.
            progress(f"{name}: profiles", 1, started)
            scene = mitsuba_scene(mi, folder, depth, args.spp, best)
            m_share = query_share.profile_self(
                cache / f"perf-mitsuba-{name}.data",
                lambda: [np.array(mi.render(scene, seed=200 + k)) for k in range(args.runs)])
            o_share = query_share.profile_command(
                cache / f"perf-ours-{name}.data",
                ours_command(args, path, depth, 4 * args.spp, out, 200, args.ours.split()))
            shares = (m_share, o_share)
        clear()
        lum = np.array([0.2126, 0.7152, 0.0722])
        mean_m, mean_o = float(np.mean(mref[..., :3] @ lum)), float(np.mean(oref[..., :3] @ lum))
        base = (statistics.median(bt), statistics.median(be)) if args.baseline else None
        rows.append(dict(name=name, depth=depth, mitsuba=mitsuba, best=best, o_sec=statistics.median(ot),
                         o_rate=statistics.median(orate), o_err=statistics.median(oe), mean_m=mean_m, mean_o=mean_o,
                         cross=rel_mse(np, mref, oref), shares=shares, base=base))
    report(args, rows, pixels)


def report(args, rows, pixels):
    """Every renderer's row per scene, then the table the README and docs/performance.md quote."""
    print(f"{'scene':<10} {'renderer':<21} {'seconds':>8} {'M samples/s':>12} {'relMSE':>10} {'efficiency':>11}")
    for r in rows:
        for i, (sampler, (sec, err)) in enumerate(r["mitsuba"].items()):
            label = f"mitsuba {sampler}" + (" *" if sampler == r["best"] else "")
            print(f"{r['name'] if i == 0 else '':<10} {label:<21} {sec:8.3f} {pixels * args.spp / sec / 1e6:12.2f} "
                  f"{err:10.5f} {1 / (err * sec):11.1f}")
        print(f"{'(m=' + str(r['depth']) + ')':<10} {'ours':<21} {r['o_sec']:8.3f} {r['o_rate'] / 1e6:12.2f} "
              f"{r['o_err']:10.5f} {1 / (r['o_err'] * r['o_sec']):11.1f}")
        print(f"{'':<10} references: mean luminance ours {r['mean_o']:.4f} vs Mitsuba {r['mean_m']:.4f} "
              f"({100 * (r['mean_o'] / r['mean_m'] - 1):+.1f}%), relMSE between them {r['cross']:.5f}")
        if r["base"]:
            b_sec, b_err = r["base"]
            print(f"{'':<10} {'baseline':<21} {b_sec:8.3f} {'':>12} {b_err:10.5f} {1 / (b_err * b_sec):11.1f}   "
                  f"ours/baseline: efficiency {(b_err * b_sec) / (r['o_err'] * r['o_sec']):.3f}x ({args.baseline})")
        if r["shares"]:
            (m_q, m_n), (o_q, o_n) = r["shares"]
            print(f"{'':<10} share of time in ray queries (perf): Mitsuba ({r['best']}) {100 * m_q:.1f}% of {m_n} "
                  f"samples, ours {100 * o_q:.1f}% of {o_n}")
            m_sec, m_err = r["mitsuba"][r["best"]]
            efficiency = (m_err * m_sec) / (r["o_err"] * r["o_sec"])
            for line in time_split(pixels * args.spp / m_sec, m_q, r["o_rate"], o_q, efficiency):
                print(f"{'':<10} {line}")
    print()
    print("| scene | Mitsuba's best sampler | efficiency: Mitsuba | ours | ours / Mitsuba's best "
          "| samples/s: Mitsuba | ours | ours / Mitsuba |")
    print("|---|---|---|---|---|---|---|---|")
    samples, efficiency = [], []
    for r in rows:
        m_sec, m_err = r["mitsuba"][r["best"]]
        m_eff, o_eff = 1 / (m_err * m_sec), 1 / (r["o_err"] * r["o_sec"])
        m_rate = pixels * args.spp / m_sec
        efficiency.append((r["name"], o_eff / m_eff))
        samples.append((r["name"], r["o_rate"] / m_rate))
        print(f"| {r['name']} | {r['best']} | {m_eff:.1f} | {o_eff:.1f} | {o_eff / m_eff:.2f}x | "
              f"{m_rate / 1e6:.2f} M | {r['o_rate'] / 1e6:.2f} M | {r['o_rate'] / m_rate:.2f}x |")
    print(verdict("efficiency 1/(relMSE x s) >= 1.5x Mitsuba's best sampler on every scene", 1.5, efficiency))
    print(verdict("samples/s >= Mitsuba's on CBbunny", 1.0, [c for c in samples if c[0] == "CBbunny"]))


def time_split(m_rate, m_share, o_rate, o_share, efficiency, goal=1.5):
    """Where each renderer's time a sample goes (in ray queries, around them), and how much of our
    own work (around the queries) the targets ask to cut, with our queries as they are."""
    m_t, o_t = 1e6 / m_rate, 1e6 / o_rate  # microseconds a sample
    m_q, o_q = m_t * m_share, o_t * o_share
    m_own, o_own = m_t - m_q, o_t - o_q

    def cut(target_t):
        if target_t >= o_t:
            return "met"
        if o_t - target_t >= o_own:
            return "out of reach by our own work alone"
        return f"cut by {100 * (o_t - target_t) / o_own:.0f}%"

    return [f"per sample: Mitsuba {m_t:.3f} us ({m_q:.3f} in queries, {m_own:.3f} around them), ours {o_t:.3f} us "
            f"({o_q:.3f}, {o_own:.3f}): our queries {o_q / m_q:.2f}x, our own work {o_own / m_own:.2f}x",
            f"our own work, queries as they are: samples/s parity {cut(m_t)}; {goal}x efficiency "
            f"{cut(o_t * efficiency / goal)}"]


def verdict(what, goal, cases):
    """A target against this run, as bench_scaling and bench_convergence print theirs (bench_common.h):
    met or not, the weakest case, and how many miss; ratios compare as printed, to two decimals."""
    if not cases:
        return f"target: {what}: nothing measured"
    shown = [(name, round(v, 2)) for name, v in cases]
    below = sum(1 for _, v in shown if not v >= goal)
    name, low = min(shown, key=lambda c: c[1])
    if below == 0:
        return f"target: {what}: met on this host (lowest {low:.2f}x: {name})"
    return f"target: {what}: not met on this host (lowest {low:.2f}x: {name}; {below} of {len(shown)} cases below {goal:.2f}x)"


if __name__ == "__main__":
    main()
    # Dr.Jit reports its cached kernels' variables as leaks at interpreter exit: noise, not ours.
    sys.stdout.flush()
    os._exit(0)
