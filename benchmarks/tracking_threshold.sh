#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Tracking threshold: the C/N0 at which 90 % of 60 s tracking runs keep lock (issue 3). For every C/N0 level it
# synthesises FILES static files (`ultratrack simulate`, the shipped tests/data ephemeris by default, different
# seeds and start times, every
# satellite above the horizon at that C/N0: each satellite of each file is one run), receives them hot
# (`--nav`, so ephemerides are known and nothing but tracking happens after acquisition), and classifies every
# satellite-run from tracking.csv:
#   kept lock     first locked (state phase-locked or bit-synced) within LOCK_DEADLINE_S of the file start, and
#                 from then on every tracking record of the PRN is locked, with no gap (a released channel), up
#                 to within 0.2 s of the end of the file;
#   lost          locked once, then a lost record, a gap or an unlocked record;
#   never locked  acquired (a channel got it) but not locked by LOCK_DEADLINE_S;
#   not acquired  no channel ever (an acquisition miss; reported, left out of the fraction).
# fraction kept = kept / (kept + lost + never locked) (the headline: pull-in included), and kept / (kept + lost)
# (lock kept once locked), each with its Wilson 68 % interval; a 90 % threshold is the lowest C/N0 above which
# the fraction stays >= 0.9, interpolated linearly between the bracketing levels (its bounds likewise from the
# interval curves). The report can be redone from runs.csv: --report-only DIR. The default protocol is also a
# campaign file: `ultratrack campaign run campaigns/tracking_threshold.toml --out DIR [--engine slurm]` (docs/usage.md).
#
# Acquisition is not what is measured: the receiver searches only the PRNs the file holds, +-4.5 kHz, with a
# long snapshot (10 ms coherent x 25: it finds every satellite of a 26 dB-Hz file); a lost satellite is not
# re-acquired (it has failed the run; re-acquisition searches would only cost time). The receiver's other
# settings are its defaults: --config-extra FILE appends [tracking] (or [pvt]) settings to the receive's
# configuration, --receive-args passes more flags (e.g. a later issue's tracking modes) to every receive.
# The loops are told the simulated front end's oscillator class (`receive --oscillator`), as a user who knows
# their front end sets it: the scenario's `[receiver] oscillator` (tcxo, ocxo), else ideal (the static files and
# scenarios without one have a perfect clock); --oscillator NAME tells them another (e.g. ideal on a TCXO file:
# the loops assuming a perfect clock).
#
#   benchmarks/tracking_threshold.sh [--levels "24 26 28 30 32"] [--files 4] [--duration 60] [--fs 2.6e6]
#       [--seed0 100] [--out DIR] [--ultratrack build/tools/ultratrack] [--receive-args "..."]
#       [--config-extra FILE] [--lock-deadline 5] [--nav FILE] [--keep] [--coupling scalar|vector]
#       [--strong-s T0 [--strong-cn0 45]] [--couplings "scalar vector ultra-tight"] [--filter ekf|ukf]
#       [--scenario FILE] [--reuse] [--week W --tow-shift S] [--oscillator tcxo|ocxo|ideal]
# The ephemeris: benchmarks/ephemeris_option.sh (--nav or --brdc FILE; the shipped file by default; the files start
# at tow 530400 + 90 k). Needs python3 (the report). CPU: about 15 s per file at
# 2.6 MHz on one core. Files are deleted after their receive unless --keep. --reuse: a file kept by an earlier
# --keep run in the same --out (same level, file number and options: the same seed and content) is received
# again instead of simulated (e.g. a further coupling on the same files); runs.csv and positions.csv are
# appended to, not restarted. A file and coupling received again (e.g. the same --out with a larger --files)
# replaces its earlier rows in runs.csv, positions.csv and nav_positions.csv instead of counting twice.
#
# The common loss-of-lock rule (pipelines/truth_lock_rule.hpp, `ultratrack compare --tracking`): beside each
# receiver's own detectors, every coupling's channels are judged the same way against the simulator's
# satellite_truth.csv (runs_truth.csv and the last table of the report), so that the thresholds compare.
#
# The step protocol (--strong-s T0 > 0): every file is T0 + DURATION s long, all satellites at --strong-cn0
# (45 dB-Hz) for the first T0 s, so that acquisition, bit and frame sync and a vector hand-over complete, then a
# [[cn0_step]] (sample-exact) to the level under test for DURATION s. A satellite-run is then
#   kept          locked (phase-locked or bit-synced) at the step (a locked record within 0.2 s before T0), and
#                 every record of the PRN from there on locked, with no gap, up to within 0.2 s of the end;
#   lost          locked at the step, then a non-locked record (coasting counts as not locked), a gap, or an
#                 early end;
#   not locked at the step (left out of the fractions, like not acquired: pull-in is not what is measured).
# --couplings runs every file through `receive --coupling X` for each X (the same files for every coupling);
# loose, tight and ultra-tight get --imu DIR/imu.csv --filter ekf or --filter F (needs --scenario with [trajectory]); a
# coupling that `receive` rejects is skipped with a message. Per coupling: the per-level table, the 90 %
# threshold with its 68 % range, and the 3-D position RMS of solution.csv against truth.csv over the weak part
# (fixes at and after T0, `ultratrack compare`): positions.csv, one row per file and coupling; for GNSS/INS
# couplings also the fused nav.csv over the weak part (3-D RMS and maximum): nav_positions.csv.
# --scenario FILE: the trajectory (and IMU) of an inertial scenario (e.g. scenarios/ultratight_circle.toml; its
# trajectory must last T0 + DURATION s) instead of the static receiver; [signal] duration_s, cn0_dbhz and seed
# are rewritten, relative paths made absolute.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
source "$root/benchmarks/ephemeris_option.sh"
levels="24 26 28 30 32"; files=4; duration=60; fs=2.6e6; seed0=100; out=/tmp/ultratrack_threshold
ultratrack=$root/build/tools/ultratrack; receive_args=""; keep=0; nav=$brdc
lock_deadline_s=5; extra_config=""; report_only=0; reuse=0
strong_s=0; strong_cn0=45; couplings=""; scenario=""; filter=ekf; oscillator=""
while [ $# -gt 0 ]; do
  case "$1" in
    --levels) levels=$2; shift 2 ;;
    --files) files=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --fs) fs=$2; shift 2 ;;
    --seed0) seed0=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --ultratrack) ultratrack=$2; shift 2 ;;
    --receive-args) receive_args=$2; shift 2 ;;
    --coupling) receive_args="$receive_args --coupling $2"; shift 2 ;;  # scalar (default) or vector (issue 7)
    --nav|--brdc) nav=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    --lock-deadline) lock_deadline_s=$2; shift 2 ;;
    --config-extra) extra_config=$(realpath "$2"); shift 2 ;;
    --strong-s) strong_s=$2; shift 2 ;;
    --strong-cn0) strong_cn0=$2; shift 2 ;;
    --couplings) couplings=$2; shift 2 ;;
    --filter) filter=$2; shift 2 ;;  # the GNSS/INS couplings' filter
    --scenario) scenario=$(realpath "$2"); shift 2 ;;
    --oscillator) oscillator=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    --reuse) reuse=1; keep=1; shift ;;
    --report-only) report_only=1; out=$2; shift 2 ;;
    -h|--help) sed -n '2,64p' "$0"; exit 0 ;;
    *) echo "tracking_threshold.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
