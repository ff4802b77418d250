#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Snapshot (coarse-time) positioning Monte Carlo (issue 18): synthesises short snapshots with `ultratrack simulate`
# and solves each with `ultratrack snapshot` WITHOUT an approximate position, from an approximate time that is
# off by a uniform random error within +-TIME_ERROR s. Case classes: C/N0 45 and 35 dB-Hz x static and an aircraft
# at 250 m/s (level flight, random heading, 2-11 km) x 20 and 100 ms; CASES per class (default 7: 56 cases).
# Every case: a random place (latitude -60..70 deg), start time inside the ephemeris file's validity (shipped
# tests/data file: week 1823, TOW 511800-532200; --week/--tow-min/--tow-max for another), receiver clock bias
# (+-0.3 ms) and drift (+-0.5 ppm), sample format in turn i8 at 2.6 MHz, r2 (2-bit real) at 20 MHz with a 4.1 MHz
# IF, i16 at 4 MHz. Truth: the scenario's start position and time (the snapshot's first sample).
# Prints one row per case and the table per class: cases, fixes within 10 m (3-D), fixes flagged by the
# quality check (quality != pass, or no fix), wrong fixes (> 10 m) not flagged, median and 95th-percentile error,
# and the fixes within their own 95 % error bound (snapshot.json error_bound_3d_95_m).
#
#   benchmarks/snapshot_mc.sh [--cases 7] [--seed0 1] [--time-error 10] [--out DIR] [--ultratrack build/tools/ultratrack]
#       [--nav FILE --week W --tow-min A --tow-max B] [--keep] [--snapshot-args "..."] [--cn0 "45 35"]
#       (more options for every `snapshot`; levels). brdc0010.22n, where the [E] figures were measured:
#       --nav FILE --week 2190 --tow-min 519000 --tow-max 603000.
# Needs python3. CPU: a few seconds per case.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cases=7 seed0=1 time_error=10 out="" keep=0 snapshot_args="" levels="45 35"
ut="$here/../build/tools/ultratrack"
nav="$here/../tests/data/brdc3540_0000-0200.14n"; week=1823 tow_min=511800 tow_max=532200
while [[ $# -gt 0 ]]; do
  case "$1" in
    --cases) cases="$2"; shift 2 ;;
    --seed0) seed0="$2"; shift 2 ;;
    --time-error) time_error="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --ultratrack) ut="$2"; shift 2 ;;
    --nav|--brdc) nav="$2"; shift 2 ;;
    --week) week="$2"; shift 2 ;;
    --tow-min) tow_min="$2"; shift 2 ;;
    --tow-max) tow_max="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    --snapshot-args) snapshot_args="$2"; shift 2 ;;
    --cn0) levels="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
[[ -f "$nav" ]] || { echo "snapshot_mc.sh: no navigation file $nav (--nav FILE)" >&2; exit 2; }
[[ -x "$ut" ]] || { echo "snapshot_mc.sh: no ultratrack at $ut (--ultratrack)" >&2; exit 2; }
[[ -n "$out" ]] || out="$(mktemp -d /tmp/snapshot_mc.XXXXXX)"
mkdir -p "$out"
nav="$(cd "$(dirname "$nav")" && pwd)/$(basename "$nav")"

python3 - "$ut" "$nav" "$out" "$cases" "$seed0" "$time_error" "$keep" "$snapshot_args" "$levels" "$week" "$tow_min" "$tow_max" <<'EOF'
import json, math, os, random, shutil, statistics, subprocess, sys

ut, nav, out, cases, seed0, time_error, keep = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6]), sys.argv[7] == "1"
extra = sys.argv[8].split()
levels = [float(x) for x in sys.argv[9].split()]
week, tow_min, tow_max = int(sys.argv[10]), float(sys.argv[11]), float(sys.argv[12])

def ecef(lat, lon, h):
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    la, lo = math.radians(lat), math.radians(lon)
    n = a / math.sqrt(1 - e2 * math.sin(la) ** 2)
    return ((n + h) * math.cos(la) * math.cos(lo), (n + h) * math.cos(la) * math.sin(lo), (n * (1 - e2) + h) * math.sin(la))

