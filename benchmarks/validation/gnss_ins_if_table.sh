#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The loose/tight-from-IF table of docs/validation.md (section 10.1): scenarios/circle_100m_30kmh_imu.toml (the 100 m
# circle at 30 km/h, 120 s, 45 dB-Hz, HG1700AE at 100 Hz) simulated once and received hot by the scalar receiver
# alone and with its IMU, loose and tight, EKF and UKF, in-motion alignment. Per run: nav.csv's 3-D (horizontal,
# vertical) RMS against the truth over all its rows and from 30 s (benchmarks/nav_error_stats.py), solution.csv's
# fixes likewise (`ultratrack compare`, truth at each fix's true time), and the filter's updates accepted / rejected.
#   benchmarks/validation/gnss_ins_if_table.sh [--out DIR] [--ultratrack build/tools/ultratrack] [--keep]
# Cost: about 1.5 CPU-min; 624 MB of scratch (the sample file is deleted at the end unless --keep).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
name=gnss_ins_if_table.sh; out=/tmp/ultratrack_gnss_ins_if_table
source "$here/table_options.sh"
sim=$out/sim
"$ultratrack" simulate --scenario "$root/scenarios/circle_100m_30kmh_imu.toml" --out "$sim" --quiet > "$out/sim.log"
runs=("scalar scalar ekf" "loose-ekf loose ekf" "loose-ukf loose ukf" "tight-ekf tight ekf" "tight-ukf tight ukf")
for r in "${runs[@]}"; do
  read -r name coupling filter <<< "$r"
  imu=(); [ "$coupling" = scalar ] || imu=(--imu "$sim/imu.csv" --filter "$filter" --align motion)
  "$ultratrack" receive --input "$sim/antenna0.i8.bin" --format i8 --fs 2.6e6 \
    --nav "$root/tests/data/brdc3540_0000-0200.14n" --coupling "$coupling" "${imu[@]}" --quiet \
    --out "$out/$name" > "$out/$name.log"
done
[ "$keep" = 1 ] || rm -f "$sim"/antenna0.i8.bin
python3 - "$out" "$ultratrack" "$root" "${runs[@]}" <<'PY'
import json, subprocess, sys
out, ultratrack, root, runs = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
sim = f"{out}/sim"
truth_tow0 = float(open(f"{sim}/truth.csv").readlines()[1].split(",")[2])

def nav_stats(run, from_s):
    r = subprocess.run([f"{root}/benchmarks/nav_error_stats.py", f"{out}/{run}/nav.csv", f"{sim}/truth.csv",
                        "--from-s", str(from_s)], capture_output=True, text=True, check=True)
    return json.loads(r.stdout)

def fix_stats(run, from_s):
    first = float(open(f"{out}/{run}/solution.csv").readlines()[1].split(",")[1]) - truth_tow0
    r = subprocess.run([ultratrack, "compare", "--solution", f"{out}/{run}/solution.csv", "--truth",
                        f"{sim}/truth.csv", "--skip", str(max(0.0, from_s - first)), "--json"],
                       capture_output=True, text=True, check=True)
    return json.loads(r.stdout), first

def fmt(h, v):
    return f"{(h * h + v * v) ** 0.5:.3f} ({h:.3f}, {v:.3f}) m"

print("| run | fused 3-D (horizontal, vertical) | GNSS-only 3-D (horizontal, vertical) | from 30 s: fused / GNSS-only 3-D "
      "(horizontal) | updates accepted / rejected |")
print("|---|---|---|---|---|")
for spec in runs:
    name, coupling, _ = spec.split()
    fixes, first = fix_stats(name, 0.0)
    fixes30, _ = fix_stats(name, 30.0)
    g = fmt(fixes["rms_horizontal_m"], fixes["rms_vertical_m"])
    g30 = f"{fixes30['rms_3d_m']:.3f} ({fixes30['rms_horizontal_m']:.3f})"
    if coupling == "scalar":
        print(f"| {name} | - | {g} | - / {g30} m | - |")
        continue
    n, n30 = nav_stats(name, 0.0), nav_stats(name, 30.0)
    fused = fmt(n["horizontal_rms_m"], n["height_rms_m"])
    f30 = f"{n30['position_3d_rms_m']:.3f} ({n30['horizontal_rms_m']:.3f})"
    fusion = json.load(open(f"{out}/{name}/summary.json")).get("fusion", {})
    updates = f"{fusion.get('updates_accepted', '?')} / {fusion.get('updates_rejected', '?')}"
    print(f"| {name} | {fused} | {g} | {f30} / {g30} m | {updates} |")
PY