if [ "$report_only" = 0 ] && [ ! -f "$nav" ]; then
  echo "tracking_threshold.sh: $nav not found (--nav FILE)"
  exit 0
fi
[ -x "$ultratrack" ] || { echo "tracking_threshold.sh: $ultratrack not built" >&2; exit 2; }
command -v python3 >/dev/null || { echo "tracking_threshold.sh: python3 is needed for the report" >&2; exit 2; }
[ "$report_only" = 1 ] || nav=$(realpath "$nav")
mkdir -p "$out"
out=$(realpath "$out")

# The simulated front end's oscillator class (see above) unless --oscillator says otherwise.
if [ -z "$oscillator" ]; then
  oscillator=ideal
  if [ -n "$scenario" ]; then
    oscillator=$(python3 - "$scenario" <<'PY'
import re, sys
section, found = "", "ideal"
for line in open(sys.argv[1]):
    m = re.match(r"\s*\[+([a-z_0-9]+)\]+", line)
    if m:
        section = m.group(1)
    v = re.match(r'\s*oscillator\s*=\s*"([a-z]+)"', line)
    if section == "receiver" and v:
        found = v.group(1)
print(found)
PY
)
  fi
fi

acq_config=$out/acquisition.toml
cat > "$acq_config" <<'TOML'
[receiver]
reacquisition_interval_s = 1000.0
[acquisition]
coherent_ms = 10
noncoherent = 25
doppler_max_hz = 4500.0
TOML
[ -z "$extra_config" ] || cat "$extra_config" >> "$acq_config"

