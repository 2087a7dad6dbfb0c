"""A render farm across a network (docs/scale-out.md, "Security"):

- a worker reaching Redis through an encrypted spiped tunnel (Debian 12's hiredis has no TLS), with
  the password and the farm key: the job renders, and the tunnel's port does not speak Redis in
  the clear;
- two hosts for real: Redis and the server in one network namespace, a worker in another, joined
  by a veth pair with addresses from the documentation range 192.0.2.0/24 (only inside the
  namespaces this test makes; no traffic reaches any other address). The worker logs in as the
  ACL user of scripts/redis-farm.acl over an interface that is not loopback; its link is cut
  mid-pass (down, then up) and the job still finishes with every sample once and the image of an
  honest single-process render.
The namespace test re-runs itself inside `unshare -Urn` (a user and network namespace of its own,
no privileges needed); where the machine cannot make namespaces it is skipped, even under CI=true,
and a machine that can but fails the test fails it."""
import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from resp import Resp
from support import cannot_run
from test_farm_security import (FINAL, SMALL, acl_users, assert_same_image, farm, reference, stack,  # noqa: F401
                                write_secret)
from test_scale_out import RENDER_WORKER, free_port, wait_for

IN_NETNS = "PT_FARM_IN_NETNS"


def run(*cmd):
    r = subprocess.run(list(cmd), capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, f"{' '.join(cmd)}: {r.stderr}"
    return r.stdout


def test_worker_through_an_encrypted_tunnel(tmp_path, servers, stack):
    if not shutil.which("spiped"):
        cannot_run("spiped is not installed (scripts/install-deps.sh installs it)")
    password = "tunnel-" + os.urandom(8).hex()
    redis = stack.redis(args=["--requirepass", password], password=password)
    tunnel_key = tmp_path / "tunnel.key"
    tunnel_key.write_bytes(os.urandom(32))
    tunnel_key.chmod(0o600)
    far, near = free_port(), free_port()
    # The Redis host decrypts (-d) what arrives on `far`; the worker's host encrypts (-e) what its
    # worker sends to `near`. Both ends run here, on loopback.
    pipes = [subprocess.Popen(["spiped", "-F", "-d", "-s", f"[127.0.0.1]:{far}", "-t", f"[127.0.0.1]:{redis.port}",
                               "-k", str(tunnel_key), "-p", str(tmp_path / "d.pid")]),
             subprocess.Popen(["spiped", "-F", "-e", "-s", f"[127.0.0.1]:{near}", "-t", f"[127.0.0.1]:{far}",
                               "-k", str(tunnel_key), "-p", str(tmp_path / "e.pid")])]
    try:
        def through_tunnel():
            try:
                return Resp("127.0.0.1", near, password=password).call("PING") == "PONG"
            except (OSError, ConnectionError):
                return False  # spiped not listening yet
        wait_for(through_tunnel, "the tunnel carries Redis", 10)
        # The tunnel's public end does not speak Redis to someone without its key.
        with socket.create_connection(("127.0.0.1", far), timeout=3) as s:
            s.sendall(f"AUTH {password}\r\nPING\r\n".encode())
            got = b""
            try:
                while chunk := s.recv(4096):
                    got += chunk
            except (socket.timeout, ConnectionResetError):
                pass
        assert b"PONG" not in got and b"+OK" not in got and b"NOAUTH" not in got, got

        pw_file = write_secret(tmp_path / "redis.pw", password)
        srv = servers("tunnel", threads=1, args=["--queue", redis.url, "--redis-password-file", pw_file,
                                                 "--farm-key-file", stack.key])
        worker = stack.worker(f"redis://127.0.0.1:{near}", "far-host", "--redis-password-file", pw_file,
                              "--farm-key-file", stack.key)
        job_id = srv.api.submit(SMALL)["id"]
        done = srv.api.wait(job_id, FINAL, timeout=180)
        assert done["state"] == "done" and done["samples"] == SMALL["width"] * SMALL["height"] * SMALL["spp"], done
        assert "pass 0" in worker.text() and farm(srv.api)["rejected"] == 0
    finally:
        for p in pipes:
            p.kill()
            p.wait(10)


def can_make_namespaces():
    if not shutil.which("unshare") or not shutil.which("ip") or not shutil.which("nsenter"):
        return False
    r = subprocess.run(["unshare", "-Urn", "sh", "-c", "ip link add t0 type veth peer name t1 && unshare -n true"],
                       capture_output=True, timeout=30)
    return r.returncode == 0


def test_two_hosts_over_a_veth_pair(tmp_path, servers, stack):
    if os.environ.get(IN_NETNS) != "1":
        if not can_make_namespaces():
            pytest.skip("this machine cannot make user and network namespaces (unshare -Urn, a veth pair)")
        # Again, inside a user and network namespace of its own: host A.
        r = subprocess.run(["unshare", "-Urn", "--fork", "--kill-child", sys.executable, "-m", "pytest", "-q", "-s",
                            "-p", "no:cacheprovider", f"{__file__}::test_two_hosts_over_a_veth_pair",
                            "--basetemp", str(tmp_path / "netns")],
                           env=dict(os.environ, **{IN_NETNS: "1"}), capture_output=True, text=True, timeout=560)
        print(r.stdout[-12000:], r.stderr[-4000:])
        assert r.returncode == 0, "the two-host test failed inside its namespaces (output above)"
        return

    run("ip", "link", "set", "lo", "up")
    host_b = subprocess.Popen(["unshare", "-n", "sleep", "600"])  # host B: a network namespace of its own
    try:
        wait_for(lambda: os.readlink(f"/proc/{host_b.pid}/ns/net") != os.readlink("/proc/self/ns/net"), "host B")
        in_b = ["nsenter", "-t", str(host_b.pid), "-n"]
        run("ip", "link", "add", "veth-a", "type", "veth", "peer", "name", "veth-b")
        run("ip", "link", "set", "veth-b", "netns", str(host_b.pid))
        run("ip", "addr", "add", "192.0.2.1/24", "dev", "veth-a")
        run("ip", "link", "set", "veth-a", "up")
        run(*in_b, "ip", "addr", "add", "192.0.2.2/24", "dev", "veth-b")
        run(*in_b, "ip", "link", "set", "veth-b", "up")
        run(*in_b, "ip", "link", "set", "lo", "up")
        assert "192.0.2.1" not in run(*in_b, "ip", "-4", "addr", "show", "dev", "lo")

        admin = "admin-" + os.urandom(8).hex()
        passwords = {"render-server": "srv-" + os.urandom(8).hex(), "render-worker": "wrk-" + os.urandom(8).hex()}
        redis = stack.redis(args=["--requirepass", admin], password=admin, bind="192.0.2.1")
        for u in acl_users(passwords):
            assert redis.cli("ACL", "SETUSER", *u) == "OK", u
        srv = servers("host-a", threads=1, args=[
            "--queue", f"redis://render-server@192.0.2.1:{redis.port}", "--farm-key-file", stack.key,
            "--redis-password-file", write_secret(tmp_path / "server.pw", passwords["render-server"])])
        worker = stack.worker(f"redis://render-worker@192.0.2.1:{redis.port}", "host-b", "--farm-key-file", stack.key,
                              "--redis-password-file", write_secret(tmp_path / "worker.pw", passwords["render-worker"]),
                              "--redis-timeout", "120", prefix=in_b)
        # Without the key, a worker on host B refuses this Redis before connecting: it is not on loopback.
        unsigned = subprocess.run([*in_b, str(RENDER_WORKER), "--queue", f"redis://192.0.2.1:{redis.port}"],
                                  capture_output=True, text=True, timeout=30)
        assert unsigned.returncode == 2 and "not on loopback" in unsigned.stderr, unsigned.stderr
        spec = dict(SMALL, width=96, height=72, spp=256)
        job_id = srv.api.submit(spec)["id"]
        wait_for(lambda: worker.text().count(" pass ") >= 5, "the worker on host B rendered passes", 120)
        clients = redis.cli("CLIENT", "LIST")
        assert "addr=192.0.2.2:" in clients and "user=render-worker" in clients, clients

        # Cut host B's link mid-pass for longer than a command's 5 s timeout, then restore it.
        passes_before = worker.text().count(" pass ")
        run("ip", "link", "set", "veth-a", "down")
        time.sleep(7)
        run("ip", "link", "set", "veth-a", "up")
        done = srv.api.wait(job_id, FINAL, timeout=200)
        assert done["state"] == "done", done
        assert done["samples"] == spec["width"] * spec["height"] * spec["spp"], "every sample once"
        text = worker.text()
        assert worker.text().count(" pass ") > passes_before, text
        # The worker felt the cut: a send that broke (sent again as a new attempt), a connection lost
        # and waited out, or its heartbeat failing while TCP held the main connection's data until the
        # link came back. Which one depends on where in the pass it fell.
        assert any(s in text for s in ("connection broke", "lost Redis", "heartbeat:")), text[-3000:]
        f = farm(srv.api)
        assert f["rejected"] == 0 and f["authenticated"] and f["signed"] and not f["insecure"], f
        assert [w["passes"] for w in f["workers"] if w["name"] == "host-b"][0] >= 1, f
        ref_api, ref_id = reference(servers, spec)
        assert_same_image(srv.api, job_id, ref_api, ref_id)
    finally:
        host_b.kill()
        host_b.wait(10)
