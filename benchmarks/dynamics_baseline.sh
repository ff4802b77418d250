#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Dynamics and blockage test bed (issue 7): runs the receiver on scenarios/ultratight_*.toml (one trajectory
# drives the IF samples, the IMU data and the truth) at several C/N0 levels and tabulates, per scenario and level:
#   sats        satellites in the file (satellites.csv)
#   lost        PRNs that were locked (phase-locked or bit-synced) and later not, with the time of the first loss
#               (with a blockage, lock is checked before it and from the first lock after the return: the
#               gap's own loss is expected and the re-lock is relock_s)
#   never       PRNs never locked
#   losses      lock losses of all channels together (summary.json per_satellite losses; the tunnel's included)
#   pos_rms_3d  3-D position RMS of solution.csv against truth.csv (`ultratrack compare`), first 5 s skipped
#   fixes       fixes in solution.csv; last_fix_s the time of the last one (s since the file start)
#   tracked_frac  the satellites' summed tracked_s (summary.json) over sats x duration
#   fixes_gap   fixes inside the blockage window (tunnel only)
#   relock_s    seconds from the signal's return until every PRN locked before the tunnel is locked again
#               (tunnel only; "never" when one does not re-lock before the end)
#   refix_s     seconds from the signal's return to the first fix after it (tunnel only)
#   nav_rms_3d_m  3-D position RMS of nav.csv (GNSS/INS couplings: the fused solution) against truth.csv from
#               its first row + 1 s ("" without nav.csv)
#   wall_s, cpu_s  the receive's wall time and CPU time (user + sys)
# In --receive-args, {sim} stands for the simulation folder (e.g. "--imu {sim}/imu.csv --coupling ultra-tight").
# Hot start: --nav is the scenario's RINEX (ephemerides known). Receiver settings are its defaults (scalar loops,
# default bandwidths) plus --receive-args (e.g. "--coupling vector") and --config FILE for receive.
#
#   benchmarks/dynamics_baseline.sh [--scenarios "straight circle s spiral 10g_turn tunnel"] [--levels "45 35"]
#       [--duration S (cap the signal duration)] [--out DIR] [--ultratrack build/tools/ultratrack]
#       [--receive-args "..."] [--keep] [--report-only DIR (re-analyse the kept folders of a run)]
#       [--brdc FILE --week W --tow-shift S (benchmarks/ephemeris_option.sh; the shipped file by default)]
# CPU: simulate + receive, roughly 0.5-1 s of CPU per second of signal on one core at 2.6 MHz. Sample files are
# deleted after their receive unless --keep (2.6 MHz i8 = 5.2 MB/s).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
source "$root/benchmarks/ephemeris_option.sh"
scenarios="straight circle s spiral 10g_turn tunnel"; levels="45 35"; duration=""; out=/tmp/ultratrack_dynamics
ultratrack=$root/build/tools/ultratrack; receive_args=""; keep=0; report_only=0
while [ $# -gt 0 ]; do
  case "$1" in
    --scenarios) scenarios=$2; shift 2 ;;
    --levels) levels=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --ultratrack) ultratrack=$2; shift 2 ;;
    --receive-args) receive_args=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    --brdc|--nav) brdc=$2; shift 2 ;;
    --week) brdc_week=$2; shift 2 ;;
    --tow-shift) brdc_tow_shift=$2; shift 2 ;;
    --report-only) report_only=1; out=$2; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "dynamics_baseline.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
nav=$(realpath -m "$brdc")
if [ "$report_only" = 0 ] && [ ! -f "$nav" ]; then
  echo "dynamics_baseline.sh: $nav not found (--brdc FILE)" >&2; exit 2
fi
[ -x "$ultratrack" ] || { echo "dynamics_baseline.sh: $ultratrack not built" >&2; exit 2; }
mkdir -p "$out"; out=$(realpath "$out")
results=$out/results.csv
if [ "$report_only" = 1 ]; then rm -f "$results"; fi
[ -f "$results" ] || echo "scenario,cn0_dbhz,sats,lost,never,losses,pos_rms_3d_m,fixes,last_fix_s,tracked_frac,fixes_gap,relock_s,refix_s,nav_rms_3d_m,wall_s,cpu_s" > "$results"

