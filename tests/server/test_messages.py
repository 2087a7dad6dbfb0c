"""What the service says to a new user: every invalid field of a job at once, what the scene's
loader ignored or defaulted (in the scene list and in the job's status), and what it is (its
version in /api/health and --version on both binaries)."""
import re
import subprocess

from support import CORNELL, RENDER_SERVER, TINY
from test_scale_out import RENDER_WORKER


def test_every_invalid_field_is_named_at_once(server):
    api = server.api
    # The first in the options table's order leads: max_depth, then spp, then unknown fields.
    err = api.error(api.post("/api/jobs", dict(TINY, spp=0, max_depth=-1, bogus=1)), 400, "max_depth")
    assert [e["field"] for e in err["errors"]] == ["max_depth", "spp", "bogus"], err
    assert err["errors"][0] == {"field": "max_depth", "message": err["message"]}
    assert all(e["message"] for e in err["errors"])
    # One invalid field: the answer is as it always was, without a list.
    assert "errors" not in api.error(api.post("/api/jobs", dict(TINY, spp=0)), 400, "spp")
    # /check names them the same way, and two framings at once are refused naming the new one.
    assert len(api.error(api.post("/api/jobs/check", dict(TINY, width=0, height=0)), 400, "width")["errors"]) == 2
    api.error(api.post("/api/jobs", dict(TINY, keep_fov=True, frame_scene=True)), 400, "frame_scene")


def test_a_mistyped_field_or_scene_gets_the_nearest_valid_one(servers, tmp_path):
    srv = servers("near", bundled_scenes=True)
    api = srv.api
    err = api.error(api.post("/api/jobs", dict(TINY, sppp=4)), 400, "sppp")
    assert err["message"] == "unknown field 'sppp' (did you mean 'spp'?)"
    err = api.error(api.post("/api/jobs/check", dict(TINY, max_dept=2)), 400, "max_dept")
    assert "did you mean 'max_depth'?" in err["message"]
    assert "did you mean" not in api.error(api.post("/api/jobs", dict(TINY, zzzzzz=1)), 400, "zzzzzz")["message"]
    err = api.error(api.post("/api/jobs", dict(TINY, scene="cornel")), 404, "scene")
    assert err["message"] == "unknown scene 'cornel' (did you mean 'cornell'?)"
    # --scenes adds to the bundled scenes: the test's folder and the source tree's scenes/ both list.
    names = {s["name"] for s in api.get("/api/scenes").json()["scenes"]}
    assert {"cornell", "showcase", "dof"} <= names, names
    err = api.error(api.post("/api/jobs", dict(TINY, scene="showcas")), 404, "scene")
    assert "did you mean 'showcase'?" in err["message"]
    # Without the bundled scenes only the folder's own are served, and the help names both flags.
    only = {s["name"] for s in servers("only").api.get("/api/scenes").json()["scenes"]}
    assert only == {"cornell"}, only
    help_text = subprocess.run([str(RENDER_SERVER), "--help"], capture_output=True, text=True, timeout=10).stdout
    assert "--no-bundled-scenes" in help_text and ".gltf, .glb" in help_text
    bad = subprocess.run([str(RENDER_SERVER), "--scene", "x"], capture_output=True, text=True, timeout=10)
    assert bad.returncode == 2 and "did you mean --scenes?" in bad.stderr, bad.stderr


def test_what_the_loader_ignored_reaches_the_scene_list_and_the_jobs_status(server):
    api = server.api
    no_camera = re.sub(rb'<instance_camera url="[^"]*"/>', b"", CORNELL.read_bytes())
    summary = api.request("PUT", "/api/scenes/nocam", 201, data=no_camera,
                          headers={"Content-Type": "model/vnd.collada+xml"}).json()["summary"]
    assert any("no <instance_camera>" in w and w.startswith("nocam.dae:") for w in summary["warnings"]), summary
    assert api.get("/api/scenes").json()["scenes"] and not next(
        s for s in api.get("/api/scenes").json()["scenes"] if s["name"] == "cornell")["summary"]["warnings"]
    job = api.submit(dict(TINY, scene="nocam"))
    assert job["warnings"] == summary["warnings"]
    done = api.wait(job["id"], ("done", "failed"), timeout=30)
    assert done["state"] == "done" and done["warnings"] == summary["warnings"]
    assert api.submit(dict(TINY))["warnings"] == []


def test_health_and_the_binaries_say_their_version(server):
    version = server.api.get("/api/health").json()["version"]
    assert re.fullmatch(r"\d+\.\d+\.\d+", version["version"]) and version["commit"]
    assert version["embree"].startswith("3.") and version["openimageio"].startswith("2."), version
    for binary, name in ((RENDER_SERVER, "render-server"), (RENDER_WORKER, "render-worker")):
        out = subprocess.run([str(binary), "--version"], capture_output=True, text=True, timeout=30)
        assert out.returncode == 0
        assert out.stdout == (f"{name} {version['version']} (commit {version['commit']}), "
                              f"Embree {version['embree']}, OpenImageIO {version['openimageio']}\n")
