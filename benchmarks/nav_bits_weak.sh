#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Data wipe-off with real-world bits against the oracle (issue 27): the same weak-signal files through
# `receive --coupling ultra-tight` with the default `--nav-bits decoded` and with `--nav-bits oracle`, by
# benchmarks/tracking_threshold.sh's step protocol (all satellites at 45 dB-Hz for STRONG_S, then a C/N0 step to
# each level for DURATION s; lock kept per satellite, 3-D RMS of solution.csv and nav.csv against truth.csv over
# the weak part). The files are simulated once (decoded pass, --keep) and linked into the oracle pass (--reuse).
#
#   benchmarks/nav_bits_weak.sh [--levels "18 20 25"] [--files 2] [--strong-s 16] [--duration 40] [--filter ukf]
#       [--scenario scenarios/ultratight_straight.toml] [--nav FILE [--week W --tow-shift S]] [--ultratrack BIN]
#       [--out DIR]
# Writes DIR/decoded and DIR/oracle (tracking_threshold.sh's folders: runs.csv, positions.csv, nav_positions.csv)
# and prints both reports. A scenario's `rinex` path is replaced by --nav (benchmarks/ephemeris_option.sh: the
# shipped file by default), its week and start moved by --week / --tow-shift.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
source "$root/benchmarks/ephemeris_option.sh"
levels="18 20 25"; files=2; strong_s=16; duration=40; filter=ukf
scenario=$root/scenarios/ultratight_straight.toml
ultratrack=$root/build/tools/ultratrack; out=/tmp/ultratrack_nav_bits
while [ $# -gt 0 ]; do
  case "$1" in
    --levels) levels=$2; shift 2 ;;
    --files) files=$2; shift 2 ;;
    --strong-s) strong_s=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --filter) filter=$2; shift 2 ;;
    --scenario) scenario=$2; shift 2 ;;
    --nav|--brdc) brdc=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    --ultratrack) ultratrack=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "nav_bits_weak: unknown argument $1" >&2; exit 2 ;;
  esac
done
brdc=$(realpath "$brdc"); nav=$brdc
mkdir -p "$out/decoded" "$out/oracle"
retime_scenario "$scenario" > "$out/scenario.toml"
common=(--levels "$levels" --files "$files" --strong-s "$strong_s" --duration "$duration" --scenario "$out/scenario.toml"
        --couplings ultra-tight --filter "$filter" --nav "$nav" --ultratrack "$ultratrack")
"$here/tracking_threshold.sh" "${common[@]}" --keep --out "$out/decoded" > "$out/decoded.log" 2>&1
for f in "$out"/decoded/cn0_*_file_*.sim "$out"/decoded/cn0_*_file_*.sim.toml; do ln -sf "$f" "$out/oracle/"; done
"$here/tracking_threshold.sh" "${common[@]}" --reuse --receive-args "--nav-bits oracle" --out "$out/oracle" \
  > "$out/oracle.log" 2>&1
for mode in decoded oracle; do
  echo "== --nav-bits $mode"
  sed -n '/^== coupling/,$p' "$out/$mode.log"
done
