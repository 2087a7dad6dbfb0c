#!/usr/bin/env bash
# Regenerates docs/stability.md from the stability_report program that ctest also runs.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build --target stability_report > /dev/null
{
  cat <<'HEAD'
# Numerical stability on stiff and extreme cases

Every row is rendered and checked by `build/tests/stability_report` (ctest test `stability`,
label `stress`; regenerate this page with `bash scripts/stability-report.sh`). A case passes when
no sample or pixel is NaN/Inf and its check holds: white-furnace cases (a sphere under a uniform
environment of radiance 1) may not exceed 1 (no energy gain) or must equal the stated value;
"compared with" cases must agree with their limit case within 4.5 standard errors of the per-pixel
difference (plus a small relative tolerance); "finite" cases must only stay finite.

Columns: non-finite samples dropped by the release-build guard (must be 0), the brightest pixel
component, the image's mean luminance, the comparison, what was measured, the verdict.

HEAD
  ./build/tests/stability_report --report 2>/dev/null | sed '/^stability:/d'
} > docs/stability.md
echo "wrote docs/stability.md"
