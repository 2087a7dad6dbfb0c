#!/usr/bin/env bash
# The test command: installs dependencies, builds, runs every test with ctest; then the sanitizer
# run and a short fuzzing run.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
# The browser test's Node packages (tests/web), installed only when missing or older than the lock file.
if [ ! -f tests/web/node_modules/.package-lock.json ] ||
   [ tests/web/package-lock.json -nt tests/web/node_modules/.package-lock.json ]; then
  (cd tests/web && npm ci --no-audit --no-fund)
fi
bash scripts/python-env.sh  # build/venv: pytest, requests, jsonschema, schemathesis for tests/server
(cd build && ctest --output-on-failure --timeout 900 -j "$(nproc)")
bash scripts/main-smoke.sh  # the README's first command: the server with the bundled scenes and the page
# The C++ and server tests again under AddressSanitizer + UBSan (build-asan), then the scene loader
# under libFuzzer for a minute (build-fuzz); docs/reliability.md has the longer runs.
bash scripts/asan.sh
bash scripts/fuzz.sh 60
