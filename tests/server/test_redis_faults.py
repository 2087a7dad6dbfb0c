"""Redis faults under the scale-out backend (docs/scale-out.md, "Failures"), against a real
redis-server, render-server --queue and render-worker processes:

- a pass that keeps failing (its run's hash overwritten with a string: WRONGTYPE) is tried
  kMaxDeliveries = 3 times, set aside in the dead-letter stream pt:dead and acknowledged; its job
  fails naming the reason, and the workers and the server go on with later jobs;
- an error text from Redis that is not UTF-8 fails its job with U+FFFD in place of the bad bytes,
  in the API, the event stream and job.json;
- Redis killed mid-job and started again empty on the same port: the server and the workers
  reconnect, the server puts the run back (group, scene, hash, unmerged passes) and the job finishes
  with every sample and the single-process image;
- the server killed mid-job and started again: the job resumes from its merged film's checkpoint
  and still ends with every sample once and the single-process image;
- Redis gone for good: the job fails after --redis-timeout naming Redis, the server stays up, and a
  worker gives up after its own --redis-timeout."""
import json
import re
import signal
import socket

import pytest

from test_scale_out import JOB, Redis, Worker, image, wait_for

SMALL = dict(JOB, width=64, height=48, spp=16)
FINAL = {"done", "failed", "cancelled"}


@pytest.fixture
def cluster(tmp_path, servers):
    """start(workers=N, server_args=[], worker_args=[]) -> (server, workers, redis); redis_on(port)
    starts another redis-server on a port (a restart); everything is killed at the end."""
    procs = {"redis": [], "workers": []}

    def start(workers=2, server_args=(), worker_args=()):
        redis = Redis(tmp_path)
        procs["redis"].append(redis)
        srv = servers("scaled", threads=1, args=["--queue", redis.url, "--units-in-flight", "4", *server_args])
        add_workers(redis, workers, worker_args)
        return srv, procs["workers"], redis

    def add_workers(redis, n, args=()):
        first = len(procs["workers"])
        procs["workers"].extend(Worker(tmp_path, redis.url, f"w{first + i + 1}", args) for i in range(n))
        return procs["workers"]

    def redis_on(port):
        redis = Redis(tmp_path, port)
        procs["redis"].append(redis)
        return redis

    start.add_workers = add_workers
    start.redis_on = redis_on
    yield start
    for w in procs["workers"]:
        w.stop()
        print(f"---- {w.name} ----\n{w.text()[-3000:]}")
    for r in procs["redis"]:
        if r.proc.poll() is None:
            r.stop()


def call(redis, *args):
    """One command over RESP, binary-safe (redis-cli cannot show where a stream entry ends):
    bulk strings come back as bytes, arrays as lists."""
    with socket.create_connection(("127.0.0.1", redis.port), timeout=10) as sock:
        parts = [a if isinstance(a, bytes) else str(a).encode() for a in args]
        sock.sendall(b"*%d\r\n" % len(parts) + b"".join(b"$%d\r\n%s\r\n" % (len(p), p) for p in parts))
        reader = sock.makefile("rb")

        def read():
            line = reader.readline()[:-2]
            kind, rest = line[:1], line[1:]
            if kind in (b"+", b"-"):
                return rest.decode(errors="replace") if kind == b"+" else RuntimeError(rest.decode(errors="replace"))
            if kind == b":":
                return int(rest)
            if kind == b"$":
                return None if int(rest) < 0 else reader.read(int(rest) + 2)[:-2]
            assert kind == b"*", line
            return None if int(rest) < 0 else [read() for _ in range(int(rest))]

        return read()


def run_key(redis, job_id):
    """The run's hash key pt:job:<job>:<run>, once the server has written it."""
    keys = []
    wait_for(lambda: keys.extend(call(redis, "KEYS", f"pt:job:{job_id}:*")) or keys,
             "the server put the run's keys in Redis", 30)
    return keys[0].decode()


def stream_entries(redis, key):
    """A stream's entries as {field: value} dicts of text."""
    return [{k.decode(): v.decode(errors="replace") for k, v in zip(body[::2], body[1::2])}
            for _, body in call(redis, "XRANGE", key, "-", "+")]


def failed_tries(workers, job_id):
    """{pass: [delivery numbers]} from the workers' "failed (delivery d of 3)" lines for a job."""
    tries = {}
    for w in workers:
        for unit, d in re.findall(rf"job {job_id} pass (\d+) failed \(delivery (\d+) of 3\)", w.text()):
            tries.setdefault(int(unit), []).append(int(d))
    return tries


