"""What the render-server tests share: the paths ctest passes in, a real server process on a
loopback port, an HTTP client that checks every JSON answer against server/openapi.json, an
event-stream reader, and raw HTTP for requests no client library would send (images.py decodes
what they return)."""
import copy
import http.client
import json
import os
import re
import select
import signal
import socket
import subprocess
import time
from pathlib import Path


import pytest
import requests
from jsonschema import Draft4Validator
from referencing import Registry, Resource
from referencing.jsonschema import DRAFT4

# ---- paths (ctest sets them; the fallbacks serve a run by hand from the source tree) ----
SOURCE_DIR = Path(os.environ.get("PT_SOURCE_DIR", Path(__file__).resolve().parents[2]))
RENDER_SERVER = Path(os.environ.get("PT_RENDER_SERVER", SOURCE_DIR / "build/render-server"))
PATHTRACER = Path(os.environ.get("PT_PATHTRACER", SOURCE_DIR / "build/pathtracer"))
SHARED_SCENES = Path(os.environ.get("PT_SHARED_SCENES", SOURCE_DIR.parent / "shared/scenes-cs184"))
OPENAPI_FILE = SOURCE_DIR / "server/openapi.json"
CORNELL = SOURCE_DIR / "scenes/cornell.dae"

# A render that finishes in a few milliseconds and one that runs until cancelled (or time_limit).
TINY = {"scene": "cornell", "width": 64, "height": 48, "spp": 4, "max_depth": 3, "seed": 1}
ENDLESS = {"scene": "cornell", "width": 160, "height": 120, "spp": 65536, "adaptive": False, "max_depth": 5}


def cannot_run(why):
    """Our rule: a test that cannot run where CI runs fails under CI=true rather than skipping."""
    if os.environ.get("CI") == "true":
        pytest.fail(f"CI=true, yet {why}")
    pytest.skip(why)


# ---- the contract: server/openapi.json as JSON Schema (draft 4, which OpenAPI 3.0 extends) ----
class Contract:
    URN = "urn:render-server-openapi"

    def __init__(self, doc):
        self.doc = doc
        root = self._to_json_schema(copy.deepcopy(doc))
        self.registry = Registry().with_resource(self.URN, Resource.from_contents(root, default_specification=DRAFT4))
        self.root = root
        self._validators = {}

    @classmethod
    def load(cls):
        return cls(json.loads(OPENAPI_FILE.read_text()))

    def _to_json_schema(self, node):
        # nullable: true -> a type list with "null"; local refs -> refs into the registered document.
        if isinstance(node, dict):
            if node.get("nullable") is True and "type" in node:
                node["type"] = [node["type"], "null"]
                if "enum" in node:
                    node["enum"] = node["enum"] + [None]
            if isinstance(node.get("$ref"), str) and node["$ref"].startswith("#/"):
                node["$ref"] = self.URN + node["$ref"]
            for v in node.values():
                self._to_json_schema(v)
        elif isinstance(node, list):
            for v in node:
                self._to_json_schema(v)
        return node

    def validator(self, schema):
        key = json.dumps(schema, sort_keys=True)
        if key not in self._validators:
            self._validators[key] = Draft4Validator(schema, registry=self.registry)
        return self._validators[key]

    def component(self, name):
        return {"$ref": f"{self.URN}#/components/schemas/{name}"}

    def validate(self, instance, schema, what):
        errors = sorted(self.validator(schema).iter_errors(instance), key=lambda e: list(e.path))
        assert not errors, f"{what} breaks the contract: " + "; ".join(
            f"{'/'.join(map(str, e.path)) or '(root)'}: {e.message}" for e in errors[:5])

    def validate_component(self, instance, name, what=None):
        self.validate(instance, self.component(name), what or name)

    def operation(self, method, path):
        """The documented operation for a request path (no query), or (None, None)."""
        method = method.lower()
        paths = self.root["paths"]
        for tmpl in sorted(paths, key=lambda t: "{" in t):  # literal paths before templates
            regex = "^" + re.sub(r"\\\{[a-z_]+\\\}", "[^/]+", re.escape(tmpl)) + "$"
            if re.match(regex, path) and method in paths[tmpl]:
                return tmpl, paths[tmpl][method]
        return None, None

    def check_response(self, method, path, resp):
        """Asserts that an answer is documented: status, content type, headers and JSON body."""
        path = path.split("?", 1)[0]
        what = f"{method} {path} -> {resp.status_code}"
        media = resp.headers.get("Content-Type", "").split(";")[0].strip()
        tmpl, op = self.operation(method, path)
        if op is None:  # no such endpoint, or a method the path does not take
            if not path.startswith("/api/"):
                return
            assert resp.status_code in (400, 401, 403, 404, 405, 408, 411, 413, 414, 415, 416, 421, 431, 501, 503), what
            assert media == "application/json", f"{what}: Content-Type {media!r}"
        else:
            documented = op["responses"]
            assert str(resp.status_code) in documented, f"{what}: status not documented for {tmpl}"
            spec = documented[str(resp.status_code)]
            if method.upper() != "HEAD":
                assert media in spec.get("content", {}), f"{what}: Content-Type {media!r} not documented"
            for header in spec.get("headers", {}):
                assert header in resp.headers, f"{what}: missing header {header}"
            if media != "application/json":
                return
        body = resp.json()
        if op is None or resp.status_code >= 400:
            self.validate_component(body, "Error", what)
            assert body["error"]["status"] == resp.status_code, what
        else:
            self.validate(body, documented[str(resp.status_code)]["content"]["application/json"]["schema"], what)


