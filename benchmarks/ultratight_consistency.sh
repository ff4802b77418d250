#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Receiver-level consistency of the ultra-tight filter (issue 7): the whole receiver on synthesised IF, N seeds.
# Scenario: the car of the ReceiveUltraTight tests, a level circle of radius 100 m at 30 km/h
# (scenarios/circle_100m_30kmh_segments.csv), 2 MHz i8, C/N0 --cn0 (45 dB-Hz), HG1700AE IMU at 100 Hz,
# ionosphere and troposphere on (the receiver corrects both by default), signal seed SEED0 + k, IMU seed
# SEED0 + 1000 + k. Each run: `simulate`, then for each filter `receive --coupling ultra-tight --filter F
# --align motion` (motion window 1 s; the tight filter starts at ~9 s, the hand-over is ~2 s later).
# Figures, per filter and evaluation time t (the last nav.csv row at or before t, against truth.csv interpolated):
#   z = (nav - truth) / nav.csv's 1-sigma per NED axis, position and velocity (nav.csv has no cross-covariances:
#   not the 17-state NEES, but each z has mean 0 and E[z^2] = 1 for a consistent filter, whatever the correlations)
#   mean z per axis (a common bias: a systematic error of the model; its 95 % band +-1.96 / sqrt(N)),
#   mean z^2 per axis (95 % band chi2(N) / N), and the sums over N/E/D ("NEES" of position and of velocity; their
#   band chi2(3N) / N holds only if the three axes' errors are uncorrelated, so the per-axis bands are the test).
#   Times before the hand-over (~11.1 s) read the tight filter's rows, which the ultra-tight filter starts from.
# The default protocol is also a campaign file: `ultratrack campaign run campaigns/ultratight_consistency.toml
# --out DIR [--engine slurm]` (docs/usage.md).
# Usage: benchmarks/ultratight_consistency.sh [--runs 40] [--duration 60] [--times "10.5 11 12 14 16 20 25 30 40 50 59.5"]
#          [--filters "ekf ukf"] [--cn0 45] [--seed0 1000] [--out DIR] [--receive-args "..."]
#          [--ultratrack build/tools/ultratrack] [--atmosphere off (neither simulated nor corrected)]
#          [--coupling tight (the tight filter alone, nav.csv from it throughout)] [--report-only DIR]
#          [--brdc FILE --week W --tow-shift S (benchmarks/ephemeris_option.sh; the shipped file by default)]
# Cost (2 MHz i8, --threads 2): per 60 s seed, simulate 5-12 s wall, each receive 1.1-3.2 s; 40 seeds of 60 s with
# both filters took 7.3 min on the project's 2-core machine shared with 3 other jobs (load ~5). Only nav.csv,
# truth.csv and summary.json are kept per run (the sample file is deleted after its receives).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
source "$root/benchmarks/ephemeris_option.sh"
runs=40; duration=60; times="10.5 11 12 14 16 20 25 30 40 50 59.5"; filters="ekf ukf"; cn0=45; seed0=1000
out=/tmp/ultratrack_consistency; ultratrack=$root/build/tools/ultratrack; receive_args=""; report_only=0; atmosphere=on; coupling=ultra-tight
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --times) times=$2; shift 2 ;;
    --filters) filters=$2; shift 2 ;;
    --cn0) cn0=$2; shift 2 ;;
    --seed0) seed0=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --receive-args) receive_args=$2; shift 2 ;;
    --ultratrack) ultratrack=$2; shift 2 ;;
    --atmosphere) atmosphere=$2; shift 2 ;;
    --coupling) coupling=$2; shift 2 ;;
    --brdc|--nav) brdc=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    --report-only) report_only=1; out=$2; shift 2 ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "ultratight_consistency.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
