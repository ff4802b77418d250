#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Is the datasheet MEMS model honest? The MEMS drive of benchmarks/mems_fusion.sh over many seeds (default 50: IMU
# errors, fix noise and alignment all redrawn), then the NEES of position, velocity and attitude averaged over the
# runs at each time, against its chi-square 95 % band (benchmarks/nav_nees.py). Options after --runs go to
# mems_fusion.sh unchanged (e.g. --fixes pos, --filter ukf, --correlation 30 --told-correlation 30 --told-sigma ...);
# --window-s W adds nav_nees.py's windows (each axis's NEES, RMS error and RMS 1-sigma per W seconds from --from-s).
#   benchmarks/mems_nees.sh [--build DIR] [--runs 50] [--out DIR] [--from-s 60] [--window-s W] [mems_fusion.sh options]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="$here/build"; runs=50; out="${TMPDIR:-/tmp}/mems_nees"; from_s=60; window_s=0; pass=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;; --runs) runs="$2"; shift 2 ;; --out) out="$2"; shift 2 ;;
    --from-s) from_s="$2"; shift 2 ;; --window-s) window_s="$2"; shift 2 ;;
    *) pass+=("$1"); shift ;;
  esac
done
"$here/benchmarks/mems_fusion.sh" --build "$build" --out "$out" --seeds "$(seq -s ' ' 1 "$runs")" --from-s "$from_s" \
    --clean "${pass[@]}"
pairs=()
for seed in $(seq 1 "$runs"); do pairs+=("$out/seed$seed/fuse/nav.csv" "$out/seed$seed/sim/truth.csv"); done
echo "NEES over $runs runs (from $from_s s): mean over runs and times, chi-square 95 % band of a $runs-run average"
python3 "$here/benchmarks/nav_nees.py" --from-s "$from_s" --window-s "$window_s" "${pairs[@]}" | tee "$out/nees.json"