# Requests sent and server errors seen by this process (5xx: all, deliberate 503 / 507 included;
# 500: internal errors, which must never happen); conftest prints them at the end.
STATS = {"requests": 0, "5xx": 0, "500": 0}


def count_answer(status):
    STATS["requests"] += 1
    if status is not None and status >= 500:
        STATS["5xx"] += 1
        STATS["500"] += status == 500


# ---- the HTTP client: every answer goes through the contract ----
class Api:
    def __init__(self, base, contract, token=None):
        self.base = base
        self.contract = contract
        self.session = requests.Session()
        if token is not None:
            self.session.headers["Authorization"] = f"Bearer {token}"

    def request(self, method, path, expect=None, timeout=15, **kw):
        resp = self.session.request(method, self.base + path, timeout=timeout, **kw)
        count_answer(resp.status_code)
        self.contract.check_response(method, path, resp)
        if expect is not None:
            assert resp.status_code == expect, f"{method} {path}: {resp.status_code} {resp.text[:400]}"
        return resp

    def get(self, path, expect=200, **kw):
        return self.request("GET", path, expect, **kw)

    def post(self, path, body=None, expect=None, headers=None, **kw):
        return self.request("POST", path, expect, json=body, headers=headers, **kw)

    def delete(self, path, expect=None, **kw):
        return self.request("DELETE", path, expect, **kw)

    def submit(self, spec, expect=201, key=None):
        headers = {"Idempotency-Key": key} if key is not None else None
        return self.post("/api/jobs", spec, expect=expect, headers=headers).json()

    def job(self, job_id):
        return self.get(f"/api/jobs/{job_id}").json()

    def wait(self, job_id, states, timeout=30, samples=0, poll=0.02):
        """Polls until the job is in one of `states` (and has taken at least `samples` samples)."""
        states = {states} if isinstance(states, str) else set(states)
        deadline = time.monotonic() + timeout
        while True:
            job = self.job(job_id)
            if job["state"] in states and job["samples"] >= samples:
                return job
            assert time.monotonic() < deadline, f"job {job_id} still {job['state']} ({job['samples']} samples)"
            time.sleep(poll)

    def error(self, resp, status, field=None):
        """Asserts an error answer: exact status, JSON shape, and the field it names (or none)."""
        assert resp.status_code == status, f"expected {status}, got {resp.status_code}: {resp.text[:400]}"
        err = resp.json()["error"]
        assert err["status"] == status and err["message"]
        assert err.get("field") == field, f"field {err.get('field')!r}, expected {field!r}: {err['message']}"
        return err


