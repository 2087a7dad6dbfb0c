"""Scale-out (docs/scale-out.md): a real redis-server on a loopback port, render-server with --queue
and three render-worker processes. A job renders through the workers; one worker is killed with
SIGKILL while it holds a pass, another claims that pass, and the job still finishes with the image a
single process renders (passes merge as sums of the same samples, so the two agree to float
rounding). Cancel and the event stream behave as with the embedded queue, and a worker builds a
scene once for all the jobs that use its content."""
import os
import re
import shutil
import signal
import socket
import struct
import subprocess
import time
from pathlib import Path

import pytest

from images import read_exr
from support import SOURCE_DIR

RENDER_WORKER = Path(os.environ.get("PT_RENDER_WORKER", SOURCE_DIR / "build/render-worker"))
# cornell has mirror and glass spheres and an area light: passes carry light-traced caustics too.
JOB = {"scene": "cornell", "width": 160, "height": 120, "spp": 256, "max_depth": 4, "adaptive": False, "seed": 7}


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Redis:
    """A redis-server without persistence on a free loopback port, or on `port` (a restart).
    `args`: more redis-server options (--requirepass ...); `password`: what redis-cli logs in with;
    `bind`: the address it listens on (and redis-cli connects to)."""

    def __init__(self, root, port=None, args=(), password=None, bind="127.0.0.1"):
        assert shutil.which("redis-server"), "redis-server is missing: run scripts/install-deps.sh"
        self.port = port or free_port()
        self.bind = bind
        self.password = password
        self.proc = subprocess.Popen(["redis-server", "--port", str(self.port), "--bind", bind, "--save", "",
                                      "--appendonly", "no", "--dir", str(root), *args],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 10
        while self.cli("PING") != "PONG":
            assert time.monotonic() < deadline and self.proc.poll() is None, "redis-server did not start"
            time.sleep(0.05)
        self.url = f"redis://{bind}:{self.port}"

    def cli(self, *args):
        env = dict(os.environ, REDISCLI_AUTH=self.password) if self.password else None
        r = subprocess.run(["redis-cli", "-h", self.bind, "-p", str(self.port), *args], capture_output=True, text=True,
                           timeout=10, env=env)
        return r.stdout.strip()

    def pending_by_worker(self):
        """{consumer: passes it holds unacknowledged} in the group."""
        out = self.cli("XPENDING", "pt:work", "workers").splitlines()
        # Summary: count, smallest id, largest id, then consumer/count pairs.
        pairs = out[3:] if len(out) > 3 else []
        return {pairs[i]: int(pairs[i + 1]) for i in range(0, len(pairs) - 1, 2)}

    def stop(self):
        self.proc.kill()
        self.proc.wait(10)


class Worker:
    def __init__(self, root, redis_url, name, args=(), env=None, prefix=()):
        self.name = name
        self.log_path = Path(root) / f"{name}.log"
        self.log = open(self.log_path, "wb")
        self.proc = subprocess.Popen([*prefix, str(RENDER_WORKER), "--queue", redis_url, "-t", "1", "--name", name,
                                      "--claim-timeout", "1", *args], stdout=self.log, stderr=self.log,
                                     env=dict(os.environ, **env) if env else None)

    def text(self):
        return self.log_path.read_text(errors="replace")

    def stop(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait(10)
        self.log.close()


@pytest.fixture
def cluster(tmp_path, servers):
    redis = Redis(tmp_path)
    workers = []

    def start(n_workers=3):
        srv = servers("scaled", threads=1, args=["--queue", redis.url, "--units-in-flight", "4"])
        workers.extend(Worker(tmp_path, redis.url, f"w{i + 1}") for i in range(n_workers))
        return srv, workers, redis

    yield start
    for w in workers:
        w.stop()
        print(f"---- {w.name} ----\n{w.text()[-3000:]}")
    redis.stop()


def wait_for(predicate, what, timeout=10):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, f"timed out waiting: {what}"
        time.sleep(0.05)


def median_pass_rate(workers):
    """Samples per pixel per second of the workers' passes of 4 or more, median (their logs)."""
    rates = []
    for w in workers:
        for first, end, seconds in re.findall(r"samples \[(\d+), (\d+)\) in ([\d.]+) s", w.text()):
            n = int(end) - int(first)
            if n >= 4 and float(seconds) > 0:
                rates.append(n / float(seconds))
    rates.sort()
    return rates[len(rates) // 2] if rates else 0.0


def image(api, job_id):
    w, h, ch, attrs = read_exr(api.get(f"/api/jobs/{job_id}/image.exr").content)
    return w, h, ch, attrs


def test_killed_worker_loses_nothing_and_image_matches_single_process(cluster, servers):
    srv, workers, redis = cluster(3)
    api = srv.api
    assert api.get("/api/health").json()["rendering"] == redis.url
    wait_for(lambda: api.get("/api/health").json()["workers"] == 3, "three workers announced")
    job_id = api.submit(JOB)["id"]

    # Kill -9 a worker while it holds a pass (unacknowledged in the consumer group). First passes
    # take milliseconds, so a worker seen holding one may ack it before the kill: it is stopped
    # first, and killed only if it still holds the pass once stopped (else it goes on).
    victim, deadline = None, time.monotonic() + 60
    while victim is None:
        assert time.monotonic() < deadline, "no worker ever held a pass"
        holding = redis.pending_by_worker()
        job = api.job(job_id)
        assert job["state"] in ("queued", "running"), job
        if job["samples"] > 0:
            candidate = next((w for w in workers if holding.get(w.name, 0) > 0), None)
            if candidate is not None:
                candidate.proc.send_signal(signal.SIGSTOP)
                time.sleep(0.05)  # an ack already sent reaches Redis
                if redis.pending_by_worker().get(candidate.name, 0) > 0:
                    victim = candidate
                else:
                    candidate.proc.send_signal(signal.SIGCONT)
        time.sleep(0.02)
    victim.proc.send_signal(signal.SIGKILL)
    victim.proc.wait(10)
    wait_for(lambda: api.get("/api/health").json()["workers"] == 2, "the killed worker no longer counted", 15)

    done = api.wait(job_id, {"done", "failed", "cancelled"}, timeout=180)
    assert done["state"] == "done", done
    assert done["samples"] == JOB["width"] * JOB["height"] * JOB["spp"], "every sample rendered exactly once"
    claimed = [w.name for w in workers if "left by another worker" in w.text()]
    assert claimed, "no worker took over the killed worker's pass"
    left = [k for k in redis.cli("KEYS", f"pt:*:{job_id}:*").splitlines() if k]
    assert not left, f"the run's keys were not removed: {left}"
    # Passes start at 1 spp for a quick first picture and grow once the workers' speed is known.
    m = re.search(rf"job {job_id}: .*spp a pass: ([\d ]+)", srv.log_text())
    assert m, "the server logged no merge summary"
    sizes = [int(n) for n in m.group(1).split()]
    assert sizes[:2] == [1, 1] and sum(sizes) == JOB["spp"], sizes
    assert all(n & (n - 1) == 0 for n in sizes), f"pass sizes are powers of two: {sizes}"
    # Passes aim at about 2 s of a worker's time (kPassSeconds), so how far they grow depends on
    # the workers' speed: from 8 spp a second a pass outgrows the ramp's 8; at 16 or more (twice
    # that, for the rate's smoothing) it must. Under a sanitizer on a slow host workers ran 3-7
    # spp a second and the passes rightly stayed at 8; a plain build there ran about 28.
    rate = median_pass_rate(workers)
    if rate >= 16:
        assert max(sizes) >= 16, (sizes, f"{rate:.1f} spp/s")

    # The same job on an embedded server: the same samples, so the same image up to float rounding.
    single = servers("single", threads=2)
    ref_id = single.api.submit(JOB)["id"]
    assert single.api.wait(ref_id, {"done", "failed"}, timeout=180)["state"] == "done"
    w, h, dist, attrs = image(api, job_id)
    _, _, ref, _ = image(single.api, ref_id)
    assert attrs["pathtracer:backend"] == redis.url
    worst = 0.0
    for c in "RGB":
        for a, b in zip(dist[c], ref[c]):
            worst = max(worst, abs(a - b) / (abs(b) + 1e-3))
    assert worst < 1e-3, f"distributed and single-process images differ by up to {worst:.2e} (relative)"
    assert done["error_estimate"] is not None and done["error_estimate"] > 0
    # Each pixel's sample count reaches /pixels through the merges too: they add up to the job's.
    counts = struct.unpack(f"<{w * h * 4}f", api.get(f"/api/jobs/{job_id}/pixels").content)[3::4]
    assert sum(counts) == done["samples"] and min(counts) >= 1


def test_events_stream_merged_passes_and_adaptive_converges(cluster):
    srv, workers, redis = cluster(2)
    spec = dict(JOB, adaptive=True, spp=2048, width=96, height=72, seed=3)
    job_id = srv.api.submit(spec)["id"]
    stream = srv.events(job_id, timeout=120)
    kinds = {}
    for ev in stream:
        kinds[ev.kind] = kinds.get(ev.kind, 0) + 1
        if ev.kind == "end":
            break
    stream.close()
    job = srv.api.job(job_id)
    assert job["state"] == "done", job
    assert kinds.get("tile", 0) >= 2 * 9, f"tiles should stream as passes merge: {kinds}"  # 3x3 tiles, 2+ passes
    assert "adaptive sampling" in job["features"] and "glass" in job["features"]
    # Adaptive sampling on merged statistics stops converged pixels early.
    assert job["samples"] < spec["width"] * spec["height"] * spec["spp"], job["samples"]


def test_cancel_stops_the_workers(cluster):
    srv, workers, redis = cluster(2)
    spec = dict(JOB, spp=65536, width=160, height=120)
    job_id = srv.api.submit(spec)["id"]
    srv.api.wait(job_id, {"running"}, timeout=60, samples=1)
    t0 = time.monotonic()
    srv.api.delete(f"/api/jobs/{job_id}")
    job = srv.api.wait(job_id, {"cancelled"}, timeout=30)
    assert job["state"] == "cancelled"
    # Workers see the run's key gone and drop their passes: nothing stays pending for long.
    deadline = time.monotonic() + 20
    while redis.pending_by_worker():
        assert time.monotonic() < deadline, f"passes still held after cancel: {redis.pending_by_worker()}"
        time.sleep(0.1)
    assert time.monotonic() - t0 < 20
    assert all(w.proc.poll() is None for w in workers), "a worker died"


def test_a_worker_builds_a_scene_once_for_every_job_of_that_content(cluster):
    srv, workers, redis = cluster(1)
    # The same bytes under a second name: one content, one upload, one build.
    shutil.copy(srv.scenes / "cornell.dae", srv.scenes / "cornell_copy.dae")
    for scene, seed in (("cornell", 1), ("cornell_copy", 2), ("cornell", 3)):
        job_id = srv.api.submit(dict(JOB, scene=scene, seed=seed, spp=4, width=64, height=48))["id"]
        assert srv.api.wait(job_id, {"done", "failed"}, timeout=60)["state"] == "done"
    builds = [line for line in workers[0].text().splitlines() if "built in" in line]
    assert len(builds) == 1, f"the worker rebuilt a scene it had: {builds}"
    scene_keys = [k for k in redis.cli("KEYS", "pt:scene:*").splitlines() if k]
    assert len(scene_keys) == 1, scene_keys
    # A different scene is built: the cache is keyed by content, not reused blindly.
    text = (srv.scenes / "cornell.dae").read_text().replace("</COLLADA>", "<!-- edited --></COLLADA>")
    (srv.scenes / "cornell_edited.dae").write_text(text)
    job_id = srv.api.submit(dict(JOB, scene="cornell_edited", spp=4, width=64, height=48))["id"]
    assert srv.api.wait(job_id, {"done", "failed"}, timeout=60)["state"] == "done"
    builds = [line for line in workers[0].text().splitlines() if "built in" in line]
    assert len(builds) == 2, builds


def test_a_camera_field_reaches_the_worker(cluster, servers):
    """A job's pose travels with its spec through Redis: the worker renders the view the job shows,
    the same image as an embedded server's."""
    srv, workers, redis = cluster(1)
    spec = dict(JOB, spp=4, width=64, height=48, camera={"position": [2.5, 1.2, 3.0], "target": [0, 0.4, 0], "vfov": 40})
    job_id = srv.api.submit(spec)["id"]
    done = srv.api.wait(job_id, {"done", "failed"}, timeout=90)
    assert done["state"] == "done" and done["view"]["position"] == [2.5, 1.2, 3.0] and done["view"]["vfov"] == 40
    single = servers("single_camera", threads=2)
    ref_id = single.api.submit(spec)["id"]
    assert single.api.wait(ref_id, {"done", "failed"}, timeout=90)["state"] == "done"
    _, _, dist, attrs = image(srv.api, job_id)
    _, _, ref, _ = image(single.api, ref_id)
    assert attrs["pathtracer:backend"] == redis.url
    worst = max(abs(a - b) / (abs(b) + 1e-3) for c in "RGB" for a, b in zip(dist[c], ref[c]))
    assert worst < 1e-3, f"the worker's view differs from the embedded server's by up to {worst:.2e}"
    # And it is not the scene's own framing.
    framed_id = single.api.submit(dict(spec, camera=None))["id"]
    assert single.api.wait(framed_id, {"done", "failed"}, timeout=90)["state"] == "done"
    _, _, framed, _ = image(single.api, framed_id)
    assert sum(abs(a - b) for a, b in zip(framed["G"], ref["G"])) > 0.05 * sum(ref["G"])


def test_a_pass_rendered_twice_is_merged_once(cluster):
    """A worker stopped while it holds a pass looks dead: another claims and renders the pass. Woken
    again, the first one finishes it too and sends its copy: the server merges only the first."""
    srv, workers, redis = cluster(2)
    api = srv.api
    wait_for(lambda: api.get("/api/health").json()["workers"] == 2, "two workers announced")
    spec = dict(JOB, spp=512)  # long enough that the second copy arrives while the job runs
    job_id = api.submit(spec)["id"]
    sleeper, deadline = None, time.monotonic() + 60
    while sleeper is None:  # as in the kill test: stopped while it still holds a pass
        assert time.monotonic() < deadline, "no worker ever held a pass"
        assert api.job(job_id)["state"] in ("queued", "running")
        candidate = next((w for w in workers if redis.pending_by_worker().get(w.name, 0) > 0), None)
        if candidate is not None:
            candidate.proc.send_signal(signal.SIGSTOP)
            time.sleep(0.05)
            if redis.pending_by_worker().get(candidate.name, 0) > 0:
                sleeper = candidate
            else:
                candidate.proc.send_signal(signal.SIGCONT)
        time.sleep(0.02)
    other = next(w for w in workers if w is not sleeper)
    wait_for(lambda: "left by another worker" in other.text(), "the other worker claimed the held pass", 30)
    claimed = re.search(rf"claimed pass (\d+) of job {job_id}", other.text()).group(1)
    wait_for(lambda: re.search(rf"job {job_id} pass {claimed}: samples", other.text()), "the claimed pass rendered", 60)
    sleeper.proc.send_signal(signal.SIGCONT)
    wait_for(lambda: re.search(rf"job {job_id} pass {claimed}: samples", sleeper.text()), "the woken worker's copy", 60)
    assert api.job(job_id)["state"] == "running", "the job ended before the second copy came: nothing was tested"
    done = api.wait(job_id, {"done", "failed", "cancelled"}, timeout=300)
    assert done["state"] == "done", done
    assert done["samples"] == spec["width"] * spec["height"] * spec["spp"], "a pass was merged twice"
    counts = struct.unpack(f"<{spec['width'] * spec['height'] * 4}f", api.get(f"/api/jobs/{job_id}/pixels").content)[3::4]
    assert set(counts) == {spec["spp"]}, "a pixel's count is not the job's spp"
