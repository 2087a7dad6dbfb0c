"""The bounded queue (429 with Retry-After when full) and idempotent submission (the same key and
spec give the same job; the same key with another spec is a 409)."""
from support import ENDLESS, TINY, health_counts


def test_queue_full_is_429_with_retry_after(servers):
    srv = servers(args=["--max-queue", "1", "--concurrency", "1"])
    api = srv.api
    running = api.submit(ENDLESS, key="long")
    api.wait(running["id"], "running")

    # Submit until refused: one waits, the next is a 429.
    accepted, refused = [], None
    for i in range(5):
        resp = api.post("/api/jobs", dict(TINY, seed=100 + i))
        if resp.status_code == 429:
            refused = resp
            break
        assert resp.status_code == 201, resp.text
        accepted.append(resp.json())
    assert refused is not None and len(accepted) == 1
    err = api.error(refused, 429)
    assert "queue is full" in err["message"]
    assert int(refused.headers["Retry-After"]) >= 1
    assert health_counts(api.get("/api/health").json()) == {"status": "ok", "queued": 1, "running": 1, "paused": 0, "rendering": "embedded"}
    assert len(api.get("/api/jobs").json()["jobs"]) == 2  # the refused job left no trace

    # A repeated Idempotency-Key is answered even when the queue is full: nothing new is queued.
    again = api.post("/api/jobs", ENDLESS, expect=200, headers={"Idempotency-Key": "long"}).json()
    assert again["id"] == running["id"]

    # Cancelling the waiting job makes room again.
    api.delete(f"/api/jobs/{accepted[0]['id']}", expect=200)
    room = api.submit(TINY)
    api.error(api.post("/api/jobs", dict(TINY, seed=9)), 429)
    api.delete(f"/api/jobs/{running['id']}", expect=200)
    api.wait(room["id"], "done", timeout=20)
    api.submit(TINY)  # room again once the queue drains


def test_idempotency_key(server):
    api = server.api
    spec = dict(TINY, seed=42)
    first = api.post("/api/jobs", spec, expect=201, headers={"Idempotency-Key": "key-1"})
    second = api.post("/api/jobs", spec, expect=200, headers={"Idempotency-Key": "key-1"})
    assert first.json()["id"] == second.json()["id"]
    assert first.headers["Location"] == second.headers["Location"] == f"/api/jobs/{first.json()['id']}"
    # The same spec spelled differently (defaults written out) is the same spec.
    spelled = dict(spec, light_samples=1, adaptive=True, aperture=0, time_limit=None)
    assert api.post("/api/jobs", spelled, expect=200, headers={"Idempotency-Key": "key-1"}).json()["id"] == first.json()["id"]
    assert len(api.get("/api/jobs").json()["jobs"]) == 1

    # Another spec under the same key is a conflict naming the header; no job is created.
    err = api.error(api.post("/api/jobs", dict(spec, seed=43), headers={"Idempotency-Key": "key-1"}), 409,
                    "Idempotency-Key")
    assert "different" in err["message"]
    assert len(api.get("/api/jobs").json()["jobs"]) == 1

    # Without a key, or with another key, the same spec is a new job.
    assert api.post("/api/jobs", spec, expect=201).json()["id"] != first.json()["id"]
    assert api.post("/api/jobs", spec, expect=201, headers={"Idempotency-Key": "key-2"}).json()["id"] != first.json()["id"]
    assert len(api.get("/api/jobs").json()["jobs"]) == 3
    # A key over 200 characters is refused.
    api.error(api.post("/api/jobs", spec, headers={"Idempotency-Key": "k" * 201}), 400, "Idempotency-Key")
    api.post("/api/jobs", spec, expect=201, headers={"Idempotency-Key": "k" * 200})
