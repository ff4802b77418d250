#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Whole-receiver throughput: synthesises a standard set of IF files once (cached in a scratch folder), runs
# `ultratrack receive` on each several times and prints, per file, the median realtime factor (summary.json:
# signal seconds / wall seconds), the median CPU realtime factor (signal seconds / CPU seconds of all threads,
# which a loaded machine disturbs far less), the median peak RSS (/usr/bin/time -v) and the 3-D RMS error of the
# fixes against the simulator's truth.
#
#   benchmarks/receiver_throughput.sh [--build DIR] [--scratch DIR] [--runs N] [--threads N] [--only REGEX]
#       [--brdc FILE --week W --tow-shift S]
#
# Standard set: 8 and 12 satellites x 2.6 / 4 / 16 MHz x i8 / i16, complex baseband, 45 dB-Hz, static receiver,
# the shipped broadcast ephemeris tests/data/brdc3540_0000-0200.14n of 2014-12-20 (benchmarks/ephemeris_option.sh)
# (set "8": Nagoya from tow 530772, 6 s before subframe 4 page 18, first fix ~36 s in, simulator elevation mask
# 9 deg: 10 satellites here, 8 on brdc0010.22n where the set was named; set "12": 70 N 90 W from tow 530398, 2 s
# before a frame, first fix ~20 s in, mask 0: 11 satellites here, three below the receiver's 10 deg mask; 12 on
# brdc0010.22n with one below it). 60 s of signal, 40 s
# at 16 MHz (2.6 GB for i16). Defaults: build/, ${ULTRATRACK_BENCH_DIR:-/tmp/ultratrack_bench}, 3 runs,
# --threads 2 (the issue's 2 cores; --threads none for builds without the option). Needs python3 and /usr/bin/time (Debian package `time`).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
root=$here
source "$here/benchmarks/ephemeris_option.sh"
build=$here/build; scratch=${ULTRATRACK_BENCH_DIR:-/tmp/ultratrack_bench}; runs=3; threads=2; only=.
while [[ $# -gt 0 ]]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --scratch) scratch=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    --brdc) brdc=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    *) echo "receiver_throughput.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
ut=$build/tools/ultratrack
[[ -x $ut ]] || { echo "receiver_throughput.sh: $ut not built (cmake --build build --target ultratrack)" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "receiver_throughput.sh: /usr/bin/time missing (apt-get install time)" >&2; exit 2; }
[[ -f $brdc ]] || { echo "receiver_throughput.sh: $brdc missing (--brdc FILE)" >&2; exit 2; }
brdc=$(realpath "$brdc")
mkdir -p "$scratch"
threads_flag=(--threads "$threads")
[[ $threads == none ]] && threads_flag=()  # builds from before --threads existed

# name sats fs format duration
set_list() {
  for sats in 8 12; do
    for fs in 2.6e6 4e6 16e6; do
      for fmt in i8 i16; do
        duration=60; [[ $fs == 16e6 ]] && duration=40
        echo "sat${sats}_${fs}_${fmt} $sats $fs $fmt $duration"
      done
    done
  done
}

synthesise() {  # name sats fs format duration -> the IF file path on stdout
  local name=$1 sats=$2 fs=$3 fmt=$4 duration=$5 dir=$scratch/$1
  local llh="35.274016, 137.013759, 100.0" mask=9 tow
  tow=$(brdc_tow_plus 530772.0)
  [[ $sats == 12 ]] && { llh="70.0, -90.0, 100.0"; mask=0; tow=$(brdc_tow_plus 530398.0); }
  local scenario
  scenario=$(cat <<TOML
[signal]
sample_rate_hz = $fs
format = "$fmt"
duration_s = $duration
cn0_dbhz = 45.0
seed = 1
[time]
gps_week = $(brdc_week_or 1823)
tow_s = $tow
[navigation]
rinex = "$brdc"
elevation_mask_deg = $mask
[receiver]
llh_deg_m = [$llh]
[atmosphere]
ionosphere = true
troposphere = false
TOML
)
  if [[ ! -f $dir/done || "$(cat "$dir/input.toml")" != "$scenario" ]]; then
    rm -rf "$dir"; mkdir -p "$dir"
    echo "$scenario" > "$dir/input.toml"
    echo "synthesising $name ..." >&2
    "$ut" simulate --scenario "$dir/input.toml" --out "$dir/sim" --quiet >&2
    touch "$dir/done"
  fi
  echo "$dir/sim/antenna0.$fmt.bin"
}

median() { python3 -c 'import statistics,sys; v=[float(x) for x in sys.argv[1:]]; print(f"{statistics.median(v):.4g}")' "$@"; }

echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores; $runs runs per file, --threads $threads"
printf "%-18s %5s %9s %6s %9s %9s %9s %8s %9s\n" file sats fs_MHz fmt signal_s rt_factor cpu_rt peak_MB err3d_m
while read -r name sats fs fmt duration; do
  [[ $name =~ $only ]] || continue
  input=$(synthesise "$name" "$sats" "$fs" "$fmt" "$duration")
  rts=(); cpus=(); rss=(); err=
  for ((r = 0; r < runs; r++)); do
    out=$scratch/$name/rx
    rm -rf "$out"
    /usr/bin/time -v -o "$scratch/$name/time.txt" "$ut" receive --input "$input" --format "$fmt" --fs "$fs" \
      --out "$out" --quiet ${threads_flag[@]+"${threads_flag[@]}"} --reference-week "$(brdc_week_or 1823)" --troposphere off >/dev/null
    read -r rt cpu kb e < <(python3 - "$out" "$scratch/$name/time.txt" "$scratch/$name/sim/truth.csv" <<'PY'
import csv, json, math, sys
out, timing, truth = sys.argv[1:]
s = json.load(open(f"{out}/summary.json"))
t = {}
for line in open(timing):
    k, _, v = line.strip().rpartition(": ")
    t[k] = v
cpu = float(t["User time (seconds)"]) + float(t["System time (seconds)"])
signal = s["duration_s"]
row = next(csv.DictReader(open(truth)))
r = [float(row[k]) for k in ("ecef_x_m", "ecef_y_m", "ecef_z_m")]
sq = [sum((float(f[k]) - r[i]) ** 2 for i, k in enumerate(("ecef_x_m", "ecef_y_m", "ecef_z_m")))
      for f in csv.DictReader(open(f"{out}/solution.csv"))]
err = math.sqrt(sum(sq) / len(sq)) if sq else float("nan")
print(s["realtime_factor"], signal / cpu, t["Maximum resident set size (kbytes)"], f"{err:.3f}")
PY
)
    rts+=("$rt"); cpus+=("$cpu"); rss+=("$(python3 -c "print($kb/1024)")"); err=$e
  done
  printf "%-18s %5s %9s %6s %9s %9s %9s %8s %9s\n" "$name" "$sats" "$(python3 -c "print($fs/1e6)")" "$fmt" "$duration" \
    "$(median "${rts[@]}")" "$(median "${cpus[@]}")" "$(median "${rss[@]}")" "$err"
done < <(set_list)
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
