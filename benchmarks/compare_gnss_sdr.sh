#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Side by side on the same file: GNSS-SDR (Debian package gnss-sdr, run by benchmarks/peers/gnss_sdr_run.sh,
# whose header documents its configuration: File_Signal_Source, pass-through conditioner, PCPS acquisition
# +-5 kHz / 250 Hz / pfa 0.01, DLL/PLL 2 Hz / 25 Hz with 0.5 chip spacing, Hybrid observables, RTKLIB single
# point PVT at 10 Hz, broadcast ionosphere, Saastamoinen troposphere) and `ultratrack receive` with the
# equivalent settings (8 channels, 10 Hz fixes, broadcast ionosphere, troposphere on). Prints for each the
# median realtime factor (wall clock), the median CPU realtime factor (signal seconds per CPU second of all its
# threads: robust to a loaded machine), the median peak RSS and the 3-D RMS error of its fixes against the
# simulator's truth (GNSS-SDR logs one fix per second, ultratrack writes ten).
#
#   benchmarks/compare_gnss_sdr.sh [--build DIR] [--scratch DIR] [--runs N] [--threads N]
#       [--brdc FILE --week W --tow-shift S]
#
# The file: Nagoya from tow 530772 on the shipped ephemeris (benchmarks/ephemeris_option.sh; mask 9 deg: 10
# satellites there, 8 on brdc0010.22n from 518772, where the [E] figures were measured), 60 s, 2.6 MHz i8, 45 dB-Hz, with
# ionosphere and troposphere in the signal so that both receivers' models apply; synthesised once into the
# scratch folder (default ${ULTRATRACK_BENCH_DIR:-/tmp/ultratrack_bench}). Where the machine has more than 2 cores,
# both receivers are pinned to cores 0-1 (taskset) for the issue's 2-core figure. Exits 0 with a message when
# gnss-sdr is not installed.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
root=$here
source "$here/benchmarks/ephemeris_option.sh"
if ! command -v gnss-sdr >/dev/null; then
  echo "compare_gnss_sdr.sh: gnss-sdr is not installed (apt-get install gnss-sdr): comparison skipped"
  exit 0
