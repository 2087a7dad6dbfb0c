#!/usr/bin/env bash
# The C++ test suite (and the server tests, against the instrumented render-server) under
# AddressSanitizer + UndefinedBehaviorSanitizer: clang, -O1, its own tree build-asan. Any report
# fails the run. Embree, TBB, OpenImageIO and httplib are not instrumented; only their leaks are
# suppressed (tests/sanitizers/lsan.supp), never a frame of ours.
# Usage: scripts/asan.sh [--build-only] [ctest arguments...]
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build_only=0
if [ "${1:-}" = --build-only ]; then build_only=1; shift; fi
# intercept_tls_get_addr=0: with it on, LeakSanitizer reads a bogus dynamic-TLS range of a library
# the image module loads and its tracer crashes at exit ("Tracer caught signal 11", "DTLS 14 at
# 0x1d4e-0x800002e50"; google/sanitizers#1353), after tests that pass (Features.ParametersAddTheirFeatures
# every time). Leaks are still found: only the dynamic-TLS blocks are not scanned as roots.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:abort_on_error=0:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1:intercept_tls_get_addr=0"
export LSAN_OPTIONS="suppressions=$root/tests/sanitizers/lsan.supp:print_suppressions=0"
export PT_SANITIZED=1  # tests/server/test_load.py allows for the allocator's quarantine
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$root/tests/sanitizers/ubsan.supp"
flags="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
if [ ! -f build-asan/build.ninja ]; then
  CC=clang CXX=clang++ cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_MODULE_LINKER_FLAGS="-fsanitize=address,undefined" > /dev/null
fi
# gtest_discover_tests runs each test binary at build time: under the options above.
cmake --build build-asan
[ "$build_only" = 1 ] && exit 0
# The server tests use build/venv (scripts/python-env.sh): the same packages, the asan binaries.
ln -sfn ../build/venv build-asan/venv
cd build-asan
# The window (Mesa under Xvfb) and web (Chromium) tests exercise uninstrumented code at length:
# left to the plain build.
ctest --output-on-failure --timeout 900 -j "$(nproc)" -LE '^(window|web)$' "$@"
