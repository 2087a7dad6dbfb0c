#!/usr/bin/env bash
# The main job: installs dependencies, builds, and starts the render server with the bundled
# scenes and the web page. Options are passed to render-server (e.g. --port 9000).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh main
bash scripts/build.sh render-server render-worker pathtracer heavy_scene  # not the tests: scripts/test.sh builds those
exec ./build/render-server --data "${PT_DATA_DIR:-data}" "$@"
