#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Seed 000's alignment end to end from IF, over RUNS runs: scenarios/align_static_if.toml (the seed's 3-antenna
# array, 3 mm carrier noise, 45 dB-Hz, HG1700AE at 100 Hz, at rest at 0/0/0 for 110 s) simulated with a new signal
# and IMU seed per run, received by `ultratrack attitude`, aligned by `ultratrack align` (100 s from the first fixed
# attitude, EKF, filter 1 Hz); final roll/pitch/yaw errors against the truth (0/0/0), RMS over the runs beside the
# filter's 1-sigma and seed 000 Table 2. About 1 min of CPU and 1.7 GB of scratch per run (deleted as it goes).
# Usage: benchmarks/alignment_if.sh [--brdc FILE --week W --tow-shift S] [RUNS] [FIRST_SEED]   (needs
# build/tools/ultratrack; the ephemeris: benchmarks/ephemeris_option.sh, the shipped file by default)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
source "$root/benchmarks/ephemeris_option.sh"
U="$root/build/tools/ultratrack"
while [[ $# -gt 0 && $1 == --* ]]; do
  case $1 in
    --brdc) brdc=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    *) echo "alignment_if.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
runs=${1:-20}
first=${2:-1}
[ -f "$brdc" ] || { echo "alignment_if.sh: broadcast ephemeris $brdc missing (--brdc FILE)" >&2; exit 2; }
brdc=$(realpath "$brdc")
nav=$brdc
work=${ULTRATRACK_WORK:-$(mktemp -d)}
mkdir -p "$work"
results="$work/results.txt"
: > "$results"
for k in $(seq "$first" $((first + runs - 1))); do
  retime_scenario "$root/scenarios/align_static_if.toml" | sed -e "s|^seed = 11|seed = $((100 + k))|" \
      -e "s|^seed = 7|seed = $((200 + k))|" > "$work/s.toml"
  "$U" simulate --scenario "$work/s.toml" --out "$work/sim" >/dev/null
  "$U" attitude --input "$work"/sim/antenna{0,1,2}.i8.bin --format i8 --fs 2.6e6 \
      --antennas "$root/scenarios/attitude_antennas.toml" --nav "$nav" --out "$work/rx" >/dev/null
  "$U" align --imu "$work/sim/imu.csv" --attitude "$work/rx/attitude.csv" --attitude-origin "$(brdc_week_or 1823)" "$(brdc_tow_plus 530396)" \
      --position 35.274016 137.013759 100 --quiet --out "$work/al" >/dev/null
  python3 - "$work/al/alignment.json" "$k" >> "$results" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print(sys.argv[2], j["roll_deg"], j["pitch_deg"], j["yaw_deg"], j["sigma_roll_deg"], j["sigma_pitch_deg"],
      j["sigma_yaw_deg"], j["duration_s"], j["updates"]["attitude"], len(j["warnings"]))
PY
  rm -rf "$work/sim" "$work/rx"
  tail -1 "$results"
done
python3 - "$results" <<'PY'
import math, sys
rows = [list(map(float, l.split())) for l in open(sys.argv[1]) if l.strip()]
n = len(rows)
print(f"\nSeed 000 Table 2 end to end from IF: {n} runs (attitude -> align, 100 s)")
print("| axis | seed 1-sigma | our RMS error | our mean error | filter 1-sigma (mean) | max abs error |")
print("|---|---|---|---|---|---|")
for i, (name, seed) in enumerate([("roll", 0.045), ("pitch", 0.040), ("yaw", 0.025)]):
    e = [r[1 + i] if i < 2 else ((r[3] + 180) % 360 - 180) for r in rows]
    s = [r[4 + i] for r in rows]
    rms = math.sqrt(sum(x * x for x in e) / n)
    print(f"| {name} | {seed:.3f} | {rms:.4f} | {sum(e) / n:+.4f} | {sum(s) / n:.4f} | {max(abs(x) for x in e):.4f} |")
print(f"runs with warnings: {sum(1 for r in rows if r[9] > 0)}; attitude updates per run: {min(r[8] for r in rows):.0f}-{max(r[8] for r in rows):.0f}")
PY
