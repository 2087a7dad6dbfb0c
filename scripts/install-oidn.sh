#!/usr/bin/env bash
# Installs Intel Open Image Denoise (OIDN 2.5.1, Apache-2.0), the denoiser behind --denoise and a
# job's denoise field, into build/oidn/lib: its CPU libraries from the pinned PyPI wheel pyoidn
# 2.5.1.0 (Debian 12 does not package OIDN; the wheel carries its shared libraries). The renderer
# loads them at run time (renderer/denoiser.cpp), so everything else works without them.
# Idempotent. A failed download leaves the renderer without a denoiser and says so; it does not
# fail the caller. PT_OIDN_REQUIRED=1 makes it fail (the tests need it).
set -euo pipefail
cd "$(dirname "$0")/.."
dest=build/oidn
version=2.5.1
wheel=pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl
sha256=32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e
if [ -f "$dest/installed" ] && [ "$(cat "$dest/installed")" = "$version" ]; then
  echo "install-oidn: OIDN $version is in $dest"
  exit 0
fi
fail() {
  echo "install-oidn: $1; the renderer runs without its denoiser (--denoise says how to get it)" >&2
  [ "${PT_OIDN_REQUIRED:-0}" = 1 ] && exit 1
  exit 0
}
[ "$(uname -m)" = x86_64 ] || fail "the wheel is for x86-64 Linux only"
mkdir -p build
tmp=$(mktemp -d build/.oidn.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
# pip verifies the hash (--require-hashes); --no-deps: only the libraries are used, not its Python.
printf 'pyoidn==2.5.1.0 --hash=sha256:%s\n' "$sha256" > "$tmp/requirements.txt"
python3 -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
  --platform manylinux2014_x86_64 --require-hashes -r "$tmp/requirements.txt" -d "$tmp" ||
  fail "could not download $wheel from PyPI"
# Only the CPU device: the core, its CPU module and the loader (about 50 MB of the wheel's 87 MB).
# Their TBB is the system's (libtbb12, which Embree already loads; every symbol they need is there).
python3 - "$tmp/$wheel" "$tmp/lib" "$version" <<'EOF' || fail "could not unpack $wheel"
import os, sys, zipfile
wheel, out, version = sys.argv[1:]
os.makedirs(out)
names = [f"libOpenImageDenoise.so.{version}", f"libOpenImageDenoise_core.so.{version}",
         f"libOpenImageDenoise_device_cpu.so.{version}"]
with zipfile.ZipFile(wheel) as z:
    for name in names:
        with z.open("pyoidn/oidn/lib/" + name) as src, open(os.path.join(out, name), "wb") as dst:
            dst.write(src.read())
    # The wheel's own licence (MIT); OIDN itself is Apache-2.0 (README, "Dependencies").
    with z.open("pyoidn-2.5.1.0.dist-info/licenses/LICENSE") as src, open(os.path.join(out, "LICENSE-pyoidn"), "wb") as dst:
        dst.write(src.read())
os.symlink(f"libOpenImageDenoise.so.{version}", os.path.join(out, "libOpenImageDenoise.so.2"))
EOF
# In lib/: the libraries find each other through their RPATH, $ORIGIN/../lib.
echo "$version" > "$tmp/lib/installed"
rm -rf "$dest"
mkdir -p "$dest"
mv "$tmp/lib" "$dest/lib"
mv "$dest/lib/installed" "$dest/installed"
echo "install-oidn: OIDN $version installed in $dest"