runs=$out/runs.csv
positions=$out/positions.csv
file_s=$(python3 -c "print($strong_s + $duration)")
# The coupling list: "" (one pass, the classic mode: receive_args alone) or the named couplings.
[ -n "$couplings" ] || couplings="-"
if [ "$report_only" = 1 ]; then levels=""; elif [ "$reuse" = 0 ] || [ ! -f "$runs" ]; then
  echo "cn0_dbhz,file,prn,outcome,first_lock_s,lock_end_s,coupling" > "$runs"
  echo "cn0_dbhz,file,coupling,fixes,rms_3d_m" > "$positions"
  echo "cn0_dbhz,file,coupling,rows,nav_rms_3d_m,nav_max_3d_m" > "$out/nav_positions.csv"
  echo "cn0_dbhz,file,prn,outcome,reason,lost_s,max_code_error_chips,max_frequency_error_hz,records,coupling" \
    > "$out/runs_truth.csv"
fi
skipped=" "
for level in $levels; do
  for ((k = 0; k < files; ++k)); do
    seed=$((seed0 + k))
    tow=$((530400 + brdc_tow_shift + 90 * k))  # different nav-bit content and geometry per file, inside the fit
    name=cn0_${level}_file_${k}
    sim=$out/$name.sim
    reused=0
    if [ "$reuse" = 1 ] && [ -f "$sim/antenna0.i8.bin" ] && [ -f "$sim/summary.json" ]; then reused=1; else
      rm -rf "$sim"
    fi
    mkdir -p "$sim"
    file_cn0=$level
    [ "$strong_s" = 0 ] || file_cn0=$strong_cn0
    if [ -n "$scenario" ]; then
      python3 - "$scenario" "$file_s" "$file_cn0" "$seed" > "$sim.toml" <<'PY'
import os, re, sys
path, duration, cn0, seed = sys.argv[1:5]
folder = os.path.dirname(path)
section, out = "", []
for line in open(path):
    m = re.match(r"\s*\[+([a-z_0-9]+)\]+", line)
    if m:
        section = m.group(1)
    key = re.match(r"\s*([a-z_0-9]+)\s*=", line)
    if section == "signal" and key and key.group(1) in ("duration_s", "cn0_dbhz", "seed"):
        continue
    p = re.match(r'(\s*[a-z_0-9]+\s*=\s*)"([^"]+)"(.*)', line)
    if p and not os.path.isabs(p.group(2)) and os.path.exists(os.path.join(folder, p.group(2))):
        line = f'{p.group(1)}"{os.path.join(folder, p.group(2))}"{p.group(3)}\n'
    out.append(line)
    if m and section == "signal":
        out.append(f"duration_s = {duration}\ncn0_dbhz = {cn0}\nseed = {seed}\n")
print("".join(out))
PY
    else
      cat > "$sim.toml" <<TOML
