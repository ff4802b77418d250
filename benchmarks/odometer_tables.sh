#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Seed 004's tables in shape, from simulation (docs/validation.md, "Odometer aiding"):
#   Table 1: the 12.7 km ordinary-road loop (scenarios/odometer_loop.toml), navigation-grade IMU, GNSS for the
#            static alignment and the first 170 s only, then odometer aiding: yaw-rate thresholds 1.0 to 2.0 deg/s
#            in 0.25 steps (gated, 5 m/s) beside the always-on mode and the seed's rows.
#   Table 2: the 114.5 km mostly-motorway drive with slip / skid events (scenarios/odometer_motorway.toml), GNSS
#            until 240 s, gated at 1.5 deg/s: navigation grade (target <= 0.06 % DT horizontal) and HG1700AE, the
#            estimated scale factor against the simulated one.
# Errors: maximum horizontal / altitude error after the last GNSS fix used, and in % of the distance travelled
# since then (DT), from fuse --truth's summary.json "odometer" object.
# Usage: benchmarks/odometer_tables.sh [--build DIR] [--out DIR] [--tables "1 2"] [--seed N]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="$here/build"; out="${TMPDIR:-/tmp}/odometer_tables"; tables="1 2"; seed=1
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;; --out) out="$2"; shift 2 ;; --tables) tables="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
U="$build/tools/ultratrack"
mkdir -p "$out"
cp "$here"/scenarios/odometer_*_segments.csv "$out/"

# simulate NAME SCENARIO PRESET -> $out/NAME/{sim,gnss.csv}
simulate() {
  local dir="$out/$1"
  mkdir -p "$dir"
  sed -e "s/^preset = .*/preset = \"$3\"/" -e "s/^seed = .*/seed = $seed/" "$2" > "$out/$1.toml"
  "$U" simulate --scenario "$out/$1.toml" --out "$dir/sim" --quiet >/dev/null
  "$U" gnsssim --truth "$dir/sim/truth.csv" --rate 1 --sigma 1.5 1.5 3 --seed "$seed" --out "$dir/gnss.csv" >/dev/null
}

# fuse NAME RUN PRESET MODE THRESHOLD GNSS_UNTIL -> $out/NAME/RUN/summary.json
fuse() {
  local dir="$out/$1"
  sed -e "s/^preset = .*/preset = \"$3\"/" -e "s/^mode = .*/mode = \"$4\"/" \
      -e "s/^yaw_rate_threshold_dps = .*/yaw_rate_threshold_dps = $5/" "$here/scenarios/odometer_fuse.toml" \
      > "$dir/$2.toml"
  "$U" fuse --imu "$dir/sim/imu.csv" --gnss "$dir/gnss.csv" --odometer "$dir/sim/odometer.csv" --gnss-until "$6" \
      --config "$dir/$2.toml" --align static --truth "$dir/sim/truth.csv" --decimate 100 --out "$dir/$2" --quiet \
      >/dev/null
}

if [[ " $tables " == *" 1 "* ]]; then
  simulate loop "$here/scenarios/odometer_loop.toml" navigation
  for t in 1.00 1.25 1.50 1.75 2.00; do fuse loop "gated_$t" navigation gated "$t" 170; done
  fuse loop always navigation always 1.5 170
  python3 - "$out/loop" <<'PY'
import json, sys
d = sys.argv[1]
seed = {"1.00": (12576, 34, 7.6, 0.27, 0.06), "1.25": (12542, 26, 8.7, 0.21, 0.07), "1.50": (12499, 19.4, 8, 0.16, 0.06),
        "1.75": (12590, 25.6, 12.6, 0.20, 0.10), "2.00": (9090, 21.2, 17.7, 0.23, 0.19)}
print("Table 1 (12.7 km loop, navigation grade, GNSS until 170 s; ours | seed 004 Table 1)\n")
print("| threshold [deg/s] | distance [m] | horizontal error max [m] | altitude error max [m] | horizontal [% DT] "
      "| altitude [% DT] | updates accepted / rejected | gated: yaw rate / speed | seed: distance, pos, alt [m], pos, alt [% DT] |")
print("|---|---|---|---|---|---|---|---|---|")
for run in ["gated_1.00", "gated_1.25", "gated_1.50", "gated_1.75", "gated_2.00", "always"]:
    o = json.load(open(f"{d}/{run}/summary.json"))["odometer"]
    t = run.split("_")[1] if run.startswith("gated") else None
    s = seed.get(t)
    print(f"| {t if t else 'always-on'} | {o['distance_travelled_m']:.0f} | {o['horizontal_error_max_m']:.2f} | "
          f"{o['altitude_error_max_m']:.2f} | {o['horizontal_error_max_pct_dt']:.3f} | {o['altitude_error_max_pct_dt']:.3f} | "
          f"{o['updates_accepted']} / {o['updates_rejected']} | {o['gated_yaw_rate']} / {o['gated_speed']} | "
          + (f"{s[0]}, {s[1]}, {s[2]}, {s[3]:.2f}, {s[4]:.2f} |" if s else "- |"))
PY
fi

if [[ " $tables " == *" 2 "* ]]; then
  for preset in navigation hg1700ae; do
    [ -n "${skip_sim:-}" ] && [ -f "$out/motorway_$preset/gnss.csv" ] && continue
    simulate "motorway_$preset" "$here/scenarios/odometer_motorway.toml" "$preset"
    fuse "motorway_$preset" gated_1.50 "$preset" gated 1.5 240
    fuse "motorway_$preset" always "$preset" always 1.5 240
  done
  python3 - "$out" "$here/scenarios/odometer_motorway.toml" <<'PY'
import json, re, sys
d, scenario = sys.argv[1], open(sys.argv[2]).read()
sf_true = float(re.search(r"^odometer_scale_factor_error = (\S+)", scenario, re.M).group(1))
print("\nTable 2 (114.5 km mostly motorway, GNSS until 240 s, slip / skid events; seed 004 Table 2: 120.28 km, "
      "77.9 m, 363.9 m, 0.06 % DT, 0.30 % DT)\n")
print("| IMU | mode | distance [km] | horizontal error max [m] | altitude error max [m] | horizontal [% DT] | "
      "altitude [% DT] | horizontal <= 0.06 % DT | scale factor est. (sim. " + f"{sf_true:g}" + ") | within 3 sigma | "
      "updates accepted / rejected | gated: yaw rate / speed |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for preset in ["navigation", "hg1700ae"]:
    for run in ["gated_1.50", "always"]:
        o = json.load(open(f"{d}/motorway_{preset}/{run}/summary.json"))["odometer"]
        sf, ssf = o["scale_factor"], o["sigma_scale_factor"]
        ok = abs(sf - sf_true) <= 3 * ssf
        met = "met" if o["horizontal_error_max_pct_dt"] <= 0.06 else "NOT met"
        print(f"| {preset} | {'gated 1.5 deg/s' if run != 'always' else 'always-on'} | "
              f"{o['distance_travelled_m'] / 1000:.2f} | {o['horizontal_error_max_m']:.1f} | "
              f"{o['altitude_error_max_m']:.1f} | {o['horizontal_error_max_pct_dt']:.3f} | "
              f"{o['altitude_error_max_pct_dt']:.3f} | {met} | {sf:.5f} +- {ssf:.5f} | {'yes' if ok else 'NO'} | "
              f"{o['updates_accepted']} / {o['updates_rejected']} | {o['gated_yaw_rate']} / {o['gated_speed']} |")
PY
fi