nav=$(realpath -m "$brdc")
mkdir -p "$out"; out=$(realpath "$out")
if [ "$report_only" = 0 ]; then
  [ -f "$nav" ] || { echo "ultratight_consistency.sh: $nav not found (--brdc FILE)" >&2; exit 2; }
  [ -x "$ultratrack" ] || { echo "ultratight_consistency.sh: $ultratrack not built" >&2; exit 2; }
  printf '[alignment]\nmotion_window_s = 1.0\n' > "$out/motion.toml"
  atmo=true; rx_config=()
  if [ "$atmosphere" = off ]; then
    atmo=false; printf '[pvt]\nionosphere = false\ntroposphere = false\n' > "$out/no_atmosphere.toml"
    rx_config=(--config "$out/no_atmosphere.toml")
  fi
  # scenarios/circle_100m_30kmh_segments.csv's circle, cut to the run (a segment file sets the trajectory's length)
  printf 'duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n%s,0.0,4.774648,0.0,0.0\n' "$duration" \
    > "$out/circle.csv"
  for ((k = 0; k < runs; k++)); do
    sim=$out/sim$k
    cat > "$out/s$k.toml" <<EOF
[signal]
sample_rate_hz = 2.0e6
format = "i8"
duration_s = $duration
cn0_dbhz = $cn0
seed = $((seed0 + k))
[time]
gps_week = $(brdc_week_or 1823)
tow_s = $(brdc_tow_plus 530776.0)
[navigation]
rinex = "$nav"
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
[trajectory]
file = "$out/circle.csv"
speed_mps = 8.333333333
heading_deg = 0.0
imu_rate_hz = 100.0
[imu]
preset = "hg1700ae"
seed = $((seed0 + 1000 + k))
[atmosphere]
ionosphere = $atmo
troposphere = $atmo
EOF
    "$ultratrack" simulate --scenario "$out/s$k.toml" --out "$sim" --quiet > "$out/sim$k.log" 2>&1 ||
      { echo "ultratight_consistency.sh: simulate seed $k failed (see $out/sim$k.log)" >&2; continue; }
    for f in $filters; do
      # shellcheck disable=SC2086
      "$ultratrack" receive --input "$sim/antenna0.i8.bin" --format i8 --fs 2.0e6 --nav "$nav" --imu "$sim/imu.csv" \
        --coupling "$coupling" --filter "$f" --align motion --fusion-config "$out/motion.toml" --threads 2 --quiet \
        "${rx_config[@]}" $receive_args --out "$out/rx${k}_$f" > "$out/rx${k}_$f.log" 2>&1 ||
        echo "ultratight_consistency.sh: receive seed $k $f failed (see $out/rx${k}_$f.log)" >&2
    done
    rm -f "$sim/antenna0.i8.bin"
  done
fi
python3 - "$out" "$times" "$filters" <<'EOF'
import csv, bisect, glob, json, math, os, re, sys
out, times, filters = sys.argv[1], [float(t) for t in sys.argv[2].split()], sys.argv[3].split()
# --coupling tight: no hand-over; every run whose fusion started counts.
a = 6378137.0; f = 1 / 298.257223563; e2 = f * (2 - f)
def ecef(lat, lon, h):
    la, lo = math.radians(lat), math.radians(lon); n = a / math.sqrt(1 - e2 * math.sin(la) ** 2)
    return ((n + h) * math.cos(la) * math.cos(lo), (n + h) * math.cos(la) * math.sin(lo), (n * (1 - e2) + h) * math.sin(la))
def ned(lat, lon, d):
    la, lo = math.radians(lat), math.radians(lon)
    sl, cl, so, co = math.sin(la), math.cos(la), math.sin(lo), math.cos(lo)
    return (-sl * co * d[0] - sl * so * d[1] + cl * d[2], -so * d[0] + co * d[1], -cl * co * d[0] - cl * so * d[1] - sl * d[2])
def chi2_quantile(p, k):  # Wilson-Hilferty, good to < 1 % of the band for k >= 20
    zp = {0.025: -1.959964, 0.975: 1.959964}[p]
    return k * (1 - 2 / (9 * k) + zp * math.sqrt(2 / (9 * k))) ** 3
def z_at(truth, tt, rows, rt, t):
    j = bisect.bisect_right(rt, t) - 1
    if j < 0: return None
    r = rows[j]; tr = rt[j]
    i = min(max(bisect.bisect_left(tt, tr), 1), len(tt) - 1)
    w = (tr - tt[i - 1]) / (tt[i] - tt[i - 1])
    lin = lambda k: float(truth[i - 1][k]) + w * (float(truth[i][k]) - float(truth[i - 1][k]))
    lat, lon = float(r["lat_deg"]), float(r["lon_deg"])
    q = ecef(lat, lon, float(r["height_m"]))
    ep = ned(lat, lon, [q[0] - lin("ecef_x_m"), q[1] - lin("ecef_y_m"), q[2] - lin("ecef_z_m")])
    ev = [float(r[k]) - lin(k) for k in ("vel_n_mps", "vel_e_mps", "vel_d_mps")]
    sp = [float(r[k]) for k in ("sigma_n_m", "sigma_e_m", "sigma_d_m")]
    sv = [float(r[k]) for k in ("sigma_vn_mps", "sigma_ve_mps", "sigma_vd_mps")]
    return [ep[k] / sp[k] for k in range(3)] + [ev[k] / sv[k] for k in range(3)], list(ep) + ev, sp + sv