[signal]
sample_rate_hz = $fs
format = "i8"
duration_s = $file_s
cn0_dbhz = $file_cn0
seed = $seed
[time]
gps_week = $(brdc_week_or 1823)
tow_s = $tow.0
[navigation]
rinex = "$nav"
elevation_mask_deg = 0.0
include_unhealthy = true
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
[atmosphere]
ionosphere = true
troposphere = false
TOML
    fi
    [ "$strong_s" = 0 ] || printf '\n[[cn0_step]]\nstart_s = %s\ncn0_dbhz = %s\n' "$strong_s" "$level" >> "$sim.toml"
    [ "$reused" = 1 ] || nice -n 5 "$ultratrack" simulate --scenario "$sim.toml" --out "$sim" --quiet > /dev/null
    sim_fs=$(python3 -c "import json; print(json.load(open('$sim/summary.json'))['sample_rate_hz'])")
    prns=$(tail -n +2 "$sim/satellites.csv" | cut -d, -f1 | paste -sd, -)
    config_args=(--config "$acq_config")
    # Issue 7's protocol compares positions with the truth: the receiver's troposphere model as simulated.
    if [ "$strong_s" != 0 ] && grep -A3 '^\[atmosphere\]' "$sim/scenario.toml" | grep -q 'troposphere = false'; then
      config_args+=(--troposphere off)
    fi
    for coupling in $couplings; do
      case "$skipped" in *" $coupling "*) continue ;; esac
      coupling_args=()
      label=""
      if [ "$coupling" != "-" ]; then
        label=$coupling
        coupling_args=(--coupling "$coupling")
        case "$coupling" in
          loose|tight|ultra-tight)
            if [ ! -f "$sim/imu.csv" ]; then
              echo "tracking_threshold: coupling $coupling needs an IMU (--scenario with [trajectory]): skipped" >&2
              skipped="$skipped$coupling "; continue
            fi
            coupling_args+=(--imu "$sim/imu.csv" --filter "$filter") ;;
        esac
      fi
      rx=$out/$name${label:+.$label}.rx
      if [ "$reuse" = 1 ]; then
        # --reuse: drop this file's and coupling's earlier rows (a second receive would count it twice).
        python3 - "$name" "$label" "$runs" "$positions" "$out/nav_positions.csv" "$out/runs_truth.csv" <<'PY'
import os, sys
name, label = sys.argv[1:3]
# runs.csv: coupling last (6); positions, nav_positions: third (2); runs_truth.csv: last (9)
for path, coupling_col in zip(sys.argv[3:], (6, 2, 2, 9)):
    if not os.path.exists(path):
        continue
    lines = open(path).read().splitlines()
    keep = [lines[0]] + [l for l in lines[1:] if not (l.split(",")[1] == name and l.split(",")[coupling_col] == label)]
    if len(keep) != len(lines):
        open(path, "w").write("\n".join(keep) + "\n")
PY
      fi
      rm -rf "$rx"
      rc=0
      # shellcheck disable=SC2086
      nice -n 5 "$ultratrack" receive --input "$sim/antenna0.i8.bin" --format i8 --fs "$sim_fs" --nav "$nav" \
        --prn "$prns" --out "$rx" --quiet --oscillator "$oscillator" "${config_args[@]}" $receive_args \
        "${coupling_args[@]}" > "$rx.log" 2>&1 || rc=$?
      if [ "$rc" != 0 ] && [ ! -f "$rx/tracking.csv" ] && grep -q -- "--coupling\|coupling" "$rx.log"; then
        echo "tracking_threshold: receive rejects --coupling $coupling ($(tail -n 1 "$rx.log")): skipped" >&2
        skipped="$skipped$coupling "; continue
      fi
      python3 - "$sim/satellites.csv" "$rx/tracking.csv" "$file_s" "$lock_deadline_s" "$level" "$name" "$strong_s" \
        "$label" >> "$runs" <<'PY'
import csv, sys
sats_file, tracking_file, duration, deadline, level, name, strong_s, coupling = sys.argv[1:9]
duration, deadline, strong_s = float(duration), float(deadline), float(strong_s)
prns = [int(r["prn"]) for r in csv.DictReader(open(sats_file))]
rows = {}
try:
    for r in csv.DictReader(open(tracking_file)):
        rows.setdefault(int(r["prn"]), []).append((float(r["time_s"]), r["state"]))
except FileNotFoundError:
    pass
