#!/usr/bin/env python3
"""The code's layout rules, checked on the source tree (README.md, "Layout"):

- no source file over 600 lines;
- no #include cycle among the project's own headers;
- Embree is included by renderer/accel.cpp alone; the server never includes it, and the renderer
  never includes HTTP, nor the JSON library outside the glTF reader (glTF is JSON);
- the renderer's library does not include its front ends (renderer/cmd/), and its helpers
  (renderer/util/) include nothing of the library.
"""
import re
import sys
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCE_DIRS = ["renderer", "server", "tests", "bench", "web", "scripts"]
SOURCE_SUFFIXES = {".h", ".cpp", ".inc", ".in", ".py", ".js", ".mjs", ".sh", ".html", ".css"}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', re.M)


def sources(dirs=SOURCE_DIRS, suffixes=SOURCE_SUFFIXES):
    for d in dirs:
        for p in sorted((ROOT / d).rglob("*")):
            if p.is_file() and p.suffix in suffixes and "node_modules" not in p.parts:
                yield p


def includes(path):
    return INCLUDE.findall(path.read_text(errors="replace"))


class Layout(unittest.TestCase):
    def test_no_file_over_600_lines(self):
        long = [f"{p.relative_to(ROOT)}: {n}" for p in sources() if (n := len(p.read_text(errors="replace").splitlines())) > 600]
        self.assertEqual(long, [], "files over 600 lines")

    def test_no_include_cycle(self):
        # Project headers by bare name (every renderer and server directory is on the include path).
        headers = {p.name: p for p in sources(["renderer", "server"], {".h", ".inc"})}
        graph = {name: [i.split("/")[-1] for i in includes(p) if i.split("/")[-1] in headers] for name, p in headers.items()}
        state = {}
        cycle = []

        def visit(node, stack):
            state[node] = 1
            for nxt in graph[node]:
                if state.get(nxt) == 1:
                    cycle.append(" -> ".join(stack[stack.index(nxt):] + [nxt]))
                elif nxt not in state:
                    visit(nxt, stack + [nxt])
            state[node] = 2

        for name in sorted(graph):
            if name not in state:
                visit(name, [name])
        self.assertEqual(cycle, [], "include cycles")

    def test_embree_lives_in_one_file(self):
        users = [str(p.relative_to(ROOT)) for p in sources(["renderer", "server", "bench"], {".h", ".cpp", ".inc"})
                 if any(i.startswith("embree3/") for i in includes(p))]
        self.assertEqual(users, ["renderer/accel.cpp"])

    def test_the_renderer_knows_no_http(self):
        users = [str(p.relative_to(ROOT)) for p in sources(["renderer"], {".h", ".cpp", ".inc"})
                 if any("httplib" in i or ("nlohmann" in i and not p.name.startswith("gltf_")) for i in includes(p))]
        self.assertEqual(users, [])

    def test_the_library_does_not_include_its_front_ends(self):
        cmd = {p.name for p in (ROOT / "renderer" / "cmd").glob("*.h")}
        self.assertTrue(cmd, "renderer/cmd holds the front ends")
        library = [p for p in sources(["renderer"], {".h", ".cpp", ".inc"}) if "cmd" not in p.relative_to(ROOT).parts]
        users = [f"{p.relative_to(ROOT)}: {i}" for p in library for i in includes(p) if i.split("/")[-1] in cmd]
        self.assertEqual(users, [])

    def test_helpers_include_only_helpers(self):
        util = ROOT / "renderer" / "util"
        own = {p.name for p in util.iterdir()}
        library = {p.name for p in sources(["renderer"], {".h", ".inc"})} - own
        users = [f"{p.relative_to(ROOT)}: {i}" for p in util.iterdir() if p.suffix in {".h", ".cpp", ".inc"}
                 for i in includes(p) if i.split("/")[-1] in library]
        self.assertEqual(users, [])


if __name__ == "__main__":
    sys.exit(unittest.main())
