"""A render farm's security (docs/scale-out.md, "Security") against a real redis-server,
render-server --queue and render-worker processes:

- a Redis with `requirepass`: the server reads the password from --redis-password-file, a worker
  from PT_REDIS_PASSWORD, neither shows it in its process list, and a job renders; a wrong password
  and a missing one each end a worker at once (status 1) with one clear message, and the server
  refuses to start;
- a Redis whose users follow scripts/redis-farm.acl (the documented rules): a job renders through
  them, and the worker's user cannot write a run's spec or flush the database;
- forged results written straight into a job's result stream (unsigned, signed with another key,
  for another job, moved from another job, more samples than asked, an error entry, a pass never
  issued, a replayed pass) are each refused, counted and logged with the worker's name, and the
  job's image and sample count equal a render by honest workers only; a forged pass request is
  refused by the workers; a worker without the key stops with a clear message and its pass is
  rendered by another;
- a farm whose Redis is not on loopback is refused without a key unless --insecure-farm."""
import hashlib
import hmac
import os
import signal
import struct
import subprocess
import time
from pathlib import Path

import pytest

from resp import Resp, RespError, entry_fields
from support import RENDER_SERVER, SOURCE_DIR
from test_scale_out import JOB, RENDER_WORKER, Redis, Worker, image, wait_for

SMALL = dict(JOB, width=64, height=48, spp=64)
FINAL = {"done", "failed", "cancelled"}
ACL_RULES = SOURCE_DIR / "scripts/redis-farm.acl"


def write_secret(path, text):
    path.write_text(text + "\n")
    path.chmod(0o600)
    return str(path)


def farm_sig(key, *fields):
    """The farm's signature (server/farm_security.cpp): HMAC-SHA256 over length-prefixed fields."""
    mac = hmac.new(key, digestmod=hashlib.sha256)
    for f in fields:
        b = f if isinstance(f, bytes) else str(f).encode()
        mac.update(struct.pack("<Q", len(b)))
        mac.update(b)
    return mac.hexdigest()


def film_pass(w, h, first, count, samples, value=1000.0):
    """A well-formed pt::FilmPass (renderer/film_pass.cpp) painting every pixel with `value`."""
    n = w * h
    header = struct.pack("<8s4I2QdQ2I", b"PTFILM2\0", w, h, first, count, n * count, 0, 0.01, 0, 0, 0)
    return (header + struct.pack(f"<{3 * n}f", *([value] * (3 * n))) + struct.pack(f"<{n}f", *([value * value] * n)) +
            struct.pack(f"<{n}I", *([samples] * n)))


def assert_same_image(api, job_id, ref_api, ref_id):
    _, _, dist, _ = image(api, job_id)
    _, _, ref, _ = image(ref_api, ref_id)
    worst = max(abs(a - b) / (abs(b) + 1e-3) for c in "RGB" for a, b in zip(dist[c], ref[c]))
    assert worst < 1e-3, f"the farm's image differs from an honest render by up to {worst:.2e} (relative)"


def reference(servers, spec):
    single = servers("single", threads=2)
    ref_id = single.api.submit(spec)["id"]
    assert single.api.wait(ref_id, FINAL, timeout=180)["state"] == "done"
    return single.api, ref_id


def farm(api):
    return api.get("/api/health").json()["farm"]


@pytest.fixture
def stack(tmp_path):
    """Redis servers and workers started by a test, stopped after it (their logs printed)."""
    redises, workers = [], []

    class Stack:
        key = write_secret(tmp_path / "farm.key", "k3y-" + os.urandom(24).hex())
        key_bytes = Path(key).read_bytes().rstrip()

        def redis(self, **kw):
            redises.append(Redis(tmp_path, **kw))
            return redises[-1]

        def worker(self, url, name, *args, env=None, prefix=()):
            w = Worker(tmp_path, url, name, args, env=env, prefix=prefix)
            workers.append(w)
            return w

    yield Stack()
    for w in workers:
        w.stop()
        print(f"---- {w.name} ----\n{w.text()[-3000:]}")
    for r in redises:
        r.stop()


def run_server_expecting_failure(tmp_path, *args):
    data = tmp_path / "refused"
    r = subprocess.run([str(RENDER_SERVER), "--port", "0", "--data", str(data), "--no-bundled-scenes", *args],
                       capture_output=True, text=True, timeout=30)
    return r.returncode, r.stderr


