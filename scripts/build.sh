#!/usr/bin/env bash
# Configures (Release) and builds into ./build: everything, or only the targets named
# (scripts/main.sh builds the three binaries the main job runs: bash scripts/build.sh render-server ...).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
if [ $# -gt 0 ]; then
  cmake --build build --target "$@"
else
  cmake --build build
fi