locked_states = ("phase-locked", "bit-synced")
for prn in prns:
    recs = rows.get(prn, [])
    outcome, first, end = "not_acquired", "", ""
    if recs and strong_s > 0:
        # Issue 7: locked at the step, then locked through the weak part.
        outcome = "not_locked_at_step"
        before = [i for i, (t, s) in enumerate(recs) if strong_s - 0.2 <= t <= strong_s]
        if before and recs[before[-1]][1] in locked_states:
            i0 = before[-1]
            first = f"{recs[i0][0]:.3f}"
            outcome, end_t, previous = "kept", recs[-1][0], recs[i0][0]
            for t, s in recs[i0:]:
                if s not in locked_states or t - previous > 0.2:
                    outcome, end_t = "lost", previous
                    break
                previous = t
            if outcome == "kept" and end_t < duration - 0.2:
                outcome = "lost"
            end = f"{end_t:.3f}"
    elif recs:
        outcome = "never_locked"
        lock = next((i for i, (t, s) in enumerate(recs) if s in locked_states), None)
        if lock is not None and recs[lock][0] <= deadline:
            first = f"{recs[lock][0]:.3f}"
            outcome, end_t = "kept", recs[-1][0]
            previous = recs[lock][0]
            for t, s in recs[lock:]:
                if s not in locked_states or t - previous > 0.2:  # records come every 20 ms
                    outcome, end_t = "lost", previous
                    break
                previous = t
            if outcome == "kept" and end_t < duration - 0.2:
                outcome = "lost"
            end = f"{end_t:.3f}"
    print(f"{level},{name},{prn},{outcome},{first},{end},{coupling}")
PY
      # The common rule (pipelines/truth_lock_rule.hpp): every coupling's channels against the simulator's
      # satellite_truth.csv, from the step (or the lock deadline) to the end: code within 0.5 chip, each 1 s mean
      # carrier frequency error within 2.5 Hz, no gap. Lines of runs_truth.csv; files simulated before the
      # simulator wrote satellite_truth.csv are left out.
      if [ -f "$sim/satellite_truth.csv" ] && [ -f "$rx/tracking.csv" ]; then
        [ -f "$out/runs_truth.csv" ] || echo "cn0_dbhz,file,prn,outcome,reason,lost_s,max_code_error_chips,max_frequency_error_hz,records,coupling" > "$out/runs_truth.csv"
        from_s=$strong_s; [ "$strong_s" != 0 ] || from_s=$lock_deadline_s
        "$ultratrack" compare --tracking "$rx/tracking.csv" --satellite-truth "$sim/satellite_truth.csv" \
          --from "$from_s" --end "$file_s" | tail -n +2 | sed "s/^/$level,$name,/; s/\$/,$label/" >> "$out/runs_truth.csv"
      fi
      # 3-D position RMS over the weak part: fixes at and after T0 (receiver time since the first sample).
      fixes=0; rms=""
      if [ -f "$rx/solution.csv" ]; then
        python3 - "$rx/solution.csv" "$sim/truth.csv" "$strong_s" > "$rx/solution_weak.csv" <<'PY'
import csv, sys
sol, truth, t0 = sys.argv[1], sys.argv[2], float(sys.argv[3])
tow0 = float(next(csv.DictReader(open(truth)))["tow_s"])
lines = open(sol).read().splitlines()
header = lines[0].split(",")
col = header.index("tow_s")
print(lines[0])
for line in lines[1:]:
    d = float(line.split(",")[col]) - tow0
    d -= 604800 * round(d / 604800)
    if d >= t0 - 1e-3:
        print(line)
PY
        fixes=$(($(wc -l < "$rx/solution_weak.csv") - 1))
        if [ "$fixes" -gt 0 ]; then
          rms=$("$ultratrack" compare --solution "$rx/solution_weak.csv" --truth "$sim/truth.csv" --json 2>/dev/null |
                python3 -c "import json, sys; print(f\"{json.load(sys.stdin)['rms_3d_m']:.3f}\")" 2>/dev/null || true)
        fi
      fi
      echo "$level,$name,$label,$fixes,$rms" >> "$positions"
      # GNSS/INS couplings: the fused position (nav.csv, IMU time = seconds since the file's first sample) over the
      # weak part against truth.csv, in nav_positions.csv.
      if [ -f "$rx/nav.csv" ]; then
        [ -f "$out/nav_positions.csv" ] || echo "cn0_dbhz,file,coupling,rows,nav_rms_3d_m,nav_max_3d_m" > "$out/nav_positions.csv"
        python3 - "$rx/nav.csv" "$sim/truth.csv" "$strong_s" "$level" "$name" "$label" >> "$out/nav_positions.csv" <<'PY'
