#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# A MEMS unit that starts parked, from IF samples (scenarios/circle_parked_bmi088.toml): `receive --imu --coupling
# loose --align motion`, the filter told only the preset class (bmi088), with the gyro biases of the parked start
# ([alignment] standstill_gyro_bias, the default) and without them (learnt in motion). Prints each run's alignment
# note and its errors from 40 s (benchmarks/nav_error_stats.py). About 15 s on 2 cores.
#   benchmarks/validation/standstill_if.sh [--build DIR] [--out DIR] [--filter ekf|ukf]
set -euo pipefail
here="$(cd "$(dirname "$0")/../.." && pwd)"
build="$here/build"; out="${TMPDIR:-/tmp}/standstill_if"; filter=ekf
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;; --out) out="$2"; shift 2 ;; --filter) filter="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
U="$build/tools/ultratrack"
mkdir -p "$out"
"$U" simulate --scenario "$here/scenarios/circle_parked_bmi088.toml" --out "$out/sim" --quiet >/dev/null
for standstill in true false; do
  printf '[imu]\npreset = "bmi088"\n\n[alignment]\nstandstill_gyro_bias = %s\n' "$standstill" > "$out/fusion_$standstill.toml"
  "$U" receive --input "$out/sim/antenna0.i8.bin" --format i8 --fs 2.6e6 --imu "$out/sim/imu.csv" --coupling loose \
      --filter "$filter" --align motion --fusion-config "$out/fusion_$standstill.toml" --out "$out/rx_$standstill" \
      --quiet >/dev/null
  note=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['fusion']['alignment']['note'])" \
      "$out/rx_$standstill/summary.json")
  stats=$(python3 "$here/benchmarks/nav_error_stats.py" "$out/rx_$standstill/nav.csv" "$out/sim/truth.csv" --from-s 40)
  echo "standstill_gyro_bias = $standstill: aligned $note"
  echo "  from 40 s: $stats"
done
python3 -c "import json,sys; print('simulated turn-on gyro biases [deg/h]:', json.load(open(sys.argv[1]))['gyro_turn_on_bias_dph'])" \
    "$out/sim/summary.json"
