"""The share of a render's CPU time spent in ray queries, by `perf` sampling (vs_mitsuba.py --profile).

The rest of the time is each renderer's own work around its queries (hit refinement, shading,
sampling): (1 - share) / share is that work per unit of query time. `perf` measures Mitsuba 3 and
ours the same way, so the two renderers compare on the same host in the same run.

A ray query is Embree's own code plus the intersection callbacks of the shapes it calls back (our
sphere user geometry; Mitsuba's sphere and rectangle plugins' `ray_intersect_preliminary` and
`ray_test`). Hit refinement, shading and sampling are the rest, for both.
"""
import os
import shutil
import signal
import subprocess
import time

# Symbols of our renderer that Embree calls during a query (renderer/accel.cpp's user geometry).
OURS_CALLBACKS = ("sphere_intersect", "sphere_occluded", "sphere_hit4", "sphere_record", "sphere_hit_lane")
# Mitsuba's shape plugins answer Embree's user-geometry calls through these.
MITSUBA_CALLBACKS = ("ray_intersect_preliminary", "ray_test")


def available():
    """Why profiling cannot run here, or None."""
    if not shutil.which("perf"):
        return "perf is not installed (Debian: linux-perf)"
    probe = subprocess.run(["perf", "record", "-q", "-o", os.devnull, "--", "true"], capture_output=True, text=True)
    if probe.returncode != 0:
        return "perf record failed: " + (probe.stderr.strip().splitlines() or ["no output"])[-1]
    return None


def query_share(data, callbacks):
    """(share of samples in ray queries, samples) from a perf.data file."""
    report = subprocess.run(["perf", "report", "-i", str(data), "--stdio", "--sort", "dso,sym",
                             "--percent-limit", "0", "-F", "overhead,dso,sym"],
                            capture_output=True, text=True, check=True).stdout
    return share_in_queries(report, callbacks)


def share_in_queries(report, callbacks):
    """(share, samples) from `perf report --sort dso,sym -F overhead,dso,sym` text: the rows whose
    object is Embree or whose symbol is one of the callbacks, over all rows."""
    total = queries = 0.0
    samples = 0
    for line in report.splitlines():
        if line.startswith("# Samples:"):  # "# Samples: 39K of event 'cpu-clock'"
            n = line.split()[2]
            samples = int(float(n[:-1]) * 1000) if n.endswith("K") else int(n)
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        parts = line.split(None, 2)  # overhead, object ("[JIT]" of "[JIT] tid 7" too), the rest
        if len(parts) < 3 or not parts[0].endswith("%"):
            continue
        pct = float(parts[0][:-1])
        total += pct
        if "libembree" in parts[1] or any(c in parts[2] for c in callbacks):
            queries += pct
    return (queries / total if total else 0.0), samples


def profile_self(out, work):
    """Runs work() in this process under `perf record -p`, for Mitsuba, which renders in-process."""
    perf = subprocess.Popen(["perf", "record", "-q", "-F", "997", "-p", str(os.getpid()), "-o", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(1.0)  # perf attaches to every thread before the work starts
    try:
        work()
    finally:
        perf.send_signal(signal.SIGINT)
        perf.wait()
    return query_share(out, MITSUBA_CALLBACKS)


def profile_command(out, cmd):
    """Runs our renderer's command under `perf record`."""
    subprocess.run(["perf", "record", "-q", "-F", "997", "-o", str(out), "--"] + cmd, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return query_share(out, OURS_CALLBACKS)
