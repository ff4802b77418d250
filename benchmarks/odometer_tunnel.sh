#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Odometer (VMS) aiding through a tunnel from IF samples (issue 19 "from IF", docs/validation.md "Odometer (VMS)
# aiding on land"): simulates scenarios/odometer_tunnel.toml (a car at 20 m/s, HG1700AE, a 10 Hz odometer with
# scale factor, delay and mounting errors, every satellite blocked from 30 s to 90 s) and runs
# `receive --imu imu.csv --coupling C` on it without and with `--odometer odometer.csv` for each coupling C (loose,
# tight, ultra-tight: the odometer states ride in every filter). Prints, for each run, the horizontal error against
# truth.csv at the tunnel's entry (30 s) and exit (90 s) and its RMS over the blockage (benchmarks/nav_error_stats.py),
# and the odometer object's estimates.
# CPU: ~10 s simulate + ~1-3 s per receive on one core; 400 MB of samples in --out (deleted unless --keep).
# Usage: benchmarks/odometer_tunnel.sh [--build DIR] [--out DIR] [--couplings "loose tight ultra-tight"]
#          [--brdc RINEX --week W --tow-shift S] [--keep]
#   --brdc (or --nav): the scenario's broadcast ephemerides (default the shipped tests/data file;
#   benchmarks/ephemeris_option.sh)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
root=$here
source "$here/benchmarks/ephemeris_option.sh"
build="$here/build"; out="${TMPDIR:-/tmp}/odometer_tunnel"; keep=0; couplings="loose tight ultra-tight"
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;; --out) out="$2"; shift 2 ;; --keep) keep=1; shift ;;
    --couplings) couplings="$2"; shift 2 ;;
    --brdc|--nav) brdc=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
[ -f "$brdc" ] || { echo "odometer_tunnel.sh: no $brdc (--brdc RINEX)" >&2; exit 2; }
brdc=$(realpath "$brdc"); nav=$brdc
U="$build/tools/ultratrack"
mkdir -p "$out"
# the scenario with absolute paths (the copy lives in $out)
retime_scenario "$here/scenarios/odometer_tunnel.toml" |
  sed -e "s|^file = \"\(.*\)\"|file = \"$here/scenarios/\1\"|" > "$out/tunnel.toml"
rm -rf "$out/sim"
nice -n 5 "$U" simulate --scenario "$out/tunnel.toml" --out "$out/sim" --quiet > "$out/sim.log"
prns=$(tail -n +2 "$out/sim/satellites.csv" | cut -d, -f1 | paste -sd, -)
for coupling in $couplings; do
  for mode in without with; do
    extra=()
    [ "$mode" = with ] && extra=(--odometer "$out/sim/odometer.csv")
    run="rx_${coupling}_$mode"
    rm -rf "$out/$run"
    nice -n 5 "$U" receive --input "$out/sim/antenna0.i8.bin" --format i8 --fs 2.0e6 --nav "$nav" --prn "$prns" \
      --imu "$out/sim/imu.csv" --coupling "$coupling" "${extra[@]}" --out "$out/$run" --quiet > "$out/$run.log"
  done
done
[ "$keep" = 1 ] || rm -f "$out/sim/antenna0.i8.bin"
python3 - "$out" "$here/benchmarks/nav_error_stats.py" $couplings <<'PY'
import json, subprocess, sys
out, stats, couplings = sys.argv[1], sys.argv[2], sys.argv[3:]
def horizontal(run, t0, t1):
    r = subprocess.run([sys.executable, stats, f"{out}/{run}/nav.csv", f"{out}/sim/truth.csv",
                        "--from-s", str(t0), "--to-s", str(t1)], check=True, capture_output=True, text=True)
    return json.loads(r.stdout)["horizontal_rms_m"]
print("coupling,odometer,entry_30s_m,exit_90s_m,rms_30_90s_m")
for coupling in couplings:
    for mode in ("without", "with"):
        run = f"rx_{coupling}_{mode}"
        print(f"{coupling},{mode},{horizontal(run, 30, 30):.2f},{horizontal(run, 90, 90):.2f},"
              f"{horizontal(run, 30, 90):.2f}")
for coupling in couplings:
    o = json.load(open(f"{out}/rx_{coupling}_with/summary.json"))["fusion"]["odometer"]
    print(f"{coupling} estimates: scale factor {o['scale_factor']:.5f} +- {o['sigma_scale_factor']:.5f} (simulated "
          f"0.003), misalignment pitch {o['misalignment_pitch_deg']:.3f} +- {o['sigma_misalignment_pitch_deg']:.3f} "
          f"deg (0.2), yaw {o['misalignment_yaw_deg']:.3f} +- {o['sigma_misalignment_yaw_deg']:.3f} deg (-0.3), "
          f"delay {o['delay_s']:.3f} +- {o['sigma_delay_s']:.3f} s (0.02); odometer updates accepted "
          f"{o['updates_accepted']}, gated out by heading rate {o['gated_yaw_rate']}")
PY