import bisect, csv, math, sys
nav, truth, t0, level, name, label = sys.argv[1], sys.argv[2], float(sys.argv[3]), *sys.argv[4:7]
def ecef(lat, lon, h):
    a = 6378137.0; f = 1 / 298.257223563; e2 = f * (2 - f)
    la, lo = math.radians(lat), math.radians(lon); n = a / math.sqrt(1 - e2 * math.sin(la) ** 2)
    return ((n + h) * math.cos(la) * math.cos(lo), (n + h) * math.cos(la) * math.sin(lo), (n * (1 - e2) + h) * math.sin(la))
rows = list(csv.DictReader(open(truth)))
tt = [float(r["t_s"]) for r in rows]
pp = [(float(r["ecef_x_m"]), float(r["ecef_y_m"]), float(r["ecef_z_m"])) for r in rows]
s2, n, worst = 0.0, 0, 0.0
for r in csv.DictReader(open(nav)):
    t = float(r["t_s"])
    i = bisect.bisect_left(tt, t)
    if t < t0 or i <= 0 or i >= len(tt): continue
    w = (t - tt[i - 1]) / (tt[i] - tt[i - 1])
    q = ecef(float(r["lat_deg"]), float(r["lon_deg"]), float(r["height_m"]))
    e2 = sum((pp[i - 1][k] + w * (pp[i][k] - pp[i - 1][k]) - q[k]) ** 2 for k in range(3))
    s2 += e2; n += 1; worst = max(worst, math.sqrt(e2))
print(f"{level},{name},{label},{n},{math.sqrt(s2 / n) if n else float('nan'):.3f},{worst:.3f}")
PY
      fi
      echo "tracking_threshold: $name${label:+ $label}: $(grep ",$name,.*,$label\$" "$runs" | grep -c .) runs," \
        "$(grep ",$name,.*,$label\$" "$runs" | grep -c ',kept,') kept, weak-part fixes $fixes, 3-D RMS ${rms:--} m" >&2
    done
    [ "$keep" = 1 ] || rm -f "$sim/antenna0.i8.bin"
  done
done

python3 - "$runs" "$out/positions.csv" <<'PY'
import csv, math, os, sys
all_runs = list(csv.DictReader(open(sys.argv[1])))
positions = list(csv.DictReader(open(sys.argv[2]))) if os.path.exists(sys.argv[2]) else []
nav_file = os.path.join(os.path.dirname(sys.argv[2]), "nav_positions.csv")
nav_positions = list(csv.DictReader(open(nav_file))) if os.path.exists(nav_file) else []
def wilson(k, n, z=1.0):
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))
def crossing(values):
    # lowest C/N0 above which the curve stays >= 0.9, interpolated between the bracketing levels
    pts = [(L, v) for L, v in values]
    above = [i for i in range(len(pts)) if all(v >= 0.9 for _, v in pts[i:])]
    if not above:
        return None
    i = above[0]
    if i == 0:
        return f"<= {pts[0][0]:.1f}"
    (L0, v0), (L1, v1) = pts[i - 1], pts[i]
    return f"{L0 + (0.9 - v0) * (L1 - L0) / (v1 - v0):.2f}"