rows_out = []
print(f"ultratight_consistency: {out}")
for flt in filters:
    runs = {}
    handover = []
    for d in sorted(glob.glob(f"{out}/rx*_{flt}")):
        k = re.search(r"rx(\d+)_", d).group(1)
        sim = f"{out}/sim{k}"
        if not os.path.exists(f"{d}/nav.csv") or not os.path.exists(f"{sim}/truth.csv"): continue
        summary = json.load(open(f"{d}/summary.json"))
        s = summary.get("ultratight")
        if s is None:
            if not summary.get("fusion", {}).get("started"): continue
        elif not s.get("handed_over"): continue
        else: handover.append(float(s["handover_t_s"]))
        truth = list(csv.DictReader(open(f"{sim}/truth.csv"))); tt = [float(r["t_s"]) for r in truth]
        rows = list(csv.DictReader(open(f"{d}/nav.csv"))); rt = [float(r["t_s"]) for r in rows]
        runs[k] = (truth, tt, rows, rt)
    n = len(runs)
    if n == 0:
        print(f"{flt}: no run handed over"); continue
    print(f"{flt}: {n} runs handed over, hand-over at {min(handover):.2f}-{max(handover):.2f} s" if handover else
          f"{flt}: {n} runs (no hand-over: tight coupling)")
    lo, hi = chi2_quantile(0.025, n) / n, chi2_quantile(0.975, n) / n
    lo3, hi3 = chi2_quantile(0.025, 3 * n) / n, chi2_quantile(0.975, 3 * n) / n
    print(f"  bands (95 %): mean z +-{1.96 / math.sqrt(n):.2f}; mean z^2 per axis [{lo:.2f}, {hi:.2f}]; "
          f"sum of 3 axes [{lo3:.2f}, {hi3:.2f}] (if uncorrelated)")
    print("  t_s   | mean z  pN    pE    pD    vN    vE    vD   | mean z^2 pN   pE   pD   vN   vE   vD  | pos sum vel sum | "
          "RMS err pos m  vel m/s | RMS sigma pos m vel m/s")
    for t in times:
        zs, es, ss = [], [], []
        for k, (truth, tt, rows, rt) in runs.items():
            r = z_at(truth, tt, rows, rt, t)
            if r: zs.append(r[0]); es.append(r[1]); ss.append(r[2])
        m = len(zs)
        if m == 0: continue
        mz = [sum(z[i] for z in zs) / m for i in range(6)]
        mz2 = [sum(z[i] ** 2 for z in zs) / m for i in range(6)]
        rms = lambda v, a, b: math.sqrt(sum(sum(x[i] ** 2 for i in range(a, b)) for x in v) / m)
        print(f"  {t:5.1f} | " + " ".join(f"{x:+5.2f}" for x in mz) + "  | " + " ".join(f"{x:4.2f}" for x in mz2) +
              f" | {sum(mz2[:3]):5.2f}  {sum(mz2[3:]):5.2f}  | {rms(es, 0, 3):6.3f} {rms(es, 3, 6):8.4f}    | "
              f"{rms(ss, 0, 3):6.3f} {rms(ss, 3, 6):8.4f}")
        rows_out.append([flt, t, m] + mz + mz2)
with open(f"{out}/consistency.csv", "w") as fh:
    w = csv.writer(fh)
    w.writerow(["filter", "t_s", "runs", "mz_pn", "mz_pe", "mz_pd", "mz_vn", "mz_ve", "mz_vd",
                "mz2_pn", "mz2_pe", "mz2_pd", "mz2_vn", "mz2_ve", "mz2_vd"])
    for r in rows_out: w.writerow([f"{x:.4f}" if isinstance(x, float) else x for x in r])
EOF