def assert_single_process_image(srv, job_id, servers):
    """The job's image is the one a single process renders of JOB: the samples are the same, only
    the merge order differs (so within float rounding, not bit for bit)."""
    single = servers("single", threads=2)
    ref_id = single.api.submit(JOB)["id"]
    assert single.api.wait(ref_id, FINAL, timeout=180)["state"] == "done"
    _, _, dist, _ = image(srv.api, job_id)
    _, _, ref, _ = image(single.api, ref_id)
    worst = max(abs(a - b) / (abs(b) + 1e-3) for c in "RGB" for a, b in zip(dist[c], ref[c]))
    assert worst < 1e-3, f"the image differs from a single process's by up to {worst:.2e} (relative)"


def test_a_pass_that_keeps_failing_is_dead_lettered_and_fails_its_job(cluster):
    srv, workers, redis = cluster(workers=0)
    job_id = srv.api.submit(SMALL)["id"]
    key = run_key(redis, job_id)
    # Damage the run's hash before any worker reads it: every read of it answers WRONGTYPE.
    assert call(redis, "SET", key, "not a hash") == "OK"
    cluster.add_workers(redis, 2)

    job = srv.api.wait(job_id, FINAL, timeout=120)
    assert job["state"] == "failed", job
    assert "WRONGTYPE" in job["message"] and key in job["message"] and "pt:dead" in job["message"], job["message"]
    assert "failed 3 times" in job["message"], job["message"]

    dead = [e for e in stream_entries(redis, "pt:dead") if e.get("job") == job_id]
    assert dead, stream_entries(redis, "pt:dead")
    for e in dead:
        assert e["deliveries"] == "3" and "WRONGTYPE" in e["reason"] and e["run"] == key.split(":")[-1], e

    # Acknowledged and gone from the work stream: nothing of the job is pending or queued.
    wait_for(lambda: call(redis, "XPENDING", "pt:work", "workers")[0] == 0, "no pass pending", 30)
    wait_for(lambda: all(e.get("job") != job_id for e in stream_entries(redis, "pt:work")), "the job's passes left pt:work", 30)
    tries = failed_tries(workers, job_id)
    for e in dead:
        assert sorted(tries[int(e["unit"])]) == [1, 2, 3], tries

    # The server and the workers go on: a later job renders, and no pass of the failed job is tried again.
    later = srv.api.submit(dict(SMALL, seed=2))["id"]
    assert srv.api.wait(later, FINAL, timeout=60)["state"] == "done"
    assert failed_tries(workers, job_id) == tries
    assert srv.alive() and all(w.proc.poll() is None for w in workers)


def test_an_error_from_redis_that_is_not_utf8_fails_the_job_without_harm(cluster):
    srv, workers, redis = cluster(workers=0)
    job_id = srv.api.submit(SMALL)["id"]
    run = run_key(redis, job_id).split(":")[-1]
    # A failure as a worker posts one, its text not UTF-8: a stray byte, a cut sequence, a surrogate.
    bad = b"worker says \xff\xfe, cut \xe2\x82 and surrogate \xed\xa0\x80 end"
    assert isinstance(call(redis, "XADD", f"pt:results:{job_id}:{run}", "*", "unit", "0", "worker", "fake", "error", bad), bytes)

    job = srv.api.wait(job_id, FINAL, timeout=60)
    assert job["state"] == "failed", job
    assert job["message"].startswith("worker says \ufffd\ufffd, cut ") and job["message"].endswith(" end"), job
    assert "\ufffd" * 3 in job["message"]  # the surrogate's three bytes
    stream = srv.events(job_id, timeout=30)
    end = next((ev for ev in iter(stream.next, None) if ev.kind == "end"), None)
    stream.close()
    assert end is not None and end.data["state"] == "failed", end
    # The job's file on disk holds the same, valid text (a restart shows the failure, not a re-run).
    saved = json.loads((srv.data / "jobs" / job_id / "job.json").read_text(encoding="utf-8", errors="strict"))
    assert saved["state"] == "failed" and saved["message"] == job["message"], saved
    later = srv.api.submit(dict(SMALL, seed=2))["id"]
    cluster.add_workers(redis, 1)
    assert srv.api.wait(later, FINAL, timeout=60)["state"] == "done"