step_mode = any(r["outcome"] == "not_locked_at_step" for r in all_runs) or any(r.get("coupling") for r in all_runs)
for coupling in sorted({r.get("coupling") or "" for r in all_runs}):
    runs = [r for r in all_runs if (r.get("coupling") or "") == coupling]
    if coupling:
        print(f"== coupling {coupling}")
    levels = sorted({float(r["cn0_dbhz"]) for r in runs})
    table, table_locked = [], []
    print("cn0_dbhz  runs  kept  lost  never_locked  not_acquired  fraction_kept  wilson68        kept_of_locked  wilson68"
          + ("        not_locked_at_step  weak_fixes  rms_3d_m(per file)" if step_mode else ""))
    for L in levels:
        rs = [r for r in runs if float(r["cn0_dbhz"]) == L]
        count = {o: sum(r["outcome"] == o for r in rs) for o in ("kept", "lost", "never_locked", "not_acquired", "not_locked_at_step")}
        n = count["kept"] + count["lost"] + count["never_locked"]
        f = count["kept"] / n if n else float("nan")
        lo, hi = wilson(count["kept"], n)
        table.append((L, f, lo, hi))
        m = count["kept"] + count["lost"]
        g = count["kept"] / m if m else 0.0
        glo, ghi = wilson(count["kept"], m)
        table_locked.append((L, g, glo, ghi))
        line = (f"{L:8.1f}  {len(rs):4d}  {count['kept']:4d}  {count['lost']:4d}  {count['never_locked']:12d}  "
                f"{count['not_acquired']:12d}  {f:13.3f}  [{lo:.3f}, {hi:.3f}]  {g:14.3f}  [{glo:.3f}, {ghi:.3f}]")
        if step_mode:
            ps = [p for p in positions if float(p["cn0_dbhz"]) == L and (p.get("coupling") or "") == coupling]
            fixes = sum(int(p["fixes"]) for p in ps)
            rms = " ".join(p["rms_3d_m"] or "-" for p in ps)
            line += f"  {count['not_locked_at_step']:18d}  {fixes:10d}  {rms}"
            navs = [p for p in nav_positions if float(p["cn0_dbhz"]) == L and (p.get("coupling") or "") == coupling]
            if navs:
                line += "  nav.csv " + " ".join(p["nav_rms_3d_m"] for p in navs) + " m"
        print(line)
    for label, t in (("of acquired satellites (pull-in included)", table), ("of locked satellites (lock kept)", table_locked)):
        if step_mode and label.startswith("of acquired"):
            continue  # in the step protocol both fractions are kept / (kept + lost)
        print(f"90 % threshold, {label}: {crossing([(L, f) for L, f, _, _ in t])} dB-Hz; from the 68 % intervals: "
              f"{crossing([(L, hi) for L, _, _, hi in t])} .. {crossing([(L, lo) for L, _, lo, _ in t])}")
# The common rule: the same truth-based judgement for every coupling (runs_truth.csv).
truth_file = os.path.join(os.path.dirname(sys.argv[2]), "runs_truth.csv")
truth_runs = list(csv.DictReader(open(truth_file))) if os.path.exists(truth_file) else []
if truth_runs:
    print("== common loss-of-lock rule (simulator truth: code <= 0.5 chip, 1 s mean frequency error <= 2.5 Hz, no gap)")
    print("coupling        cn0_dbhz  runs  kept  lost(code/frequency/gap/end)  not_tracked  kept_of_tracked  wilson68")
for coupling in sorted({r["coupling"] for r in truth_runs}):
    runs = [r for r in truth_runs if r["coupling"] == coupling]
    table = []
    for L in sorted({float(r["cn0_dbhz"]) for r in runs}):
        rs = [r for r in runs if float(r["cn0_dbhz"]) == L]
        kept = sum(r["outcome"] == "kept" for r in rs)
        lost = [r["reason"] for r in rs if r["outcome"] == "lost"]
        not_tracked = sum(r["outcome"] == "not_tracked" for r in rs)
        tracked = kept + len(lost)  # not_tracked left out, as not_acquired above
        f = kept / tracked if tracked else float("nan")
        lo, hi = wilson(kept, tracked)
        table.append((L, f, lo, hi))
        why = "/".join(str(lost.count(k)) for k in ("code", "frequency", "gap", "end"))
        print(f"{coupling or '-':14s}  {L:8.1f}  {len(rs):4d}  {kept:4d}  {len(lost):4d} ({why:>17s})  {not_tracked:11d}  "
              f"{f:15.3f}  [{lo:.3f}, {hi:.3f}]")
    above = f"above {table[-1][0]:.1f}"  # the curve never stays >= 0.9 up to the highest level run
    print(f"{coupling or '-'}: 90 % threshold by the common rule: {crossing([(L, f) for L, f, _, _ in table]) or above} "
          f"dB-Hz; from the 68 % intervals: {crossing([(L, hi) for L, _, _, hi in table]) or above} .. "
          f"{crossing([(L, lo) for L, _, lo, _ in table]) or above}")
PY