def test_requirepass_from_a_file_and_the_environment_and_wrong_passwords(tmp_path, servers, stack):
    password = "Pa55-" + os.urandom(8).hex()
    redis = stack.redis(args=["--requirepass", password], password=password)
    pw_file = write_secret(tmp_path / "redis.pw", password)
    srv = servers("farm", threads=1, args=["--queue", redis.url, "--redis-password-file", pw_file,
                                           "--farm-key-file", stack.key])
    w = stack.worker(redis.url, "w1", "--farm-key-file", stack.key, env={"PT_REDIS_PASSWORD": password})
    job_id = srv.api.submit(SMALL)["id"]
    done = srv.api.wait(job_id, FINAL, timeout=180)
    assert done["state"] == "done" and done["samples"] == 64 * 48 * 64, done
    f = farm(srv.api)
    assert f["authenticated"] and f["signed"] and not f["insecure"] and f["rejected"] == 0, f
    assert [x["passes"] for x in f["workers"] if x["name"] == "w1"][0] >= 1, f
    for proc in (srv.proc, w.proc):
        assert password.encode() not in Path(f"/proc/{proc.pid}/cmdline").read_bytes()

    # Wrong or missing passwords: one message and status 1 at once, never a retry loop.
    bad_file = write_secret(tmp_path / "bad.pw", "not-" + password)
    for name, args, env, expect in [
            ("wrong", ["--redis-password-file", bad_file], None, "WRONGPASS"),
            ("missing", [], {"PT_REDIS_PASSWORD": ""}, "NOAUTH")]:
        t0 = time.monotonic()
        bad = stack.worker(redis.url, name, "--farm-key-file", stack.key, *args, env=env)
        assert bad.proc.wait(20) == 1, bad.text()
        assert time.monotonic() - t0 < 15
        text = bad.text()
        assert expect in text and "--redis-password-file" in text and password not in text, text
        assert "retrying" not in text and "lost Redis" not in text, text
    rc, err = run_server_expecting_failure(tmp_path, "--queue", redis.url, "--redis-password-file", bad_file,
                                           "--farm-key-file", stack.key)
    assert rc == 1 and "WRONGPASS" in err and password not in err, err

    # The password in the URL works too, with a warning that the process list shows it. This worker's
    # name is longer than the 64 bytes the server shows: its results are checked against the name it signed.
    w.stop()
    long_name = "w-url-" + "x" * 70
    url_worker = stack.worker(f"redis://:{password}@127.0.0.1:{redis.port}", long_name, "--farm-key-file", stack.key)
    wait_for(lambda: "process list" in url_worker.text(), "the URL password warning")
    job2 = srv.api.submit(dict(SMALL, seed=9))["id"]
    assert srv.api.wait(job2, FINAL, timeout=180)["state"] == "done"
    f = farm(srv.api)
    assert f["rejected"] == 0 and any(x["name"] == long_name[:64] + "..." and x["passes"] > 0 for x in f["workers"]), f


def acl_users(passwords):
    """ACL SETUSER argument lists from scripts/redis-farm.acl, with these passwords."""
    users = []
    for line in ACL_RULES.read_text().splitlines():
        if line.startswith("user "):
            words = line.split()[1:]
            users.append([w if not w.startswith(">") else ">" + passwords[words[0]] for w in words])
    return users


