"""A job list that lasts: --keep-jobs and --max-data-mb delete the oldest finished jobs (never a
queued, running or paused one), /api/health reports the data folder's size, and GET /api/jobs
pages newest first and filters by state. Waits are on states; their timeouts only stop a broken
server from hanging the test."""
import time

from support import ENDLESS, TINY


def folder_bytes(path):
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def wait_for(predicate, what, timeout=30):
    deadline = time.monotonic() + timeout
    while not (value := predicate()):
        assert time.monotonic() < deadline, what
        time.sleep(0.02)
    return value


def run_tiny_jobs(api, n, **extra):
    ids = []
    for seed in range(n):
        job = api.submit(dict(TINY, seed=seed + 1, **extra))
        api.wait(job["id"], "done", timeout=30)
        ids.append(job["id"])
    return ids


def listed(api, **params):
    return [j["id"] for j in api.get("/api/jobs", params=params).json()["jobs"]]


def test_keep_jobs_deletes_the_oldest_finished_jobs_never_a_paused_one(servers):
    srv = servers(args=["--keep-jobs", "2"])
    api = srv.api
    paused = api.submit(ENDLESS)
    api.wait(paused["id"], "running", samples=1)
    assert api.post(f"/api/jobs/{paused['id']}/pause", expect=200).json()["state"] == "paused"
    ids = run_tiny_jobs(api, 4)
    wait_for(lambda: len(listed(api)) == 3, "retention kept more than 2 finished jobs")
    assert listed(api) == [ids[3], ids[2], paused["id"]]
    for old in ids[:2]:
        assert not (srv.data / "jobs" / old).exists(), "a deleted job's files stayed"
        api.error(api.get(f"/api/jobs/{old}", expect=None), 404)
    assert "deleted (retention: --keep-jobs)" in srv.log_text()
    assert api.job(paused["id"])["state"] == "paused"


def test_max_data_mb_bounds_the_data_folder_and_health_reports_its_size(servers):
    srv = servers(args=["--max-data-mb", "1"])
    api = srv.api
    # 96x72: each job keeps about 0.4 MiB (its film and images), so the third passes 1 MiB.
    ids = run_tiny_jobs(api, 4, width=96, height=72)
    jobs_dir = srv.data / "jobs"
    wait_for(lambda: folder_bytes(jobs_dir) <= 1 << 20, "the data folder stayed over --max-data-mb")
    kept = listed(api)
    assert kept[0] == ids[-1] and ids[0] not in kept, kept
    assert 0 < len(kept) < 4
    health = api.get("/api/health").json()
    assert health["data_bytes"] == folder_bytes(jobs_dir), "health reports another size"
    assert "deleted (retention: --max-data-mb)" in srv.log_text()


def test_without_retention_every_job_stays(server):
    ids = run_tiny_jobs(server.api, 3)
    assert listed(server.api) == ids[::-1]
    assert server.api.get("/api/health").json()["data_bytes"] == folder_bytes(server.data / "jobs")


def test_the_job_list_pages_newest_first_and_filters_by_state(server):
    api = server.api
    ids = run_tiny_jobs(api, 5)
    live = api.submit(ENDLESS)
    api.wait(live["id"], "running")
    newest_first = [live["id"]] + ids[::-1]

    seen, cursor, pages = [], None, 0
    while True:
        params = {"limit": 2, **({"cursor": cursor} if cursor else {})}
        page = api.get("/api/jobs", params=params).json()
        assert len(page["jobs"]) <= 2
        seen += [j["id"] for j in page["jobs"]]
        pages += 1
        cursor = page["next_cursor"]
        if cursor is None:
            break
    assert seen == newest_first and pages == 3
    assert listed(api, state="done") == ids[::-1]
    assert listed(api, state="running") == [live["id"]]
    assert listed(api, state="failed") == []
    assert listed(api, state="done", limit=1, cursor=ids[2]) == [ids[1]]

    for params, field in (({"limit": 0}, "limit"), ({"limit": "ten"}, "limit"), ({"limit": 1001}, "limit"),
                          ({"state": "sleeping"}, "state"), ({"cursor": "../etc"}, "cursor")):
        api.error(api.get("/api/jobs", params=params, expect=None), 400, field)
    api.delete(f"/api/jobs/{live['id']}", expect=200)
