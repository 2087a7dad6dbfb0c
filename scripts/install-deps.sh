#!/usr/bin/env bash
# Installs the Debian 12 packages the project builds and tests with (skips apt when all are present);
# `install-deps.sh main`: only what building and running the service needs.
set -euo pipefail
# What building and running the service needs (scripts/main.sh installs only these: `main`) ...
packages=(
  build-essential cmake ninja-build pkg-config python3
  libembree-dev libopenimageio-dev openimageio-tools libpugixml-dev libtbb-dev
  libtinygltf-dev  # glTF 2.0 scenes (header-only tinygltf; its images are decoded by OpenImageIO)
  libgtest-dev libcpp-httplib-dev nlohmann-json3-dev libglfw3-dev
  libgl1-mesa-dri  # the window's OpenGL without a GPU (Mesa's llvmpipe)
  libhiredis-dev  # render-worker's Redis client (the scale-out queue)
  libssl-dev  # the render farm's signatures (HMAC-SHA256, server/farm_security.cpp)
  python3-pip  # fetches the denoiser, Intel Open Image Denoise, from PyPI (scripts/install-oidn.sh)
)
# ... and what the tests add.
if [ "${1:-all}" != main ]; then
  packages+=(
    xvfb xauth  # the window tests run under Xvfb
    chromium nodejs npm  # the web page's browser test (tests/web: playwright-core drives this Chromium)
    python3-venv python3-pip  # build/venv for the server tests (scripts/python-env.sh)
    redis-server  # the scale-out tests' Redis
    spiped  # the scale-out tunnel test (an encrypted pipe to Redis, docs/scale-out.md)
    iproute2 util-linux  # the two-host test: network namespaces joined by a veth pair
    clang libclang-rt-14-dev  # build-fuzz: libFuzzer and the sanitizer runtimes (scripts/fuzz.sh, asan.sh)
  )
fi
missing=()
for p in "${packages[@]}"; do
  # A nodejs that bundles npm (NodeSource's) conflicts with Debian's npm package: keep it.
  if [ "$p" = npm ] && command -v npm >/dev/null 2>&1; then continue; fi
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  bash "$(dirname "$0")/install-oidn.sh"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
bash "$(dirname "$0")/install-oidn.sh"  # the denoiser: not packaged by Debian 12
