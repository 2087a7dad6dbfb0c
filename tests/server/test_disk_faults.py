"""Disk faults: a disk that fills up while a job writes its image, and a data directory that
becomes unusable, give a clear error and a failed (or refused) job, never a crash; nothing half
written is left behind, and the server keeps serving. The full disk is a real tiny tmpfs (in a user +
mount namespace of the server's own, which needs no privilege, else a plain mount), and a file-size
limit (ulimit -f)."""
import errno
import json
import shutil
import subprocess
from pathlib import Path

import pytest

from support import CORNELL, RENDER_SERVER, TINY, cannot_run

BIG = {"scene": "cornell", "width": 200, "height": 150, "spp": 4, "max_depth": 3}  # an EXR of ~200 KB


def no_temp_files(data):
    left = [p.name for p in (data / "jobs").rglob("*") if ".tmp" in p.name]
    assert not left, left


def test_image_bigger_than_the_file_size_limit_fails_the_job(servers):
    # 32 KiB files at most: job.json fits, the images do not (writes fail with EFBIG).
    srv = servers("fsize", limit_file_kib=32)
    api = srv.api
    job = api.submit(BIG)
    failed = api.wait(job["id"], ("failed", "done"), timeout=30)
    assert failed["state"] == "failed", failed
    assert "cannot store the finished image" in failed["message"] and "image.exr" in failed["message"]
    assert str(srv.data) not in failed["message"]  # no server paths in messages
    assert srv.alive()
    no_temp_files(srv.data)
    assert not (srv.data / "jobs" / job["id"] / "image.exr").exists()
    on_disk = json.loads((srv.data / "jobs" / job["id"] / "job.json").read_text())
    assert on_disk["state"] == "failed"
    # Small images still fit: the server goes on.
    small = api.submit(dict(TINY, width=16, height=12))
    assert api.wait(small["id"], ("failed", "done"), timeout=30)["state"] == "done"


@pytest.fixture
def tmpfs_server(servers, tmp_path):
    """A server whose --data is on a 160 KiB tmpfs; yields it and that tmpfs as this process sees it."""
    mnt = tmp_path / "disk"  # not the server's own folder (tmp_path / name), where its scenes and log are
    mnt.mkdir()
    mount = ["mount", "-t", "tmpfs", "-o", "size=160k", "tmpfs", str(mnt)]
    # First choice, unprivileged: the server gets a user + mount namespace of its own, mounts there and
    # execs; the mount is private to it and goes when the server exits, so nothing stays mounted here.
    own_ns = ["unshare", "-Urm", "sh", "-c", 'mount -t tmpfs -o size=160k tmpfs "$0" && exec "$@"', str(mnt)]
    plain = False
    if subprocess.run([*own_ns, "true"], capture_output=True).returncode != 0:
        plain = subprocess.run(mount, capture_output=True).returncode == 0
        if not plain:
            cannot_run("neither mount nor unshare -Urm can make a tmpfs here (the ulimit test covers a full disk)")
    srv = servers("tmpfs", prefix=[] if plain else own_ns, args=["--data", str(mnt / "data")])  # a later --data wins
    # Through /proc/PID/root the path resolves in the server's mount namespace, where the tmpfs is.
    yield srv, Path(f"/proc/{srv.proc.pid}/root") / mnt.relative_to("/")
    srv.kill()
    if plain:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def test_full_tmpfs_fails_the_job_with_enospc(tmpfs_server):
    srv, disk = tmpfs_server
    api = srv.api
    job = api.submit(BIG)
    failed = api.wait(job["id"], ("failed", "done"), timeout=30)
    assert failed["state"] == "failed" and "No space left on device" in failed["message"], failed
    assert srv.alive()
    no_temp_files(disk / "data")
    # Full to the last block: a new job cannot even be stored. Refused with 507, nothing queued.
    filler = disk / "filler"
    try:
        with open(filler, "wb") as f:
            while True:
                f.write(b"\0" * 4096)
                f.flush()
    except OSError as e:
        assert e.errno == errno.ENOSPC, e  # full (not a path this process cannot reach)
    resp = api.post("/api/jobs", TINY)
    api.error(resp, 507)
    assert "No space left on device" in resp.json()["error"]["message"]
    filler.unlink()
    assert api.submit(TINY)["state"] in ("queued", "running")
    assert api.get("/api/health").json()["status"] == "ok"


def test_data_directory_that_vanishes_refuses_jobs_and_fails_running_ones(servers):
    srv = servers("vanish", threads=1)
    api = srv.api
    # No request makes a running job finish on demand (cancel stores a cancelled job's image, limits
    # cannot change while it renders), so an endless job holds the one render slot while the directory
    # goes, and the job behind it renders, and stores its image, only after that.
    endless = api.submit(dict(BIG, spp=65536, adaptive=False))
    api.wait(endless["id"], "running")
    job = api.submit(BIG)
    assert api.job(job["id"])["state"] == "queued"
    # The data directory goes (a disk unmounted, a folder removed) and a file takes its place.
    shutil.rmtree(srv.data / "jobs")
    (srv.data / "jobs").write_text("not a directory")
    assert api.delete(f"/api/jobs/{endless['id']}", expect=200).json()["state"] == "cancelled"
    failed = api.wait(job["id"], ("failed", "done"), timeout=30)
    assert failed["state"] == "failed" and "cannot store the finished image" in failed["message"], failed
    resp = api.post("/api/jobs", TINY)
    api.error(resp, 507)
    assert "Not a directory" in resp.json()["error"]["message"]
    assert [j["id"] for j in api.get("/api/jobs").json()["jobs"]] == [job["id"], endless["id"]]
    assert srv.alive() and api.get("/api/health").json()["status"] == "ok"


def test_unwritable_data_directory_at_start_is_a_clear_error(tmp_path):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "cornell.dae").write_bytes(CORNELL.read_bytes())
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    for data in (blocker / "data", "/proc/render-server-data"):
        done = subprocess.run([str(RENDER_SERVER), "--port", "0", "--data", str(data), "--scenes", str(scenes)],
                              capture_output=True, text=True, timeout=30)
        assert done.returncode == 1, done.stdout + done.stderr
        assert "is not writable" in done.stderr and str(data) in done.stderr, done.stderr
