#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Realtime factor of two builds on the same files, interleaved (A, B, A, B, ...) so that the load of a shared
# machine falls on both alike; prints per job the median signal-seconds / wall-seconds of each build (summary.json's
# realtime_factor) and their ratio B / A.
#
#   benchmarks/compare_speed.sh --a BIN_A --b BIN_B [--rounds N] [--scratch DIR] [--brdc FILE]
#   (--brdc: the ephemeris output_identity.sh simulated with; the shipped tests/data file by default)
#
# BIN_A / BIN_B: two `ultratrack` binaries. Jobs, on the files benchmarks/output_identity.sh simulates (same scratch
# folder, ${ULTRATRACK_IDENTITY_DIR:-/tmp/ultratrack_identity}; run that script first): sat8 (8 satellites, 60 s,
# 2.6 MHz i8, scalar; 10 satellites on the shipped file) and ultratight (40 s of the seed-001 straight trajectory, UKF, the default loop), --threads 2.
set -euo pipefail
rounds=5
scratch=${ULTRATRACK_IDENTITY_DIR:-/tmp/ultratrack_identity}
here=$(cd "$(dirname "$0")/.." && pwd)
root=$here
source "$here/benchmarks/ephemeris_option.sh"
a=""; b=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --a) a=$2; shift 2 ;;
    --b) b=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --scratch) scratch=$2; shift 2 ;;
    --brdc) brdc=$2; shift 2 ;;
    *) echo "compare_speed.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
[[ -x $a && -x $b ]] || { echo "compare_speed.sh: --a and --b must name two ultratrack binaries" >&2; exit 2; }
key=""  # output_identity.sh's cache key
[[ $(basename "$brdc") == brdc0010.22n ]] || key=_$(basename "$brdc")
[[ -f $scratch/sim_sat8$key/antenna0.i8.bin && -f $scratch/sim_straight$key/imu.csv ]] ||
  { echo "compare_speed.sh: run benchmarks/output_identity.sh first (files in $scratch)" >&2; exit 2; }
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT

run_job() {  # binary job -> realtime factor on stdout
  local bin=$1 job=$2 dir=$out/run
  rm -rf "$dir"
  case $job in
    sat8) "$bin" receive --input "$scratch/sim_sat8$key/antenna0.i8.bin" --format i8 --fs 2.6e6 --threads 2 --quiet \
            --out "$dir" >/dev/null ;;
    ultratight) "$bin" receive --input "$scratch/sim_straight$key/antenna0.i8.bin" --format i8 --fs 2.6e6 --nav "$brdc" \
            --imu "$scratch/sim_straight$key/imu.csv" --coupling ultra-tight --filter ukf --threads 2 --quiet \
            --out "$dir" >/dev/null ;;
  esac
  python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["realtime_factor"])' "$dir/summary.json"
}

median() { sort -g | awk '{v[NR]=$1} END {print (NR%2 ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2)}'; }

printf '%-11s %8s %8s %7s   (median realtime factor of %d interleaved runs each)\n' job A B B/A "$rounds"
for job in sat8 ultratight; do
  : > "$out/a.txt"; : > "$out/b.txt"
  for ((k = 0; k < rounds; ++k)); do
    run_job "$a" $job >> "$out/a.txt"
    run_job "$b" $job >> "$out/b.txt"
  done
  ma=$(median < "$out/a.txt"); mb=$(median < "$out/b.txt")
  printf '%-11s %8.1f %8.1f %7.3f\n' $job "$ma" "$mb" "$(python3 -c "print($mb / $ma)")"
done
