"""Crashes: the server is killed with SIGKILL 20 times at random moments (while jobs are queued,
rendering and writing their images) and restarted on the same data directory each time. After
every restart no job is lost (every job the server acknowledged is listed), every job is either
done with images that decode completely (PNG and OpenEXR) or queued to run again, every job.json
parses, and no temp file is left behind; at the end every job finishes. Half the kills wait for
a job to be rendering (a state, polled), with a job whose time limit keeps it rendering for a
second whatever the machine's speed, so a fast machine still kills mid-render."""
import json
import random
import time

from images import decode_png, read_exr

KILLS = 20
SIZES = [(48, 36), (96, 72), (128, 96)]


def job_spec(rng, i):
    w, h = rng.choice(SIZES)
    return {"scene": "cornell", "width": w, "height": h, "spp": rng.choice([4, 16, 64]), "max_depth": 3,
            "adaptive": False, "seed": i, "tile_size": 16}


def long_spec(i):
    """Renders until its time limit (a second of wall time on any machine), then is done."""
    return {"scene": "cornell", "width": 48, "height": 36, "spp": 65536, "max_depth": 3, "adaptive": False,
            "seed": i, "tile_size": 16, "time_limit": 1.0}


def wait_until_rendering(api, timeout=60):
    """Polls /api/health until a job is running (states, not a clock; the timeout only stops a hang)."""
    deadline = time.monotonic() + timeout
    while api.get("/api/health").json()["running"] == 0:
        assert time.monotonic() < deadline, "no job started rendering"
        time.sleep(0.005)


def check_data_dir(data, acknowledged, pid):
    """The data directory as a restarted server (process `pid`) left it: every job.json whole, no
    temp file of an earlier process, and each acknowledged job present. Returns {id: state on disk}."""
    jobs = data / "jobs"
    # Temp names carry the writer's pid: the running server's own writes in flight are not leftovers.
    leftovers = [p.name for p in jobs.rglob("*") if ".tmp" in p.name and f".tmp{pid}" not in p.name]
    assert not leftovers, f"temp files survived a restart: {leftovers}"
    states = {}
    for d in jobs.iterdir():
        if d.is_dir():
            doc = json.loads((d / "job.json").read_text())  # raises on a truncated or corrupt file
            # (a rename replaces job.json atomically: a reader sees the old or the new file whole)
            states[d.name] = doc["state"]
    missing = set(acknowledged) - set(states)
    assert not missing, f"jobs lost: {missing}"
    return states


def check_images(api, data, job_id, spec):
    """A done job's images, from the disk and from the API, decode completely at its size."""
    for source in ("disk", "api"):
        png = ((data / "jobs" / job_id / "image.png").read_bytes() if source == "disk"
               else api.get(f"/api/jobs/{job_id}/image.png").content)
        exr = ((data / "jobs" / job_id / "image.exr").read_bytes() if source == "disk"
               else api.get(f"/api/jobs/{job_id}/image.exr").content)
        w, h, pixels = decode_png(png)
        assert (w, h) == (spec["width"], spec["height"]) and len(pixels) == w * h * 3, (source, job_id)
        ew, eh, channels, attrs = read_exr(exr)
        assert (ew, eh) == (w, h) and set(channels) >= {"R", "G", "B"}, (source, job_id)
        assert all(len(v) == w * h for v in channels.values())
        assert attrs["pathtracer:job"] == job_id


def test_kill_9_twenty_times_loses_nothing(servers):
    rng = random.Random(184)
    specs = {}
    done_seen = set()
    kills_mid_render = 0
    data = None
    for round_no in range(KILLS):
        srv = servers("crashy", threads=2, args=["--max-queue", "100"])
        data = srv.data
        api = srv.api
        # After the restart: what the last one left is intact, and the server agrees with the disk.
        on_disk = check_data_dir(data, specs, srv.proc.pid)
        listed = {j["id"]: j for j in api.get("/api/jobs").json()["jobs"]}
        assert set(listed) == set(on_disk)
        for job_id, job in listed.items():
            assert job["state"] in ("queued", "running", "done"), job
            if job["state"] == "done":
                check_images(api, data, job_id, specs[job_id])
                done_seen.add(job_id)
            else:
                assert job_id not in done_seen, f"job {job_id} was done and is not any more"
        # More work, then a kill: every other round while a job renders, else at a random moment
        # (while queued, rendering, or writing images).
        for _ in range(rng.choice([1, 2])):
            spec = job_spec(rng, len(specs))
            specs[api.submit(spec)["id"]] = spec
        if round_no % 2 == 0:
            spec = long_spec(len(specs))
            specs[api.submit(spec)["id"]] = spec
            wait_until_rendering(api)
        else:
            time.sleep(rng.uniform(0.02, 0.6))
        kills_mid_render += api.get("/api/health").json()["running"] > 0
        srv.kill()
    # The last restart finishes everything.
    srv = servers("crashy", threads=2, args=["--max-queue", "100"])
    check_data_dir(srv.data, specs, srv.proc.pid)
    for job_id, spec in specs.items():
        job = srv.api.wait(job_id, "done", timeout=60)
        assert job["spec"] == dict(job["spec"], **spec)
        check_images(srv.api, srv.data, job_id, spec)
    print(f"{KILLS} kills ({kills_mid_render} while a job was rendering), {len(specs)} jobs, all done")
    assert kills_mid_render >= KILLS // 2


def test_what_a_crash_can_leave_is_cleaned_up_at_start(servers):
    # What a kill at the worst moment leaves, planted by hand: temp files of job.json and images,
    # a job folder without job.json (killed between mkdir and the write), a done job whose image
    # is missing or empty (killed before the images were renamed into place).
    srv = servers("planted", threads=2)
    api = srv.api
    a = api.submit({"scene": "cornell", "width": 32, "height": 24, "spp": 4, "seed": 1})
    b = api.submit({"scene": "cornell", "width": 32, "height": 24, "spp": 4, "seed": 2})
    api.wait(a["id"], "done", timeout=30)
    api.wait(b["id"], "done", timeout=30)
    srv.kill()
    jobs = srv.data / "jobs"
    (jobs / a["id"] / "job.json.tmp4242").write_text('{"state": "runn')
    (jobs / a["id"] / ".image.exr.tmp4242-0").write_bytes(b"\x76\x2f\x31\x01 half an image")
    (jobs / "0000000000000000").mkdir()
    (jobs / b["id"] / "image.png").write_bytes(b"")
    srv = servers("planted", threads=2)
    assert sorted(p.name for p in (jobs / a["id"]).iterdir()) == ["checkpoint.bin", "image.exr", "image.png", "job.json", "samples.bin"]
    assert not (jobs / "0000000000000000").exists()
    assert "removed 2 temp files" in srv.log_text()
    assert [j["id"] for j in srv.api.get("/api/jobs").json()["jobs"]] == [b["id"], a["id"]]  # newest first
    assert srv.api.job(a["id"])["state"] == "done"
    redone = srv.api.wait(b["id"], "done", timeout=30)  # its empty image: rendered again
    assert redone["started_at"] > b["created_at"]
    w, h, _ = decode_png((jobs / b["id"] / "image.png").read_bytes())
    assert (w, h) == (32, 24)
