#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Odometer (VMS) aiding through a tunnel from IF samples (issue 19 "from IF", docs/validation.md "Odometer (VMS)
# aiding on land"): simulates scenarios/odometer_tunnel.toml (a car at 20 m/s, HG1700AE, a 10 Hz odometer with
# scale factor, delay and mounting errors, every satellite blocked from 30 s to 90 s) and runs
# `receive --imu imu.csv --coupling loose` on it without and with `--odometer odometer.csv`. Prints, for each, the
# horizontal error against truth.csv at the tunnel's entry (30 s) and exit (90 s) and its RMS over the blockage
# (benchmarks/nav_error_stats.py), and the odometer object's estimates.
# CPU: ~10 s simulate + ~1 s per receive on one core; 400 MB of samples in --out (deleted unless --keep).
# Usage: benchmarks/odometer_tunnel.sh [--build DIR] [--out DIR] [--brdc RINEX --week W --tow-shift S] [--keep]
#   --brdc (or --nav): the scenario's broadcast ephemerides (default the shipped tests/data file;
#   benchmarks/ephemeris_option.sh)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
root=$here
source "$here/benchmarks/ephemeris_option.sh"
build="$here/build"; out="${TMPDIR:-/tmp}/odometer_tunnel"; keep=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;; --out) out="$2"; shift 2 ;; --keep) keep=1; shift ;;
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
for mode in without with; do
  extra=()
  [ "$mode" = with ] && extra=(--odometer "$out/sim/odometer.csv")
  rm -rf "$out/rx_$mode"
  nice -n 5 "$U" receive --input "$out/sim/antenna0.i8.bin" --format i8 --fs 2.0e6 --nav "$nav" --prn "$prns" \
    --imu "$out/sim/imu.csv" --coupling loose "${extra[@]}" --out "$out/rx_$mode" --quiet > "$out/rx_$mode.log"
done
[ "$keep" = 1 ] || rm -f "$out/sim/antenna0.i8.bin"
python3 - "$out" "$here/benchmarks/nav_error_stats.py" <<'PY'
import json, subprocess, sys
out, stats = sys.argv[1], sys.argv[2]
def horizontal(mode, t0, t1):
    r = subprocess.run([sys.executable, stats, f"{out}/rx_{mode}/nav.csv", f"{out}/sim/truth.csv",
                        "--from-s", str(t0), "--to-s", str(t1)], check=True, capture_output=True, text=True)
    return json.loads(r.stdout)["horizontal_rms_m"]
print("odometer,entry_30s_m,exit_90s_m,rms_30_90s_m")
for mode in ("without", "with"):
    print(f"{mode},{horizontal(mode, 30, 30):.2f},{horizontal(mode, 90, 90):.2f},{horizontal(mode, 30, 90):.2f}")
o = json.load(open(f"{out}/rx_with/summary.json"))["fusion"]["odometer"]
print("estimates: scale factor {:.5f} +- {:.5f} (simulated 0.003), misalignment pitch {:.3f} +- {:.3f} deg (0.2), "
      "yaw {:.3f} +- {:.3f} deg (-0.3), delay {:.3f} +- {:.3f} s (0.02); odometer updates accepted {}, gated out by "
      "heading rate {}".format(o["scale_factor"], o["sigma_scale_factor"], o["misalignment_pitch_deg"],
                               o["sigma_misalignment_pitch_deg"], o["misalignment_yaw_deg"], o["sigma_misalignment_yaw_deg"],
                               o["delay_s"], o["sigma_delay_s"], o["updates_accepted"], o["gated_yaw_rate"]))
PY
