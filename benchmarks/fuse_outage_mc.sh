#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# 60 s GNSS outage Monte Carlo through the command line (imusim -> gnsssim -> fuse --outage): land profile
# 265 s at 100 Hz, 5 Hz fixes (1.5/1.5/3 m, 0.02 m/s velocity), outage from 200.37 s; horizontal error at the
# outage end, RMS over RUNS runs per preset. The filter-level Monte Carlo (1 Hz, 0.05 m/s) is
# tests/fusion/integration_test.cpp with ULTRATRACK_FUSION_MC_RUNS=100; this one checks the `fuse` path.
# Usage: benchmarks/fuse_outage_mc.sh [RUNS] [PRESET...]   (about 1 s per run; needs build/tools/ultratrack)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
U="$root/build/tools/ultratrack"
runs=${1:-100}
shift || true
presets=("${@:-navigation hg1700ae}")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for p in ${presets[@]}; do
  printf '[imu]\npreset = "%s"\n[gnss]\nvelocity_sigma_mps = 0.02\n' "$p" > "$work/c.toml"
  : > "$work/r.txt"
  for k in $(seq 1 "$runs"); do
    "$U" imusim --profile land --duration 265 --rate 100 --preset "$p" --seed $((1000 + k)) --out "$work/s" >/dev/null
    "$U" gnsssim --truth "$work/s/truth.csv" --rate 5 --first 0.37 --velocity-sigma 0.02 --seed $((2000 + k)) \
      --out "$work/s/g.csv" >/dev/null
    "$U" fuse --imu "$work/s/imu.csv" --gnss "$work/s/g.csv" --config "$work/c.toml" --outage 200.37 60 \
      --truth "$work/s/truth.csv" --quiet --out "$work/s/f" >/dev/null
    grep -o '"horizontal_error_m": [0-9.e+-]*, "sigma_horizontal_m": [0-9.e+-]*' "$work/s/f/summary.json" |
      tr -d ',' | awk '{print $2, $4}' >> "$work/r.txt"
  done
  awk -v p="$p" '{n++; s += $1 * $1; q += $2 * $2; if ($1 > m) m = $1}
    END {printf "%s: 60 s outage horizontal drift RMS %.3f m over %d runs (max %.3f m, filter 1-sigma RMS %.3f m)\n",
         p, sqrt(s / n), n, m, sqrt(q / n)}' "$work/r.txt"
done
