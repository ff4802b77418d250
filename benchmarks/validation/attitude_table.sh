#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The attitude table of docs/validation.md (section 8): the committed 3-antenna scenarios simulated and received by
# `ultratrack attitude`, then each run's attitude.csv against the simulator's truth (attitude_table.py):
#   static 100 s (scenarios/attitude_static.toml) with every satellite, with the 8 and the 7 highest (--prn: fewer
#   satellites, the geometry the seed's targets name), the banked 500 km/h circle (attitude_moving.toml) and the
#   static receiver's cycle slips and 5 s blockage (attitude_faults.toml).
#   benchmarks/validation/attitude_table.sh [--out DIR] [--ultratrack build/tools/ultratrack] [--keep]
# Cost: about 1 CPU-min and 1.6 GB of scratch at a time (sample files are deleted after their receive unless --keep).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
name=attitude_table.sh; out=/tmp/ultratrack_attitude_table
source "$here/table_options.sh"
nav=$root/tests/data/brdc3540_0000-0200.14n
antennas=$root/scenarios/attitude_antennas.toml

receive() {  # sim_dir rx_dir [attitude options]
  local sim=$1 rx=$2; shift 2
  "$ultratrack" attitude --input "$sim"/antenna0.i8.bin "$sim"/antenna1.i8.bin "$sim"/antenna2.i8.bin --format i8 \
    --fs 2.6e6 --antennas "$antennas" --nav "$nav" --quiet --out "$rx" "$@" > "$rx.log"
}
highest() {  # sim_dir n -> the n highest PRNs of satellites.csv, comma-separated
  tail -n +2 "$1/satellites.csv" | sort -t, -k2,2 -g -r | head -n "$2" | cut -d, -f1 | sort -n | paste -sd, -
}
rows=()
for scenario in static moving faults; do
  sim=$out/$scenario
  "$ultratrack" simulate --scenario "$root/scenarios/attitude_$scenario.toml" --out "$sim" --quiet > "$sim.log"
  receive "$sim" "$out/${scenario}_rx"
  n=$(($(wc -l < "$sim/satellites.csv") - 1))
  rows+=("$scenario, $n satellites" "$out/${scenario}_rx/attitude.csv" "$sim/truth.csv")
  if [ "$scenario" = static ]; then
    for k in 8 7; do
      receive "$sim" "$out/static_rx$k" --prn "$(highest "$sim" $k)"
      rows+=("static, the $k highest ($(highest "$sim" $k))" "$out/static_rx$k/attitude.csv" "$sim/truth.csv")
    done
  fi
  [ "$keep" = 1 ] || rm -f "$sim"/antenna*.bin
done
python3 "$here/attitude_table.py" "${rows[@]}"
