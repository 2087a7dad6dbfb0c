#!/usr/bin/env bash
# Paths in Embree packets (16 rays, 8 without AVX-512) against one path at a time (--no-ray-packets): samples/s of the pathtracer
# in the comparison framing (480x360 --keep-fov, 64 spp, -l 1, m = 5, no adaptive, 2 threads; dof
# through its thin lens), the two runs interleaved, medians of N.
# Usage: bench/packets_ab.sh [runs=5]   (a built ./build; the course scenes need ../shared/scenes-cs184)
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: bench/packets_ab.sh [runs=5]"
case "${1:-}" in -h|--help) echo "$usage"; exit 0 ;; esac
runs=${1:-5}
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "packets_ab.sh: runs must be a positive whole number, not '$runs'" >&2; echo "$usage" >&2; exit 2; }
S=../shared/scenes-cs184
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
source bench/progress.sh
start=$(date +%s.%N) done=0 total=$((4 * runs))
rate() { ./build/pathtracer -t 2 -s 64 -l 1 -m 5 -r 480 360 --no-adaptive -f "$out/v.exr" "$@" 2>/dev/null | tail -1 |
         grep -o '[0-9.e+]* samples/s' | cut -d' ' -f1; }
for s in CBspheres CBbunny CBdragon dof; do
  if [ "$s" = dof ]; then f=scenes/dof.dae; x=(-b 0.12 -d 4.7); else f=$S/$s.dae; x=(--keep-fov); fi
  if [ ! -f "$f" ]; then echo "$s: skipped ($f is absent)"; continue; fi
  a=(); b=()
  for i in $(seq "$runs"); do
    progress "$s run $i/$runs" "$done" "$total" "$start"
    a+=("$(rate "${x[@]}" "$f")")
    b+=("$(rate "${x[@]}" --no-ray-packets "$f")")
    done=$((done + 1))
  done
  progress_clear
  python3 - "$s" "${a[*]}" "${b[*]}" <<'PY'
import statistics as st, sys
name, a, b = sys.argv[1], [float(x) for x in sys.argv[2].split()], [float(x) for x in sys.argv[3].split()]
print("%-10s packets %6.2f M samples/s  one at a time %6.2f M  ratio %.3f  (packets %s | one at a time %s)" % (
    name, st.median(a) / 1e6, st.median(b) / 1e6, st.median(a) / st.median(b),
    " ".join("%.2f" % (x / 1e6) for x in a), " ".join("%.2f" % (x / 1e6) for x in b)))
PY
done