def test_acl_users_with_the_documented_rules(tmp_path, servers, stack):
    admin = "admin-" + os.urandom(8).hex()
    passwords = {"render-server": "srv-" + os.urandom(8).hex(), "render-worker": "wrk-" + os.urandom(8).hex()}
    users = acl_users(passwords)
    assert {u[0] for u in users} == set(passwords), "scripts/redis-farm.acl names the two users"
    # The file as documented: loaded by redis-server --aclfile, with the passwords filled in.
    acl = tmp_path / "farm.acl"
    acl.write_text("".join(" ".join(["user", *u]) + "\n" for u in users) + f"user default on >{admin} ~* &* +@all\n")
    redis = stack.redis(args=["--aclfile", str(acl)], password=admin)
    assert sorted(redis.cli("ACL", "USERS").split()) == ["default", "render-server", "render-worker"]
    srv = servers("acl", threads=1, args=[
        "--queue", f"redis://render-server@127.0.0.1:{redis.port}", "--farm-key-file", stack.key,
        "--redis-password-file", write_secret(tmp_path / "server.pw", passwords["render-server"])])
    worker_url = f"redis://render-worker@127.0.0.1:{redis.port}"
    stack.worker(worker_url, "w1", "--farm-key-file", stack.key,
                 "--redis-password-file", write_secret(tmp_path / "worker.pw", passwords["render-worker"]))
    job_id = srv.api.submit(SMALL)["id"]
    done = srv.api.wait(job_id, FINAL, timeout=180)
    assert done["state"] == "done" and done["samples"] == 64 * 48 * 64, done
    assert farm(srv.api)["queue"] == worker_url.replace("render-worker", "render-server")

    # The worker's user reads runs and scenes but cannot change them, nor anything outside pt:.
    r = Resp("127.0.0.1", redis.port, "render-worker", passwords["render-worker"])
    for forbidden in (["HSET", "pt:job:x:y", "spec", "{}"], ["SET", "pt:scene:x", "forged"], ["FLUSHALL"],
                      ["SET", "elsewhere", "1"], ["CONFIG", "GET", "*"]):
        with pytest.raises(RespError, match="NOPERM"):
            r.call(*forbidden)
    r.close()


def test_forged_results_are_refused_counted_and_change_nothing(tmp_path, servers, stack):
    redis = stack.redis()
    srv = servers("signed", threads=1, args=["--queue", redis.url, "--farm-key-file", stack.key,
                                             "--units-in-flight", "4"])
    spec = dict(SMALL, spp=256)  # long enough to replay a merged pass while the job runs
    job_id = srv.api.submit(spec)["id"]
    r = Resp("127.0.0.1", redis.port)
    wait_for(lambda: r.call("XLEN", "pt:work") >= 4, "the server issued passes", 30)
    _, first = entry_fields(r.call("XRANGE", "pt:work", "-", "+", "COUNT", "1")[0])
    run = first["run"].decode()
    assert first["job"].decode() == job_id and first["unit"] == b"0" and first["sig"], first
    results = f"pt:results:{job_id}:{run}"
    w, h = spec["width"], spec["height"]
    key, wrong = stack.key_bytes, b"another-key-" + os.urandom(16)
    honest_bytes = film_pass(w, h, 0, 1, 1)

    def forge(unit, pass_bytes, sign_key=None, job=job_id, signed_job=None, worker="mallory", error=None):
        fields = ["job", job, "run", run, "unit", str(unit), "worker", worker]
        if error is not None:
            fields += ["error", error]
            if sign_key:
                fields += ["sig", farm_sig(sign_key, "pt-error", signed_job or job, run, unit, worker, error)]
        else:
            fields += ["attempt", "1", "pass", pass_bytes, "features", ""]
            if sign_key:
                fields += ["sig", farm_sig(sign_key, "pt-result", signed_job or job, run, unit, worker, "1", pass_bytes,
                                           "")]
        r.call("XADD", results, "*", *fields)

    forge(0, honest_bytes)                                          # unsigned
    forge(0, honest_bytes, wrong)                                   # signed with another key
    forge(0, honest_bytes, key, job="0123456789abcdef")             # a pass for another job
    forge(0, honest_bytes, key, signed_job="0123456789abcdef")      # moved from another job
    forge(0, film_pass(w, h, 0, 8, 8), key)                         # samples [0, 8) for [0, 1)
    forge(0, film_pass(w, h, 0, 1, 5), key)                         # 5 samples a pixel in a 1-sample pass
    forge(0, None, error="a forged failure")                        # an unsigned error entry
    forge(999, honest_bytes, key)                                   # never issued
    expected = ["unsigned", "bad signature", "another job", "bad signature", "asked for [0, 1)",
                "more than the pass's 1", "unsigned", "never issued"]
    wait_for(lambda: farm(srv.api)["rejected"] == len(expected), "the server refused the forged results", 30)
    assert srv.api.job(job_id)["samples"] == 0, "a forged pass changed the job's sample count"

    # A worker without the key stops at the first signed pass and gives it back.
    keyless = stack.worker(redis.url, "keyless")
    assert keyless.proc.wait(30) == 2, keyless.text()
    assert "--farm-key-file" in keyless.text(), keyless.text()
    # A forged pass request: honest workers refuse it.
    r.call("XADD", "pt:work", "*", "job", job_id, "run", run, "unit", "0", "first", "0", "count", "64", "mask", "")

    w1 = stack.worker(redis.url, "w1", "--farm-key-file", stack.key)
    wait_for(lambda: farm(srv.api)["passes_merged"] >= 1, "an honest pass merged", 60)
    w1.proc.send_signal(signal.SIGSTOP)  # the job must still be running for the replay below
    try:
        honest = [entry_fields(e)[1] for e in r.call("XRANGE", results, "-", "+")]
        honest = [e for e in honest if e.get("worker") == b"w1" and "pass" in e]
        assert honest, "no honest result in the stream"
        r.call("XADD", results, "*", *[x for kv in honest[0].items() for x in kv])  # replayed verbatim
        expected.append("replayed")
        wait_for(lambda: farm(srv.api)["rejected"] == len(expected), "the replay refused", 30)
    finally:
        w1.proc.send_signal(signal.SIGCONT)
    w2 = stack.worker(redis.url, "w2", "--farm-key-file", stack.key)
    done = srv.api.wait(job_id, FINAL, timeout=240)
    assert done["state"] == "done", done
    assert done["samples"] == w * h * spec["spp"], "every sample once, and none forged"

    f = farm(srv.api)
    reasons = [x["reason"] for x in reversed(f["rejections"])]
    assert len(reasons) == len(expected), reasons
    for want, got in zip(expected, reasons):
        assert want in got, (want, got)
    assert {x["worker"] for x in f["rejections"]} == {"mallory", "w1"}  # the replay claims w1's name
    mallory = [x for x in f["workers"] if x["name"] == "mallory"][0]
    assert mallory["rejected"] == len(expected) - 1 and mallory["passes"] == 0, mallory
    log = srv.log_text()
    assert log.count("refused a result from worker 'mallory'") == len(expected) - 1, log[-3000:]
    assert any(f"refused pass 0 of job {job_id}: unsigned" in x.text() for x in (w1, w2)), "the forged request"

    ref_api, ref_id = reference(servers, spec)
    assert_same_image(srv.api, job_id, ref_api, ref_id)
    r.close()