# ---- a real server process ----
class Server:
    """`token`: started with --token and its Api sends it; `env`: extra environment; `limit_file_kib`:
    the process may write files of at most that size (ulimit -f: a disk that fills up);
    `limit_memory_mib`: its address space (ulimit -v: memory that runs out); `limit_open_files`: its
    file descriptors (ulimit -n, soft and hard); `prefix`: a command the server runs under, which
    must exec it (so that the pid stays the server's), e.g. unshare for namespaces of its own."""

    def __init__(self, root, contract, threads=1, args=(), scenes=None, token=None, env=None, limit_file_kib=None,
                 limit_memory_mib=None, limit_open_files=None, bundled_scenes=False, prefix=()):
        self.root = Path(root)
        self.token = token
        self.env = env
        self.limit_file_kib = limit_file_kib
        self.limit_memory_mib = limit_memory_mib
        self.limit_open_files = limit_open_files
        self.bundled_scenes = bundled_scenes  # scenes/ of the source tree besides `scenes`
        self.data = self.root / "data"
        self.scenes = Path(scenes) if scenes else self.root / "scenes"
        self.contract = contract
        self.threads = threads
        self.args = list(args)
        self.prefix = list(prefix)
        self.proc = None
        if not scenes and not self.scenes.exists():
            self.scenes.mkdir(parents=True)
            (self.scenes / "cornell.dae").write_bytes(CORNELL.read_bytes())

    def start(self, timeout=15):
        cmd = [str(RENDER_SERVER), "--port", "0", "--data", str(self.data), "--scenes", str(self.scenes),
               "--threads", str(self.threads), *self.args]
        if not self.bundled_scenes:
            cmd.append("--no-bundled-scenes")
        if self.token is not None:
            cmd += ["--token", self.token]
        limits = []
        if self.limit_file_kib is not None:
            limits.append(f"ulimit -f {int(self.limit_file_kib)}")
        if self.limit_memory_mib is not None:
            limits.append(f"ulimit -v {int(self.limit_memory_mib) * 1024}")
        if self.limit_open_files is not None:
            limits.append(f"ulimit -n {int(self.limit_open_files)}")
        if limits:  # bash sets the limits, then becomes the server (same pid)
            cmd = ["bash", "-c", " && ".join(limits) + ' && exec "$0" "$@"', *cmd]
        cmd = [*self.prefix, *cmd]
        env = dict(os.environ, **self.env) if self.env else None
        self.log_path = self.root / f"server-{len(list(self.root.glob('server-*.log'))) + 1}.log"
        self.log = open(self.log_path, "wb")
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.log, cwd=self.root, env=env)
        line = b""
        deadline = time.monotonic() + timeout
        while not line.endswith(b"\n"):
            left = deadline - time.monotonic()
            assert left > 0 and self.proc.poll() is None, f"server did not start: {self.log_text()}"
            if select.select([self.proc.stdout], [], [], left)[0]:
                chunk = os.read(self.proc.stdout.fileno(), 1)
                assert chunk, f"server exited: {self.log_text()}"
                line += chunk
        m = re.fullmatch(rb"render-server: listening on http://127\.0\.0\.1:(\d+)/ \(rendering: [^)]+\)\n", line)
        assert m, f"unexpected first line {line!r}"
        self.port = int(m[1])
        self.url = f"http://127.0.0.1:{self.port}"
        self.api = Api(self.url, self.contract, self.token)
        return self

    def log_text(self):
        try:
            return self.log_path.read_text(errors="replace")
        except OSError:
            return ""

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def terminate(self, timeout=20):
        """SIGTERM; returns the exit code."""
        self.proc.send_signal(signal.SIGTERM)
        return self.proc.wait(timeout)

    def kill(self):
        if self.alive():
            self.proc.kill()
        if self.proc is not None:
            self.proc.wait(10)
            self.log.close()

    def events(self, job_id, **kw):
        return EventStream(self.port, job_id, self.contract, token=self.token, **kw)

    def rss_kib(self, field="VmRSS"):
        """The server's resident memory (VmRSS), or its peak so far (field="VmHWM"), in KiB."""
        for line in open(f"/proc/{self.proc.pid}/status"):
            if line.startswith(field + ":"):
                return int(line.split()[1])
        return None


# ---- Server-Sent Events ----
class Event:
    def __init__(self, kind, data, event_id):
        self.kind, self.data, self.id = kind, data, event_id

    def __repr__(self):
        return f"Event({self.kind}, id={self.id})"


EVENT_SCHEMAS = {"image": "ImageEvent", "status": "StatusEvent", "tile": "TileEvent", "denoised": "DenoisedEvent",
                 "end": "EndEvent"}


