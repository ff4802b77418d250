#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Output identity across a refactor: runs a fixed set of jobs with one build and prints one SHA-256 line per
# output file, so that two builds (before and after a move of code) can be compared with `diff`.
#
#   benchmarks/output_identity.sh [--build DIR] [--scratch DIR] [--brdc FILE --week W --tow-shift S] [--only REGEX] \
#       > hashes.txt
#
# Jobs: the demo (`ultratrack demo`, 45 s, built-in scenario); the throughput set's 8-satellite file (2.6 MHz i8,
# static, 60 s, benchmarks/receiver_throughput.sh's recipe) through `receive --threads 2`; the seed-001 straight
# trajectory (scenarios/ultratight_straight.toml, 40 s, HG1700AE) through `receive --coupling ultra-tight` (UKF) and
# `receive --coupling vector`; the static 3-antenna scenario (scenarios/attitude_static.toml, 30 s) through
# `attitude`; and the same IMU file through `fuse`-free `ins`. Simulated files are cached in the scratch folder
# (${ULTRATRACK_IDENTITY_DIR:-/tmp/ultratrack_identity}), keyed by the job name: delete it after changing the
# simulator. Left out of the hash: lines that carry the wall time (summary.json's wall_time_s, realtime_factor,
# threads used), RINEX headers' creation date, and the run folder's name inside JSON (replaced by RUNS); every
# other byte of every output file counts.
#
# Ephemeris (benchmarks/ephemeris_option.sh): the shipped tests/data/brdc3540_0000-0200.14n by default. Before the
# move to it the default was ../shared/data/brdc0010.22n; those hashes (/work/identity/baseline.txt of the machine
# they were taken on) come back with --brdc ../shared/data/brdc0010.22n --week 2190 --tow-shift -12000. Simulated
# files made with another ephemeris than brdc0010.22n are cached under sim_<job>_<file name>.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
root=$here
source "$here/benchmarks/ephemeris_option.sh"
build=$here/build
scratch=${ULTRATRACK_IDENTITY_DIR:-/tmp/ultratrack_identity}
only=.
while [[ $# -gt 0 ]]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --scratch) scratch=$2; shift 2 ;;
    --brdc) brdc=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    *) echo "output_identity.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
ut=$build/tools/ultratrack
[[ -x $ut ]] || { echo "output_identity.sh: $ut not built" >&2; exit 2; }
[[ -f $brdc ]] || { echo "output_identity.sh: broadcast ephemeris $brdc missing (--brdc FILE)" >&2; exit 2; }
brdc=$(realpath "$brdc")
mkdir -p "$scratch"
runs=$scratch/runs.$$
rm -rf "$runs"; mkdir -p "$runs"
trap 'rm -rf "$runs"' EXIT

# A scenario file with every `rinex = ...` pointed at the ephemeris (its week and start moved with it) and
# `duration_s` lines set to $2.
rewrite_scenario() {  # source duration_s -> stdout
  retime_scenario "$1" | sed -e "s|^duration_s = [0-9.]*|duration_s = $2|"
}

# The cache key: the job's name, and the ephemeris file's name unless it is brdc0010.22n (the key before the move).
cache_key=""
[[ $(basename "$brdc") == brdc0010.22n ]] || cache_key=_$(basename "$brdc")

simulate_once() {  # name scenario_text_file
  local dir=$scratch/sim_$1$cache_key
  [[ -f $dir/summary.json ]] && return 0
  rm -rf "$dir"
  "$ut" simulate --scenario "$2" --out "$dir" >/dev/null
}

