#!/usr/bin/env bash
# Fuzzes the scene loaders (parse_collada + make_render_scene, tests/fuzz_collada.cpp; the glTF
# reader, tests/fuzz_gltf.cpp, as long) and then what the server interprets in a request (headers,
# job spec JSON, UTF-8 repair: tests/fuzz_http.cpp, for half as long) with libFuzzer in its own
# tree build-fuzz (clang, -fsanitize=fuzzer,address,undefined). The COLLADA loader is seeded with
# scenes/, ../shared/scenes-cs184/ (copied at run time: the course scenes stay out of the
# repository) and the regression inputs; the glTF reader with tests/fuzz-gltf-seeds/ and the
# regression inputs named .gltf / .glb. Exits non-zero on a finding: crash-*, timeout-*, oom-* in build-fuzz/findings;
# each one fixed becomes a file in tests/fuzz-regressions/ (test_hostile_scenes loads them all).
# Usage: scripts/fuzz.sh [SECONDS] [libFuzzer flags...]   (default 60 s, as scripts/test.sh runs it)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
[ $# -gt 0 ] && shift
flags="-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
if [ ! -f build-fuzz/build.ninja ]; then
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPT_FUZZ=ON \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_MODULE_LINKER_FLAGS="-fsanitize=address,undefined" > /dev/null
fi
cmake --build build-fuzz --target fuzz_collada fuzz_gltf fuzz_http
corpus=build-fuzz/corpus
mkdir -p "$corpus" build-fuzz/findings
for seed in scenes/*.dae ../shared/scenes-cs184/*.dae tests/fuzz-regressions/*; do
  if [ -f "$seed" ]; then cp "$seed" "$corpus"/; fi
done
chmod u+w "$corpus"/*
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0"
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# -close_fd_mask=2 silences the loader's warnings; libFuzzer and sanitizer reports still print.
# Inputs over 128 KiB (the bunny and dragon) are read truncated; -timeout and -rss_limit_mb make
# a slow or memory-hungry input a finding.
./build-fuzz/tests/fuzz_collada -max_total_time="$seconds" -max_len=131072 -timeout=10 -rss_limit_mb=2048 \
  -close_fd_mask=2 -dict=tests/fuzz_collada.dict -artifact_prefix=build-fuzz/findings/ -print_final_stats=1 \
  "$@" "$corpus"
gltf_corpus=build-fuzz/corpus-gltf
mkdir -p "$gltf_corpus"
for seed in tests/fuzz-gltf-seeds/* tests/fuzz-regressions/*.gltf tests/fuzz-regressions/*.glb; do
  if [ -f "$seed" ]; then cp "$seed" "$gltf_corpus"/; fi
done
chmod u+w "$gltf_corpus"/*
./build-fuzz/tests/fuzz_gltf -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
  -close_fd_mask=2 -dict=tests/fuzz_gltf.dict -artifact_prefix=build-fuzz/findings/gltf- -print_final_stats=1 \
  "$@" "$gltf_corpus"
http_corpus=build-fuzz/corpus-http
mkdir -p "$http_corpus"
cp tests/fuzz-http-seeds/* "$http_corpus"/
chmod u+w "$http_corpus"/*
exec ./build-fuzz/tests/fuzz_http -max_total_time="$(( (seconds + 1) / 2 ))" -max_len=4096 -timeout=10 \
  -rss_limit_mb=2048 -dict=tests/fuzz_http.dict -artifact_prefix=build-fuzz/findings/http- -print_final_stats=1 \
  "$@" "$http_corpus"
