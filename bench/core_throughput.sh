#!/usr/bin/env bash
# Wall time, samples/s and rays/s of the pathtracer on the course scenes (median of N runs).
# Usage: bench/core_throughput.sh [runs=3]   (needs ../shared/scenes-cs184 and a built ./build)
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: bench/core_throughput.sh [runs=3]"
case "${1:-}" in -h|--help) echo "$usage"; exit 0 ;; esac
runs=${1:-3}
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "core_throughput.sh: runs must be a positive whole number, not '$runs'" >&2; echo "$usage" >&2; exit 2; }
S=../shared/scenes-cs184
[ -d "$S" ] || { echo "bench: $S is absent"; exit 0; }
out=$(mktemp -d)
source bench/progress.sh
start=$(date +%s.%N) done=0 total=$((3 * runs))
run_case() {  # name, args...
  local name=$1; shift
  local lines=()
  for i in $(seq "$runs"); do
    progress "${name%% *} run $i/$runs" "$done" "$total" "$start"
    lines+=("$(./build/pathtracer --quiet "$@" -f "$out/img.png" | tail -1)")
    done=$((done + 1))
  done
  progress_clear
  printf '%s\n' "${lines[@]}" | python3 -c '
import sys, re, statistics
rows = [l for l in sys.stdin.read().splitlines() if l]
def col(rx): return statistics.median(float(re.search(rx, r).group(1)) for r in rows)
print("%-34s wall %6.2f s  %6.3f M samples/s  %6.2f M rays/s  (median of %d)" % (sys.argv[1],
      col(r", ([0-9.]+) s, "), col(r"([0-9.e+]+) samples/s")/1e6, col(r"([0-9.e+]+) rays/s")/1e6, len(rows)))' "$name"
}
run_case "CBspheres m=5  480x360 64spp -t2"  -t 2 -s 64 -l 4 -m 5 -r 480 360 $S/CBspheres.dae
run_case "CBspheres m=100 480x360 64spp -t2" -t 2 -s 64 -l 4 -m 100 -r 480 360 $S/CBspheres.dae
run_case "CBdragon m=5  480x360 64spp -t2"   -t 2 -s 64 -l 4 -m 5 -r 480 360 $S/CBdragon.dae
rm -rf "$out"
