#!/usr/bin/env bash
# Renders a fixed set of EXRs with one build, and optionally compares them bit for bit with a set
# made by another build: the check behind "same bits" in docs/performance.md.
#
#   scripts/same_bits.sh BUILD_DIR OUT_DIR [BASELINE_DIR]
#
# The set covers what the path loop specialises on: diffuse only (the packet lanes), delta and
# microfacet materials, meshes, a thin lens, spot and point lights, adaptive sampling on and off,
# the scalar loop (-H), the cell option (-p) and several thread counts. Course scenes are taken
# from ../shared/scenes-cs184 when it is there. Exit status 1 when any image differs.
set -euo pipefail
cd "$(dirname "$0")/.."
build=$1 out=$2 base=${3:-}
pt=$build/pathtracer
mkdir -p "$out"
shared=../shared/scenes-cs184
common=(--quiet --seed 7 -l 1 -m 5 -r 160 120)
cases=()
add() { cases+=("$*"); }
add "cornell -t 2 -s 16 scenes/cornell.dae"
add "cornell_adaptive -t 2 -s 64 -a 8 0.05 scenes/cornell.dae"
add "cornell_H -t 1 -s 8 -H scenes/cornell.dae"
add "dof -t 2 -s 16 -b 0.12 -d 4.7 scenes/dof.dae"
add "dof_cell -t 2 -s 16 -b 0.12 -d 4.7 -p 40 30 64 48 scenes/dof.dae"
if [[ -d $shared ]]; then
  for s in CBspheres CBspheres_lambertian CBspheres_microfacet_al_ag CBbunny CBdragon CBempty; do
    add "$s -t 2 -s 16 --no-adaptive --keep-fov $shared/$s.dae"
  done
  add "CBspheres_adaptive -t 2 -s 64 $shared/CBspheres.dae"
  add "CBspheres_t1 -t 1 -s 8 --keep-fov $shared/CBspheres.dae"
  add "CBbunny_l4 -t 2 -s 8 -l 4 --keep-fov $shared/CBbunny.dae"
fi
status=0
for c in "${cases[@]}"; do
  read -r name args <<<"$c"
  # shellcheck disable=SC2086
  "$pt" "${common[@]}" $args -f "$out/$name.exr" >/dev/null
  if [[ -n $base ]]; then
    if idiff -a -fail 0 -warn 0 "$base/$name.exr" "$out/$name.exr" >/dev/null 2>&1; then
      echo "same  $name"
    else
      echo "DIFF  $name"
      status=1
    fi
  fi
done
exit $status