# Hashes every regular file under a folder, relative names, with the wall-time lines of JSON files removed.
hash_outputs() {  # job dir
  local job=$1 dir=$2 f rel
  while IFS= read -r f; do
    rel=${f#"$dir"/}
    if [[ $f == *.json ]]; then
      h=$(grep -v -E '"(wall_time_s|wall_s|realtime_factor|cpu_time_s|threads)"' "$f" | sed "s|$runs|RUNS|g" |
          sha256sum | cut -c1-64)
    elif [[ $f == *.rnx ]]; then  # the header's creation date
      h=$(grep -v 'PGM / RUN BY / DATE' "$f" | sha256sum | cut -c1-64)
    else
      h=$(sha256sum "$f" | cut -c1-64)
    fi
    echo "$job $rel $h"
  done < <(find "$dir" -type f | LC_ALL=C sort)
}

job() { [[ $1 =~ $only ]]; }

if job demo; then
  (cd "$runs" && "$ut" demo --out "$runs/demo" >/dev/null)
  # The demo deletes its sample file unless --keep-samples; what it leaves is compared.
  hash_outputs demo "$runs/demo"
fi

if job sat8; then
  cat > "$scratch/sat8.toml" <<TOML
[signal]
sample_rate_hz = 2.6e6
format = "i8"
duration_s = 60
cn0_dbhz = 45.0
seed = 1
[time]
gps_week = $(brdc_week_or 1823)
tow_s = $(brdc_tow_plus 530772.0)
[navigation]
rinex = "$brdc"
elevation_mask_deg = 9.0
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
TOML
  simulate_once sat8 "$scratch/sat8.toml"
  # Cold (no nav file): on the shipped 2014 file the 10-bit week needs the reference (the build date is > 512 weeks
  # later); with --week the run is the one from before the move, which had none.
  week_flag=(--reference-week 1823); [[ -n $brdc_week ]] && week_flag=()
  "$ut" receive --input "$scratch/sim_sat8$cache_key/antenna0.i8.bin" --format i8 --fs 2.6e6 --threads 2 --quiet \
    "${week_flag[@]}" --out "$runs/sat8" >/dev/null
  hash_outputs sat8 "$runs/sat8"
fi

if job 'ultratight|vector'; then
  rewrite_scenario "$here/scenarios/ultratight_straight.toml" 40 > "$scratch/straight.toml"
  simulate_once straight "$scratch/straight.toml"
  s=$scratch/sim_straight$cache_key
  if job ultratight; then
    "$ut" receive --input "$s/antenna0.i8.bin" --format i8 --fs 2.6e6 --nav "$brdc" --imu "$s/imu.csv" \
      --coupling ultra-tight --filter ukf --threads 2 --quiet --out "$runs/ultratight" >/dev/null
    hash_outputs ultratight "$runs/ultratight"
  fi
  if job vector; then
    "$ut" receive --input "$s/antenna0.i8.bin" --format i8 --fs 2.6e6 --nav "$brdc" --coupling vector \
      --threads 2 --quiet --out "$runs/vector" >/dev/null
    hash_outputs vector "$runs/vector"
  fi
fi

if job attitude; then
  rewrite_scenario "$here/scenarios/attitude_static.toml" 30 > "$scratch/attitude.toml"
  simulate_once attitude "$scratch/attitude.toml"
  a=$scratch/sim_attitude$cache_key
  "$ut" attitude --input "$a/antenna0.i8.bin" "$a/antenna1.i8.bin" "$a/antenna2.i8.bin" --format i8 --fs 2.6e6 \
    --antennas "$here/scenarios/attitude_antennas.toml" --nav "$brdc" --out "$runs/attitude" >/dev/null
  hash_outputs attitude "$runs/attitude"
fi

if job simulate; then
  # The simulator itself: a short inertial scenario written afresh (samples, IMU, truth).
  rewrite_scenario "$here/scenarios/ultratight_straight.toml" 5 > "$runs/sim5.toml"
  "$ut" simulate --scenario "$runs/sim5.toml" --out "$runs/simulate" >/dev/null
  rm -f "$runs/simulate/scenario.toml"  # holds the scratch path of the ephemeris
  hash_outputs simulate "$runs/simulate"
fi