formats = [("i8", 2.6e6, 0.0), ("r2", 20e6, 4.092e6), ("i16", 4e6, 0.0)]
rows = []
index = 0
for cn0 in levels:
    for motion in ("static", "250mps"):
        for ms in (20, 100):
            for k in range(cases):
                seed = seed0 + index
                rng = random.Random(seed)
                fmt_name, fs, if_hz = formats[index % len(formats)]
                index += 1
                lat, lon = rng.uniform(-60, 70), rng.uniform(-180, 180)
                h = rng.uniform(0, 500) if motion == "static" else rng.uniform(2000, 11000)
                tow = rng.uniform(tow_min, tow_max)
                err = rng.uniform(-time_error, time_error)
                case = os.path.join(out, f"case{seed:04d}")
                os.makedirs(case, exist_ok=True)
                scenario = f"""[signal]
sample_rate_hz = {fs}
if_hz = {if_hz}
format = "{fmt_name}"
duration_s = {ms / 1000 + 0.002}
cn0_dbhz = {cn0}
seed = {seed}
[time]
gps_week = {week}
tow_s = {tow:.6f}
[navigation]
rinex = "{nav}"
elevation_mask_deg = 5.0
[receiver]
llh_deg_m = [{lat:.9f}, {lon:.9f}, {h:.3f}]
clock_bias_m = {rng.uniform(-1e5, 1e5):.3f}
clock_drift_mps = {rng.uniform(-150, 150):.3f}
[atmosphere]
ionosphere = true
troposphere = true
"""
                if motion != "static":
                    with open(os.path.join(case, "segments.csv"), "w") as f:
                        f.write("duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n1.0,0,0,0,0\n")
                    scenario += f"""[trajectory]
file = "segments.csv"
speed_mps = 250.0
heading_deg = {rng.uniform(0, 360):.3f}
imu_rate_hz = 100.0
"""
                with open(os.path.join(case, "scenario.toml"), "w") as f:
                    f.write(scenario)
                sim = subprocess.run([ut, "simulate", "--scenario", os.path.join(case, "scenario.toml"), "--out", os.path.join(case, "sim")],
                                     capture_output=True, text=True)
                if sim.returncode != 0:
                    print(f"case {seed}: simulate failed: {sim.stderr.strip()}", file=sys.stderr)
                    continue
                approx = tow + err
                args = [ut, "snapshot", "--input", os.path.join(case, "sim", f"antenna0.{fmt_name}.bin"), "--format", fmt_name,
                        "--fs", str(fs), "--if", str(if_hz), "--nav", nav, "--time", f"{week}:{approx:.6f}", "--time-sigma-s", "10",
                        "--ms", str(ms), "--doppler-max", "8000", "--out", os.path.join(case, "snap")] + extra
                snap = subprocess.run(args, capture_output=True, text=True)
                result = {"seed": seed, "cn0": cn0, "motion": motion, "ms": ms, "format": fmt_name, "exit": snap.returncode,
                          "error_m": float("nan"), "quality": "none", "time_error_s": float("nan"), "used": 0, "bound_m": float("nan")}
                path = os.path.join(case, "snap", "snapshot.json")
                if os.path.exists(path):
                    j = json.load(open(path))
                    result["used"] = j.get("satellites_used", 0)
                    if j["valid"]:
                        truth = ecef(lat, lon, h)
                        result["error_m"] = math.dist(truth, j["ecef_m"])
                        result["quality"] = j["quality"]
                        result["bound_m"] = j["error_bound_3d_95_m"]
                        result["time_error_s"] = (approx + j["time_correction_s"]) - tow
                    else:
                        result["quality"] = "no fix"
                rows.append(result)
                print(f"{seed:5d} {cn0:4.0f} {motion:7s} {ms:4d} {fmt_name:4s} exit {snap.returncode} used {result['used']:2d} "
                      f"err {result['error_m']:10.2f} m (95 % bound {result['bound_m']:6.1f})  time err {result['time_error_s']*1e3:9.3f} ms  {result['quality']}", flush=True)
                if not keep:
                    shutil.rmtree(os.path.join(case, "sim"), ignore_errors=True)

with open(os.path.join(out, "cases.json"), "w") as f:
    json.dump(rows, f, indent=1)

def pct(values, p):
    v = sorted(values)
    if not v:
        return float("nan")
    return v[min(len(v) - 1, int(math.ceil(p * len(v))) - 1)]

print()
print(f"{'C/N0':>5} {'motion':>7} {'ms':>4} {'cases':>5} {'<=10 m':>7} {'rate':>6} {'flagged':>7} {'wrong unflagged':>15} {'median m':>9} {'p95 m':>9} {'in bound':>8}")
total = good = 0
for cn0 in levels:
    for motion in ("static", "250mps"):
        for ms in (20, 100):
            sel = [r for r in rows if r["cn0"] == cn0 and r["motion"] == motion and r["ms"] == ms]
            if not sel:
                continue
            ok = sum(1 for r in sel if r["error_m"] <= 10.0)
            flagged = sum(1 for r in sel if r["quality"] != "pass")
            wrong_unflagged = sum(1 for r in sel if r["quality"] == "pass" and not (r["error_m"] <= 10.0))
            errs = [r["error_m"] for r in sel if not math.isnan(r["error_m"])]
            in_bound = sum(1 for r in sel if r["error_m"] <= r["bound_m"])
            total += len(sel)
            good += ok
            print(f"{cn0:5.0f} {motion:>7} {ms:4d} {len(sel):5d} {ok:7d} {ok / len(sel):6.0%} {flagged:7d} {wrong_unflagged:15d} "
                  f"{statistics.median(errs) if errs else float('nan'):9.2f} {pct(errs, 0.95):9.2f} {in_bound:8d}")
print(f"all: {good} of {total} within 10 m ({good / max(total, 1):.1%})")
EOF
