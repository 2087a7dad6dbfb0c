#!/usr/bin/env bash
# Creates build/venv, the Python environment of the server tests (tests/server) and
# bench/server_bench.py: the pinned packages of tests/server/requirements.txt from PyPI.
# Idempotent: returns at once when the venv already has exactly those pins.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=build/venv
req=tests/server/requirements.txt
python=/usr/bin/python3  # Debian's, which python3-venv and python3-pip belong to
[ -x "$python" ] || python=python3
mkdir -p build
exec 9> build/.venv.lock  # one installer at a time
flock 9
if [ -x "$venv/bin/python" ] && cmp -s "$req" "$venv/requirements.installed" &&
   "$venv/bin/python" -c "import pytest, requests, jsonschema" 2> /dev/null; then
  echo "python-env: $venv is up to date"
  exit 0
fi
echo "python-env: installing $(tr '\n' ' ' < "$req")into $venv"
"$venv/bin/python" -c "" 2> /dev/null || { rm -rf "$venv"; "$python" -m venv "$venv"; }
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$req"
cp "$req" "$venv/requirements.installed"