analyse() {  # sim rx scenario level: one results row
  local sim=$1 rx=$2 sc=$3 level=$4 rms
  rms=$("$ultratrack" compare --solution "$rx/solution.csv" --truth "$sim/truth.csv" --skip 5 --json 2>/dev/null \
        | python3 -c 'import json,sys; d=json.load(sys.stdin); print("%.2f" % d["rms_3d_m"])' \
        || echo nan)
  python3 - "$sim" "$rx" "$sc" "$level" "$rms" <<'PY'
import csv, os, sys
sim, rx, sc, level, rms = sys.argv[1:6]
sats = [int(r["prn"]) for r in csv.DictReader(open(f"{sim}/satellites.csv"))]
truth = list(csv.DictReader(open(f"{sim}/truth.csv")))
tow0 = float(truth[0]["tow_s"]); t_end = float(truth[-1]["t_s"])
gap = None
ev = f"{sim}/antenna_events.csv"
if os.path.exists(ev):
  for r in csv.DictReader(open(ev)):
      if r["kind"] == "blockage":
          gap = (float(r["start_s"]), float(r["end_s"]))
recs = {}
if os.path.exists(f"{rx}/tracking.csv"):
  for r in csv.DictReader(open(f"{rx}/tracking.csv")):
      recs.setdefault(int(r["prn"]), []).append((float(r["time_s"]), r["state"] in ("phase-locked", "bit-synced")))
lost, never, relock = [], [], []
for prn in sats:
  rs = recs.get(prn, [])
  first = next((t for t, ok in rs if ok), None)
  if first is None:
      never.append(str(prn)); continue
  # continuity of lock from the first lock; with a blockage, checked separately before it and from the
  # first lock after the signal's return (the gap itself and the re-lock are measured by relock_s)
  parts = [(first, t_end)]
  if gap:
      after = next((t for t, ok in rs if ok and t >= gap[1]), None)
      parts = [(first, gap[0] - 0.5)] + ([(after, t_end)] if after is not None else [])
      if first >= gap[0]: parts = [(first, t_end)]
  loss = None
  for a, b in parts:
      prev = a
      for t, ok in rs:
          if t < a or t > b: continue
          if not ok or t - prev > 0.2:
              loss = prev; break
          prev = t
      if loss is None and prev < b - 0.5: loss = prev
      if loss is not None: break
  if gap and first < gap[0]:
      back = next((t for t, ok in rs if ok and t >= gap[1]), None)
      relock.append(None if back is None else back - gap[1])
  if loss is not None:
      lost.append(f"{prn}@{loss:.1f}")
fixes = fixes_gap = 0
last_fix = float("nan")
refix = None
if os.path.exists(f"{rx}/solution.csv"):
  for r in csv.DictReader(open(f"{rx}/solution.csv")):
      fixes += 1
      t = float(r["tow_s"]) - tow0
      last_fix = t
      if gap and t >= gap[1] and refix is None: refix = t - gap[1]
      if gap and gap[0] <= t < gap[1]: fixes_gap += 1
frac, losses = float("nan"), ""
if os.path.exists(f"{rx}/summary.json"):
  import json
  per = json.load(open(f"{rx}/summary.json")).get("per_satellite", [])
  frac = sum(p["tracked_s"] for p in per if p["prn"] in sats) / (len(sats) * t_end) if sats else frac
  losses = sum(p["losses"] for p in per)
nav_rms = ""
if os.path.exists(f"{rx}/nav.csv"):
  import bisect, math
  def ecef(lat, lon, h):
      a = 6378137.0; f = 1 / 298.257223563; e2 = f * (2 - f)
      la, lo = math.radians(lat), math.radians(lon); n = a / math.sqrt(1 - e2 * math.sin(la) ** 2)
      return ((n + h) * math.cos(la) * math.cos(lo), (n + h) * math.cos(la) * math.sin(lo), (n * (1 - e2) + h) * math.sin(la))
  tt = [float(r["t_s"]) for r in truth]
  pp = [(float(r["ecef_x_m"]), float(r["ecef_y_m"]), float(r["ecef_z_m"])) for r in truth]
  s2, n, t_first = 0.0, 0, None
  for r in csv.DictReader(open(f"{rx}/nav.csv")):
      t = float(r["t_s"]); t_first = t if t_first is None else t_first
      i = bisect.bisect_left(tt, t)
      if t < t_first + 1.0 or i <= 0 or i >= len(tt): continue
      w = (t - tt[i - 1]) / (tt[i] - tt[i - 1])
      q = ecef(float(r["lat_deg"]), float(r["lon_deg"]), float(r["height_m"]))
      s2 += sum((pp[i - 1][k] + w * (pp[i][k] - pp[i - 1][k]) - q[k]) ** 2 for k in range(3)); n += 1
  nav_rms = f"{math.sqrt(s2 / n):.2f}" if n else "nan"
timing = open(f"{rx}.time").read().split("\n") if os.path.exists(f"{rx}.time") else []
timing = next((l.split() for l in reversed(timing) if len(l.split()) == 3), ["", "", ""])  # after "Command exited..."

rl = "" if not gap else ("never" if (not relock or None in relock) else f"{max(relock):.2f}")
print(f"{sc},{level},{len(sats)},{' '.join(lost) or '-'},{' '.join(never) or '-'},{losses},{rms},{fixes},{last_fix:.1f},{frac:.2f},"
    f"{fixes_gap if gap else ''},{rl},"
    f"{'' if not gap else ('never' if refix is None else f'{refix:.1f}')},{nav_rms},{timing[0]},"
    f"{'' if not timing[1] else f'{float(timing[1]) + float(timing[2]):.2f}'}")
PY
}

