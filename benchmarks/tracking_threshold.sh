#!/usr/bin/env bash
# Tracking threshold: the C/N0 at which 90 % of 60 s tracking runs keep lock (issue 3). For every C/N0 level it
# synthesises FILES static files (`ultratrack simulate`, brdc0010.22n, different seeds and start times, every
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
# interval curves). The report can be redone from runs.csv: --report-only DIR.
#
# Acquisition is not what is measured: the receiver searches only the PRNs the file holds, +-4.5 kHz, with a
# long snapshot (10 ms coherent x 25: it finds every satellite of a 26 dB-Hz file); a lost satellite is not
# re-acquired (it has failed the run; re-acquisition searches would only cost time). The receiver's other
# settings are its defaults: --config-extra FILE appends [tracking] (or [pvt]) settings to the receive's
# configuration, --receive-args passes more flags (e.g. a later issue's tracking modes) to every receive.
#
#   benchmarks/tracking_threshold.sh [--levels "24 26 28 30 32"] [--files 4] [--duration 60] [--fs 2.6e6]
#       [--seed0 100] [--out DIR] [--ultratrack build/tools/ultratrack] [--receive-args "..."]
#       [--config-extra FILE] [--lock-deadline 5] [--nav FILE] [--keep] [--coupling scalar|vector]
# Needs ../shared/data/brdc0010.22n (or --nav FILE) and python3 (the report). CPU: about 15 s per file at
# 2.6 MHz on one core. Files are deleted after their receive unless --keep.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
levels="24 26 28 30 32"; files=4; duration=60; fs=2.6e6; seed0=100; out=/tmp/ultratrack_threshold
ultratrack=$root/build/tools/ultratrack; receive_args=""; keep=0; nav=$root/../shared/data/brdc0010.22n
lock_deadline_s=5; extra_config=""; report_only=0
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
    --nav) nav=$2; shift 2 ;;
    --lock-deadline) lock_deadline_s=$2; shift 2 ;;
    --config-extra) extra_config=$(realpath "$2"); shift 2 ;;
    --keep) keep=1; shift ;;
    --report-only) report_only=1; out=$2; shift 2 ;;
    -h|--help) sed -n '2,30p' "$0"; exit 0 ;;
    *) echo "tracking_threshold.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
if [ "$report_only" = 0 ] && [ ! -f "$nav" ]; then
  echo "tracking_threshold.sh: $nav not found (../shared/data/brdc0010.22n): skipped"
  exit 0
fi
[ -x "$ultratrack" ] || { echo "tracking_threshold.sh: $ultratrack not built" >&2; exit 2; }
command -v python3 >/dev/null || { echo "tracking_threshold.sh: python3 is needed for the report" >&2; exit 2; }
[ "$report_only" = 1 ] || nav=$(realpath "$nav")
mkdir -p "$out"
out=$(realpath "$out")

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
if [ "$report_only" = 1 ]; then levels=""; else echo "cn0_dbhz,file,prn,outcome,first_lock_s,lock_end_s" > "$runs"; fi
for level in $levels; do
  for ((k = 0; k < files; ++k)); do
    seed=$((seed0 + k))
    tow=$((518400 + 90 * k))  # different nav-bit content and geometry per file, inside the ephemerides' fit
    name=cn0_${level}_file_${k}
    sim=$out/$name.sim; rx=$out/$name.rx
    rm -rf "$sim" "$rx"
    mkdir -p "$sim"
    cat > "$sim.toml" <<TOML
[signal]
sample_rate_hz = $fs
format = "i8"
duration_s = $duration
cn0_dbhz = $level
seed = $seed
[time]
gps_week = 2190
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
    nice -n 5 "$ultratrack" simulate --scenario "$sim.toml" --out "$sim" --quiet > /dev/null
    prns=$(tail -n +2 "$sim/satellites.csv" | cut -d, -f1 | paste -sd, -)
    config_args=(--config "$acq_config")
    # shellcheck disable=SC2086
    nice -n 5 "$ultratrack" receive --input "$sim/antenna0.i8.bin" --format i8 --fs "$fs" --nav "$nav" \
      --prn "$prns" --out "$rx" --quiet "${config_args[@]}" $receive_args > "$rx.log" 2>&1 || true
    python3 - "$sim/satellites.csv" "$rx/tracking.csv" "$duration" "$lock_deadline_s" "$level" "$name" >> "$runs" <<'PY'
import csv, sys
sats_file, tracking_file, duration, deadline, level, name = sys.argv[1:7]
duration, deadline = float(duration), float(deadline)
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
    if recs:
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
    print(f"{level},{name},{prn},{outcome},{first},{end}")
PY
    echo "tracking_threshold: $name: $(grep -c ",$name," "$runs") runs, $(grep ",$name," "$runs" | grep -c ',kept,') kept" >&2
    [ "$keep" = 1 ] || rm -f "$sim/antenna0.i8.bin"
  done
done

python3 - "$runs" <<'PY'
import csv, math, sys
runs = list(csv.DictReader(open(sys.argv[1])))
levels = sorted({float(r["cn0_dbhz"]) for r in runs})
def wilson(k, n, z=1.0):
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))
table, table_locked = [], []
print("cn0_dbhz  runs  kept  lost  never_locked  not_acquired  fraction_kept  wilson68        kept_of_locked  wilson68")
for L in levels:
    rs = [r for r in runs if float(r["cn0_dbhz"]) == L]
    count = {o: sum(r["outcome"] == o for r in rs) for o in ("kept", "lost", "never_locked", "not_acquired")}
    n = count["kept"] + count["lost"] + count["never_locked"]
    f = count["kept"] / n if n else float("nan")
    lo, hi = wilson(count["kept"], n)
    table.append((L, f, lo, hi))
    m = count["kept"] + count["lost"]
    g = count["kept"] / m if m else 0.0
    glo, ghi = wilson(count["kept"], m)
    table_locked.append((L, g, glo, ghi))
    print(f"{L:8.1f}  {len(rs):4d}  {count['kept']:4d}  {count['lost']:4d}  {count['never_locked']:12d}  "
          f"{count['not_acquired']:12d}  {f:13.3f}  [{lo:.3f}, {hi:.3f}]  {g:14.3f}  [{glo:.3f}, {ghi:.3f}]")
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
for label, t in (("of acquired satellites (pull-in included)", table), ("of locked satellites (lock kept)", table_locked)):
    print(f"90 % threshold, {label}: {crossing([(L, f) for L, f, _, _ in t])} dB-Hz; from the 68 % intervals: "
          f"{crossing([(L, hi) for L, _, _, hi in t])} .. {crossing([(L, lo) for L, _, lo, _ in t])}")
PY