def test_unsigned_farm_stays_on_loopback(tmp_path):
    # 192.0.2.1 (documentation range) is never contacted: the check comes before any connection.
    rc, err = run_server_expecting_failure(tmp_path, "--queue", "redis://192.0.2.1:6379")
    assert rc == 1 and "not on loopback" in err and "--farm-key-file" in err and "--insecure-farm" in err, err
    r = subprocess.run([str(RENDER_WORKER), "--queue", "redis://192.0.2.1:6379"], capture_output=True, text=True,
                       timeout=30)
    assert r.returncode == 2 and "not on loopback" in r.stderr, r.stderr
    short = Path(tmp_path / "short.key")
    short.write_text("too short\n")
    r = subprocess.run([str(RENDER_WORKER), "--queue", "redis://127.0.0.1:1", "--farm-key-file", str(short)],
                       capture_output=True, text=True, timeout=30)
    assert r.returncode == 2 and "short.key" in r.stderr and "at least 16" in r.stderr, r.stderr


def test_health_shows_the_farm_in_full_only_with_the_token(servers, stack):
    import requests
    redis = stack.redis()
    srv = servers("token", threads=1, token="farm-t0ken", args=["--queue", redis.url])
    stack.worker(redis.url, "w1")
    wait_for(lambda: srv.api.get("/api/health").json()["workers"] == 1, "the worker announced")
    plain = requests.get(srv.url + "/api/health", timeout=10).json()["farm"]
    assert set(plain) == {"authenticated", "signed", "insecure", "passes_merged", "rejected"}, plain
    assert not plain["signed"] and not plain["authenticated"] and not plain["insecure"], plain  # loopback
    full = farm(srv.api)  # the test client sends the token
    assert full["queue"] == redis.url and [w["name"] for w in full["workers"]] == ["w1"], full