def test_a_redis_restart_mid_job_loses_nothing(cluster, servers):
    srv, workers, redis = cluster(workers=2)
    job_id = srv.api.submit(JOB)["id"]
    srv.api.wait(job_id, {"running"}, timeout=60, samples=1)
    # Killed mid-job and started again without its data: streams, group, run keys and scene are gone.
    # The new one starts once the server and a worker have found Redis away (they wait with back-off).
    redis.stop()
    wait_for(lambda: "lost Redis" in srv.log_text() and any("lost Redis" in w.text() for w in workers),
             "the server and a worker noticed Redis gone", 30)
    redis = cluster.redis_on(redis.port)

    done = srv.api.wait(job_id, FINAL, timeout=180)
    assert done["state"] == "done", done
    assert done["samples"] == JOB["width"] * JOB["height"] * JOB["spp"], "every sample merged exactly once"
    assert "issuing its" in srv.log_text(), "the server did not put the run back"
    assert any(re.search(r"Redis at \S+ is back after", w.text()) for w in workers), "no worker reconnected"
    assert all(w.proc.poll() is None for w in workers), "a worker died"
    assert_single_process_image(srv, job_id, servers)
    # Later jobs render on the new Redis as usual.
    later = srv.api.submit(dict(SMALL, seed=2))["id"]
    assert srv.api.wait(later, FINAL, timeout=60)["state"] == "done"


def test_a_server_killed_mid_job_resumes_its_merged_film(cluster, servers):
    args = ["--queue", None, "--units-in-flight", "4", "--checkpoint-interval", "0"]
    srv, workers, redis = cluster(workers=2, server_args=args[4:])
    job_id = srv.api.submit(JOB)["id"]
    job_json = srv.data / "jobs" / job_id / "job.json"
    wait_for(lambda: json.loads(job_json.read_text())["checkpoint"]["samples"] > 0, "a first checkpoint", 60)
    srv.proc.send_signal(signal.SIGSTOP)
    on_disk = json.loads(job_json.read_text())
    assert on_disk["state"] == "running", "the job ended before the kill: nothing is tested"
    srv.kill()

    args[1] = redis.url
    srv = servers("scaled", threads=1, args=args)
    assert srv.api.job(job_id)["samples"] >= on_disk["checkpoint"]["samples"] > 0, "spp_done started again from 0"
    done = srv.api.wait(job_id, FINAL, timeout=180)
    assert done["state"] == "done", done
    assert "resuming from its checkpoint" in srv.log_text()
    assert done["samples"] == JOB["width"] * JOB["height"] * JOB["spp"], "every sample merged exactly once"
    assert_single_process_image(srv, job_id, servers)


def test_redis_gone_for_good_fails_the_job_after_redis_timeout(cluster):
    srv, workers, redis = cluster(workers=1, server_args=["--redis-timeout", "2"], worker_args=["--redis-timeout", "2"])
    job_id = srv.api.submit(dict(JOB, spp=65536))["id"]
    srv.api.wait(job_id, {"running"}, timeout=60, samples=1)
    redis.stop()

    job = srv.api.wait(job_id, FINAL, timeout=60)
    assert job["state"] == "failed", job
    assert f"Redis at {redis.url} was unreachable for 2 s" in job["message"], job["message"]
    # The server stays up: health answers, and a new job fails the same way rather than hanging.
    health = srv.api.get("/api/health").json()
    assert health["workers"] == 0, health
    later = srv.api.submit(SMALL)["id"]
    job = srv.api.wait(later, FINAL, timeout=60)
    assert job["state"] == "failed" and "unreachable for 2 s" in job["message"], job
    assert srv.alive()
    # The worker gives up too, after its own --redis-timeout, with a non-zero status.
    assert workers[0].proc.wait(60) == 1
    assert "unreachable for 2 s" in workers[0].text() and "giving up" in workers[0].text()


def test_a_cancel_ends_the_wait_for_redis(cluster):
    srv, workers, redis = cluster(workers=1)
    job_id = srv.api.submit(dict(JOB, spp=65536))["id"]
    srv.api.wait(job_id, {"running"}, timeout=60, samples=1)
    redis.stop()
    wait_for(lambda: "lost Redis" in srv.log_text(), "the server noticed Redis gone", 30)
    assert srv.api.job(job_id)["state"] == "running"  # waiting for Redis (--redis-timeout 300), not failed
    srv.api.delete(f"/api/jobs/{job_id}")
    assert srv.api.wait(job_id, FINAL, timeout=30)["state"] == "cancelled"
