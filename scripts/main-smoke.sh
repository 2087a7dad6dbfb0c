#!/usr/bin/env bash
# The README's first command, checked as a user runs it: scripts/main.sh starts the server with
# the bundled scenes and the page. It must print its address, serve the page, answer /api/health
# and list the bundled scenes; then it is stopped. scripts/test.sh runs this after ctest, so a
# change that breaks the main job fails CI even where every unit of it passes.
# Usage: scripts/main-smoke.sh   (needs the build main.sh makes; installs nothing new when present)
set -euo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
log="$work/server.log"
pid=""
stop() {
  if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
    kill "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap stop EXIT
fail() {
  echo "main-smoke: FAILED: $*" >&2
  echo "--- scripts/main.sh output ---" >&2
  cat "$log" >&2
  exit 1
}

PT_DATA_DIR="$work/data" bash scripts/main.sh --port 0 > "$log" 2>&1 &
pid=$!
url=""
for _ in $(seq 1 600); do  # up to 60 s: main.sh checks the packages and the build first
  url=$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$log" | head -n 1 || true)
  [ -n "$url" ] && break
  kill -0 "$pid" 2>/dev/null || fail "scripts/main.sh exited before the server listened"
  sleep 0.1
done
[ -n "$url" ] || fail "no 'listening on' address within 60 s"

# python3 (installed with the build tools) rather than curl, which a bare Debian image lacks.
get() { python3 -c 'import sys, urllib.request; sys.stdout.write(urllib.request.urlopen(sys.argv[1], timeout=10).read().decode())' "$url$1"; }
page=$(get "") || fail "GET / failed"
grep -q "<title>" <<< "$page" || fail "GET / did not return the page"
get "api/health" > /dev/null || fail "GET /api/health failed"
scenes=$(get "api/scenes") || fail "GET /api/scenes failed"
shopt -s nullglob
bundled=(scenes/*.dae scenes/*.gltf scenes/*.glb)
shopt -u nullglob
for s in "${bundled[@]}"; do
  name=$(basename "${s%.*}")
  grep -q "\"name\":\"$name\"" <<< "$scenes" || fail "the bundled scene '$name' is not listed by /api/scenes"
done
echo "main-smoke: scripts/main.sh serves the page and the ${#bundled[@]} bundled scenes at $url"