fi
build=$here/build; scratch=${ULTRATRACK_BENCH_DIR:-/tmp/ultratrack_bench}; runs=3; threads=2
while [[ $# -gt 0 ]]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --scratch) scratch=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --brdc) brdc=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    *) echo "compare_gnss_sdr.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
ut=$build/tools/ultratrack
[[ -x $ut ]] || { echo "compare_gnss_sdr.sh: $ut not built" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "compare_gnss_sdr.sh: /usr/bin/time missing (apt-get install time)" >&2; exit 2; }
brdc=$(realpath "$brdc")
pin=()
if [[ $(nproc) -gt 2 ]] && command -v taskset >/dev/null; then pin=(taskset -c 0,1); fi

dir=$scratch/compare_sat8_2.6e6_i8
scenario="[signal]
sample_rate_hz = 2.6e6
format = \"i8\"
duration_s = 60.0
cn0_dbhz = 45.0
seed = 1
[time]
gps_week = $(brdc_week_or 1823)
tow_s = $(brdc_tow_plus 530772.0)
[navigation]
rinex = \"$brdc\"
elevation_mask_deg = 9.0
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
[atmosphere]
ionosphere = true
troposphere = true"
mkdir -p "$dir"
if [[ ! -f $dir/done || "$(cat "$dir/input.toml")" != "$scenario" ]]; then
  echo "$scenario" > "$dir/input.toml"
  echo "synthesising $dir ..." >&2
  "$ut" simulate --scenario "$dir/input.toml" --out "$dir/sim" --quiet >&2
  touch "$dir/done"
fi
input=$dir/sim/antenna0.i8.bin
truth=$dir/sim/truth.csv

# errors.py KIND PATH TRUTH: 3-D RMS of the fixes against the first truth row (static receiver).
errors() {
  python3 - "$@" <<'PY'
import csv, math, re, sys
kind, path, truth = sys.argv[1:]
row = next(csv.DictReader(open(truth)))
r = [float(row[k]) for k in ("ecef_x_m", "ecef_y_m", "ecef_z_m")]
def ecef(lat, lon, h):  # WGS 84
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    lat, lon = math.radians(lat), math.radians(lon)
    n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
    return [(n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1 - e2) + h) * math.sin(lat)]
fixes = []
if kind == "ours":
    fixes = [[float(f[k]) for k in ("ecef_x_m", "ecef_y_m", "ecef_z_m")] for f in csv.DictReader(open(path))]
else:
    for line in open(path, errors="replace"):
        m = re.search(r"Lat = ([-0-9.]+) \[deg\], Long = ([-0-9.]+) \[deg\], Height\s*=\s*([-0-9.]+) \[m\]", line)
        if m: fixes.append(ecef(*map(float, m.groups())))
sq = [sum((p[i] - r[i]) ** 2 for i in range(3)) for p in fixes]
print(f"{math.sqrt(sum(sq) / len(sq)):.2f} {len(fixes)}" if sq else "nan 0")
PY
}
median() { python3 -c 'import statistics,sys; v=[float(x) for x in sys.argv[1:]]; print(f"{statistics.median(v):.4g}")' "$@"; }

echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores${pin:+, pinned to cores 0-1}; $runs runs each"
g_rt=(); g_mb=(); g_cpu=(); u_rt=(); u_mb=(); u_cpu=()
cpu_rt() {  # time -v file -> signal seconds (60) per CPU second
  awk -F': ' '/User time|System time/ {s += $2} END {printf "%.3f\n", 60.0 / s}' "$1"
}
for ((r = 0; r < runs; r++)); do
  gout=$dir/gnss-sdr
  rm -rf "$gout"
  line=$("${pin[@]}" "$here/benchmarks/peers/gnss_sdr_run.sh" "$input" i8 2600000 "$gout" 8 | grep "realtime factor")
  g_rt+=("$(sed -E 's/.*realtime factor ([0-9.]+).*/\1/' <<<"$line")")
  g_mb+=("$(sed -E 's/.*peak memory ([0-9.]+) MB.*/\1/' <<<"$line")")
  g_cpu+=("$(cpu_rt "$gout/time.txt")")
  g_err=$(errors gnss "$gout/gnss-sdr.log" "$truth")
  uout=$dir/ultratrack
  rm -rf "$uout"
  "${pin[@]}" /usr/bin/time -v -o "$dir/time.txt" "$ut" receive --input "$input" --format i8 --fs 2.6e6 --out "$uout" \
    --quiet --channels 8 --threads "$threads" --reference-week "$(brdc_week_or 1823)" >/dev/null
  u_rt+=("$(python3 -c "import json; print(json.load(open('$uout/summary.json'))['realtime_factor'])")")
  u_mb+=("$(awk '/Maximum resident set size/ {print $NF / 1024}' "$dir/time.txt")")
  u_cpu+=("$(cpu_rt "$dir/time.txt")")
  u_err=$(errors ours "$uout/solution.csv" "$truth")
done
printf "%-22s %11s %11s %9s %12s %7s\n" receiver realtime_x cpu_rt_x peak_MB err3d_rms_m fixes
printf "%-22s %11s %11s %9s %12s %7s\n" "GNSS-SDR $(gnss-sdr --version 2>&1 | grep -oE '[0-9]+\.[0-9]+\.[0-9]+' | head -1)" \
  "$(median "${g_rt[@]}")" "$(median "${g_cpu[@]}")" "$(median "${g_mb[@]}")" ${g_err}
printf "%-22s %11s %11s %9s %12s %7s\n" "ultratrack (-j $threads)" "$(median "${u_rt[@]}")" "$(median "${u_cpu[@]}")" \
  "$(median "${u_mb[@]}")" ${u_err}
python3 -c "print(f'ultratrack / GNSS-SDR: realtime factor {$(median "${u_rt[@]}") / $(median "${g_rt[@]}"):.1f}x, CPU realtime factor {$(median "${u_cpu[@]}") / $(median "${g_cpu[@]}"):.1f}x')"
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