class EventStream:
    """One watcher of /api/jobs/{id}/events; every event's data is checked against its schema."""

    def __init__(self, port, job_id, contract, last_event_id=None, timeout=15, token=None):
        self.contract = contract
        self.conn = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
        headers = {"Accept": "text/event-stream"}
        if last_event_id is not None:
            headers["Last-Event-ID"] = str(last_event_id)
        # As a browser's EventSource must: the token in the query, not a header.
        query = f"?token={token}" if token is not None else ""
        self.conn.request("GET", f"/api/jobs/{job_id}/events{query}", headers=headers)
        self.resp = self.conn.getresponse()
        count_answer(self.resp.status)
        self.status = self.resp.status
        self.content_type = self.resp.getheader("Content-Type", "")
        self.ended = False
        self.retry = None

    def next(self):
        """The next event, or None when the server closed the stream."""
        kind, data, event_id = "message", [], None
        while True:
            line = self.resp.readline()
            if not line:
                self.ended = True
                return None
            line = line.decode().rstrip("\r\n")
            if line == "":
                if not data:
                    continue
                payload = json.loads("\n".join(data))
                assert kind in EVENT_SCHEMAS, f"unknown event type {kind!r}"
                self.contract.validate_component(payload, EVENT_SCHEMAS[kind], f"{kind} event")
                return Event(kind, payload, int(event_id) if event_id is not None else None)
            if line.startswith(":"):
                continue
            name, _, value = line.partition(":")
            value = value[1:] if value.startswith(" ") else value
            if name == "event":
                kind = value
            elif name == "data":
                data.append(value)
            elif name == "id":
                event_id = value
            elif name == "retry":
                self.retry = int(value)

    def __iter__(self):
        while (ev := self.next()) is not None:
            yield ev

    def until_end(self):
        """Every remaining event; asserts the stream ends with (only) an end event."""
        events = list(self)
        assert events and events[-1].kind == "end", f"stream closed without an end event: {events[-3:]}"
        assert all(e.kind != "end" for e in events[:-1])
        return events

    def close(self):
        self.conn.close()


def health_counts(health):
    """/api/health without its running totals ("stream", which every request may move, and the data
    folder's size) and the build's version (test_messages checks it)."""
    assert set(health["stream"]) == {"watchers", "png_encodes", "tile_events"}, health
    assert isinstance(health["data_bytes"], int) and health["data_bytes"] >= 0, health
    assert set(health["version"]) == {"version", "commit", "embree", "openimageio"}, health
    assert set(health["denoiser"]) == {"available", "description"}, health
    return {k: v for k, v in health.items() if k not in ("stream", "data_bytes", "version", "denoiser")}


# ---- raw HTTP, for requests no client library would send ----
def raw_request(port, data, timeout=10):
    """Sends bytes as they are; returns (status, headers dict, body bytes) of the answer."""
    with RawConnection(port, timeout) as conn:
        conn.send(data)
        return conn.answer()


class RawConnection:
    """A socket to the server that sends bytes as they are and reads answers one at a time."""

    def __init__(self, port, timeout=10):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.buf = b""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def send(self, data):
        self.sock.sendall(data)

    def _fill(self):
        try:
            chunk = self.sock.recv(65536)
        except ConnectionResetError:
            chunk = b""
        self.buf += chunk
        return bool(chunk)

    def answer(self):
        """The next answer: (status, headers dict, body bytes), or (None, {}, b"") when the server
        closed the connection without one."""
        while b"\r\n\r\n" not in self.buf:
            if not self._fill():
                count_answer(None)
                return None, {}, b""
        head, _, self.buf = self.buf.partition(b"\r\n\r\n")
        lines = head.decode("latin-1").split("\r\n")
        status = int(lines[0].split()[1])
        headers = {k.strip().lower(): v.strip() for k, _, v in (l.partition(":") for l in lines[1:])}
        length = int(headers.get("content-length", "0"))
        while len(self.buf) < length and self._fill():
            pass
        body, self.buf = self.buf[:length], self.buf[length:]
        count_answer(status)
        return status, headers, body

    def closed_by_server(self, timeout):
        """True when the server closes the connection within `timeout` seconds (bytes it sends
        before closing are kept for answer())."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self.sock.settimeout(max(0.01, deadline - time.monotonic()))
            try:
                if not self._fill():
                    return True
            except socket.timeout:
                return False
            except OSError:
                return True
        return False

    def close(self):
        self.sock.close()
