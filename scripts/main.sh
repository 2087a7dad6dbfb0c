#!/usr/bin/env bash
# The main job: installs dependencies, builds, and renders the bundled default scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
./build/pathtracer -t "$(nproc)" -s 64 -l 4 -m 5 -r 480 360 -f out/cornell.png scenes/cornell.dae
echo "Wrote out/cornell.png (and out/cornell_rate.png)"