for sc in $( [ "$report_only" = 1 ] || echo $scenarios ); do
  src=$root/scenarios/ultratight_$sc.toml
  [ -f "$src" ] || { echo "dynamics_baseline.sh: no $src" >&2; exit 2; }
  for level in $levels; do
    name=${sc}_cn0_${level}; sim=$out/$name.sim; rx=$out/$name.rx
    rm -rf "$sim" "$rx"; mkdir -p "$sim"
    # the scenario with its C/N0, absolute paths (the copy lives in $out) and the optional duration cap
    retime_scenario "$src" | sed -e "s|^cn0_dbhz = .*|cn0_dbhz = $level|" \
        -e "s|^file = \"\(.*\)\"|file = \"$root/scenarios/\1\"|" > "$sim.toml"
    if [ -n "$duration" ]; then
      python3 - "$sim.toml" "$duration" <<'PY'
import re, sys
p, cap = sys.argv[1], float(sys.argv[2])
t = open(p).read()
m = re.search(r"^duration_s = ([0-9.]+)", t, re.M)  # the first is [signal]'s
t = t[:m.start(1)] + str(min(cap, float(m.group(1)))) + t[m.end(1):]
open(p, "w").write(t)
PY
    fi
    nice -n 5 "$ultratrack" simulate --scenario "$sim.toml" --out "$sim" --quiet > "$sim.log" 2>&1
    prns=$(tail -n +2 "$sim/satellites.csv" | cut -d, -f1 | paste -sd, -)
    # shellcheck disable=SC2086
    /usr/bin/time -f "%e %U %S" -o "$rx.time" nice -n 5 "$ultratrack" receive --input "$sim/antenna0.i8.bin" \
      --format i8 --fs 2.6e6 --nav "$nav" --prn "$prns" --out "$rx" --quiet ${receive_args//\{sim\}/$sim} \
      > "$rx.log" 2>&1 || true
    analyse "$sim" "$rx" "$sc" "$level" >> "$results"
    echo "dynamics_baseline: $(tail -1 "$results")" >&2
    [ "$keep" = 1 ] || rm -f "$sim/antenna0.i8.bin"
  done
done
if [ "$report_only" = 1 ]; then
  for rx in "$out"/*_cn0_*.rx; do
    [ -d "$rx" ] || continue
    base=$(basename "$rx" .rx); sc=${base%_cn0_*}; level=${base##*_cn0_}
    analyse "$out/$base.sim" "$rx" "$sc" "$level" >> "$results"
  done
fi
column -s, -t < "$results"
