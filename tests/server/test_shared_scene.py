"""The scene cache shares one render-scene base (BVH, lights, materials) between all jobs on the
same file content: jobs running at the same time, later jobs, another name for the same bytes and
the focus endpoint build nothing more; listing the scenes builds nothing; an edited file is built
again. The server logs each build once ("scene 'NAME' built in ..."), which is what is counted."""
import re

from images import decode_png
from support import CORNELL

BUILT = re.compile(r"render-server: scene '([^']+)' built in [0-9.]+ s \((\d+) triangles, (\d+) spheres, ([0-9.]+) MiB\)")
SPEC = {"scene": "cornell", "width": 48, "height": 36, "spp": 16, "max_depth": 3, "adaptive": False,
        "seed": 4, "tile_size": 16}


def builds(srv):
    return BUILT.findall(srv.log_text())


def test_jobs_on_one_scene_share_one_build(servers, tmp_path):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "cornell.dae").write_bytes(CORNELL.read_bytes())
    (scenes / "twin.dae").write_bytes(CORNELL.read_bytes())  # other name, same content
    srv = servers(scenes=scenes, args=["--concurrency", "2"])
    api = srv.api

    listed = {s["name"]: s for s in api.get("/api/scenes").json()["scenes"]}
    assert set(listed) == {"cornell", "twin"} and all("summary" in s for s in listed.values())
    assert builds(srv) == [], "listing the scenes must not build them"

    # Two jobs at once (concurrency 2), then one on the twin and one more on cornell.
    first = [api.submit(SPEC), api.submit(dict(SPEC, width=40, seed=5))]
    for job in first:
        api.wait(job["id"], "done", timeout=60)
    later = [api.submit(dict(SPEC, scene="twin")), api.submit(dict(SPEC, aperture=0.05, focal_distance=4))]
    for job in later:
        api.wait(job["id"], "done", timeout=60)
    api.get(f"/api/jobs/{first[0]['id']}/focus?x=24&y=18")

    got = builds(srv)
    assert len(got) == 1, f"expected one shared build, the log has {got}"
    name, triangles, spheres, mib = got[0]
    assert name in ("cornell", "twin")
    assert int(triangles) == listed["cornell"]["summary"]["triangles"]
    assert int(spheres) == listed["cornell"]["summary"]["spheres"] and float(mib) > 0
    # Both names list the memory of the one base (the default budget keeps it between jobs).
    memory = {s["name"]: s.get("memory_bytes") for s in api.get("/api/scenes").json()["scenes"]}
    assert memory["cornell"] == memory["twin"] and abs(memory["cornell"] / 2**20 - float(mib)) < 0.01

    # Same spec and seed through the shared scene: the twin's image is cornell's, pixel for pixel.
    png = {job["id"]: api.get(f"/api/jobs/{job['id']}/image.png").content for job in first + later}
    assert decode_png(png[first[0]["id"]]) == decode_png(png[later[0]["id"]])

    # An edited file is new content: built again on its next job, and only then.
    (scenes / "cornell.dae").write_bytes(CORNELL.read_bytes() + b"\n<!-- edited -->\n")
    api.get("/api/scenes")
    assert len(builds(srv)) == 1
    job = api.submit(SPEC)
    api.wait(job["id"], "done", timeout=60)
    assert [b[0] for b in builds(srv)][1:] == ["cornell"]


def test_scene_cache_keeps_bases_within_its_budget(servers, tmp_path):
    """--scene-cache-mb bounds the built bases kept between jobs: past it the least recently used
    base no job holds is dropped (and logged), /api/scenes stops listing its memory, and its next
    job builds it again. A budget of 0 keeps only the base of the latest job."""
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "cornell.dae").write_bytes(CORNELL.read_bytes())
    (scenes / "dof.dae").write_bytes((CORNELL.parent / "dof.dae").read_bytes())
    srv = servers(scenes=scenes, args=["--scene-cache-mb", "0"])
    api = srv.api

    def memory():
        return {s["name"]: s.get("memory_bytes") for s in api.get("/api/scenes").json()["scenes"]}

    assert memory() == {"cornell": None, "dof": None}, "nothing is built before a job asks"
    api.wait(api.submit(SPEC)["id"], "done", timeout=60)
    assert memory()["cornell"] > 0 and memory()["dof"] is None
    api.wait(api.submit(dict(SPEC, scene="dof"))["id"], "done", timeout=60)
    assert memory()["cornell"] is None and memory()["dof"] > 0, "cornell's unused base should be dropped"
    assert "render-server: scene 'cornell' dropped from the cache" in srv.log_text()
    api.wait(api.submit(SPEC)["id"], "done", timeout=60)
    assert [b[0] for b in builds(srv)] == ["cornell", "dof", "cornell"]


def test_scene_cache_never_drops_a_base_a_job_holds(servers, tmp_path):
    """A base in use stays however far over budget the cache is; once its job ends, the next job
    on another scene drops it."""
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "cornell.dae").write_bytes(CORNELL.read_bytes())
    (scenes / "dof.dae").write_bytes((CORNELL.parent / "dof.dae").read_bytes())
    srv = servers(scenes=scenes, args=["--scene-cache-mb", "0", "--concurrency", "2"])
    api = srv.api
    long_job = api.submit(dict(SPEC, spp=65536))
    api.wait(long_job["id"], "running", samples=1)
    api.wait(api.submit(dict(SPEC, scene="dof"))["id"], "done", timeout=60)
    assert "dropped from the cache" not in srv.log_text(), "cornell's base was dropped while its job ran"
    api.delete(f"/api/jobs/{long_job['id']}", expect=200)
    api.wait(long_job["id"], "cancelled", timeout=10)
    api.wait(api.submit(dict(SPEC, scene="dof", seed=9))["id"], "done", timeout=60)
    assert "render-server: scene 'cornell' dropped from the cache" in srv.log_text()
    assert [b[0] for b in builds(srv)] == ["cornell", "dof"]

