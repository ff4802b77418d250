#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Fusion on a datasheet MEMS unit (issue: fusion on a user's own IMU): the ADIS16405-class drive of
# scenarios/mems_drive_adis16405.toml over several IMU seeds, 5 Hz fixes at non-integer times from `gnsssim`, `fuse`
# told only the datasheet values (scenarios/mems_datasheet_fuse.toml) with in-motion alignment, and the errors after
# the first 60 s (benchmarks/nav_error_stats.py). One line per run, then the median and worst of each column.
#   benchmarks/mems_fusion.sh [--build DIR] [--seeds "1 2 3 4 5"] [--out DIR] [--fixes vel|pos] [--filter ekf|ukf]
#       [--scenario S.toml (default scenarios/mems_drive_adis16405.toml)] [--fuse-config C.toml (default
#       scenarios/mems_datasheet_fuse.toml)] [--from-s 60]
#       [--nhc on|off] [--sigma "0.5 0.5 1.0"] [--velocity-sigma 0.05] [--correlation S] [--interval S]
#       [--told-correlation S] [--told-sigma "N E D"] [--outage "START DURATION"] [--accel-bias-mg MG]
#       [--gyro-bias-dph DPH] [--rate HZ (default 5)] [--white-sigma "N E D"] [--stated-sigma "N E D"]
#       [--velocity-correlation S] [--clean]
# --rate: the fixes per second; --white-sigma: a white part on top of the (correlated) errors; --stated-sigma: the
# sigma the fix file states, when not the true one; --velocity-correlation: the velocity errors Gauss-Markov with that
# time (a receiver that smooths its velocities; gnsssim).
# --accel-bias-mg, --gyro-bias-dph: the unit's turn-on biases (1 sigma) in the simulation and in the filter's
# datasheet model alike (accel_bias_mg, gyro_bias_dph in the scenario's and the fuse configuration's [imu]; e.g. 5 mg
# and 1080 deg/h against the ADIS16405's 50 and 10800).
# --velocity-sigma: the fixes' white velocity noise per axis (gnsssim), told to the filter as [gnss]
# velocity_sigma_mps (the fix file carries the position sigmas only). --correlation: the fixes' errors first-order
# Gauss-Markov with that time (gnsssim); --interval: the filter's decorrelating interval between fixes used ([gnss]
# update_interval_s); --told-correlation: the correlation time the filter is told ([gnss] error_correlation_time_s;
# default auto: fuse measures it from the fixes, fusion/fix_error_whiteness.hpp; 0: white);
# --told-sigma: with it, the Gauss-Markov 1-sigma the filter carries as fix-error states ([gnss] error_sigma_ned_m;
# without: the fixes' variance is inflated).
# --outage: no fixes in [START, START + DURATION) (fuse --outage); the errors are then reported before the outage
# (before_*) and from 30 s after its end (after_*) besides the whole run. --clean: delete each run's imu.csv once
# fused (Monte Carlos of many seeds).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="$here/build"; seeds="1 2 3 4 5"; out="${TMPDIR:-/tmp}/mems_fusion"; fixes=vel; filter=ekf; nhc=on
sigma="0.5 0.5 1.0"; velocity_sigma=0.05; correlation=0; interval=0; told=auto; told_sigma=""; outage=""; clean=0
accel_bias_mg=""; gyro_bias_dph=""; rate=5; white_sigma=""; stated_sigma=""; velocity_correlation=0
scenario="$here/scenarios/mems_drive_adis16405.toml"; fuse_config="$here/scenarios/mems_datasheet_fuse.toml"; from_s=60
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;; --seeds) seeds="$2"; shift 2 ;; --out) out="$2"; shift 2 ;;
    --fixes) fixes="$2"; shift 2 ;; --filter) filter="$2"; shift 2 ;; --nhc) nhc="$2"; shift 2 ;;
    --sigma) sigma="$2"; shift 2 ;; --velocity-sigma) velocity_sigma="$2"; shift 2 ;;
    --correlation) correlation="$2"; shift 2 ;; --interval) interval="$2"; shift 2 ;;
    --accel-bias-mg) accel_bias_mg="$2"; shift 2 ;; --gyro-bias-dph) gyro_bias_dph="$2"; shift 2 ;;
    --told-correlation) told="$2"; shift 2 ;; --told-sigma) told_sigma="$2"; shift 2 ;;
    --outage) outage="$2"; shift 2 ;; --clean) clean=1; shift ;;
    --scenario) scenario="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
    --fuse-config) fuse_config="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
    --from-s) from_s="$2"; shift 2 ;; --rate) rate="$2"; shift 2 ;;
    --white-sigma) white_sigma="$2"; shift 2 ;; --stated-sigma) stated_sigma="$2"; shift 2 ;;
    --velocity-correlation) velocity_correlation="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
U="$build/tools/ultratrack"
mkdir -p "$out"
segments=$(sed -n 's/^file = "\(.*\)"/\1/p' "$scenario")
[ -n "$segments" ] && cp "$(dirname "$scenario")/$segments" "$out/"
config="$out/fuse.toml"
grep -v '^nhc = ' "$fuse_config" > "$config"
set_biases=(-e "")
[ -n "$accel_bias_mg" ] && set_biases+=(-e "s/^accel_bias_mg = .*/accel_bias_mg = $accel_bias_mg/")
[ -n "$gyro_bias_dph" ] && set_biases+=(-e "s/^gyro_bias_dph = .*/gyro_bias_dph = $gyro_bias_dph/")
sed -i "${set_biases[@]}" "$config"
if [ "$nhc" = on ]; then
  if grep -q '^\[vehicle\]' "$config"; then sed -i 's/^\[vehicle\]/[vehicle]\nnhc = true/' "$config"
  else printf '\n[vehicle]\nnhc = true\n' >> "$config"; fi
fi
told_value="$told"; [ "$told" = auto ] && told_value='"auto"'
printf '\n[gnss]\nupdate_interval_s = %s\nerror_correlation_time_s = %s\nvelocity_sigma_mps = %s\n' "$interval" \
    "$told_value" "$velocity_sigma" >> "$config"
if [ -n "$told_sigma" ]; then
  # shellcheck disable=SC2086
  printf 'error_sigma_ned_m = [%s]\n' "$(echo $told_sigma | tr ' ' ',')" >> "$config"
fi
outage_flag=""; [ -n "$outage" ] && outage_flag="--outage $outage"
velocity_flag=""; [ "$fixes" = pos ] && velocity_flag="--no-velocity"
echo "fixes $fixes at $rate Hz ($sigma m${white_sigma:+ + white $white_sigma m}${stated_sigma:+, stated $stated_sigma m}, velocity $velocity_sigma m/s, correlation ${correlation} s, used every ${interval} s," \
    "filter told ${told}${told_sigma:+ as states of $told_sigma m}), filter $filter, nhc $nhc${outage:+, outage $outage}"
for seed in $seeds; do
  run="$out/seed$seed"
  sed -e "s/^seed = .*/seed = $seed/" "${set_biases[@]}" "$scenario" > "$out/scenario_$seed.toml"
  "$U" simulate --scenario "$out/scenario_$seed.toml" --out "$run/sim" --quiet >/dev/null
  # shellcheck disable=SC2086
  "$U" gnsssim --truth "$run/sim/truth.csv" --rate "$rate" --first 0.137 --sigma $sigma --velocity-sigma \
      "$velocity_sigma" --velocity-correlation "$velocity_correlation" --correlation "$correlation" $velocity_flag \
      ${white_sigma:+--white-sigma $white_sigma} ${stated_sigma:+--stated-sigma $stated_sigma} --seed "$seed" \
      --out "$run/gnss.csv" >/dev/null
  # shellcheck disable=SC2086
  "$U" fuse --imu "$run/sim/imu.csv" --gnss "$run/gnss.csv" --config "$config" --filter "$filter" --align motion \
      $outage_flag --out "$run/fuse" --quiet >/dev/null
  [ "$clean" = 1 ] && rm -f "$run/sim/imu.csv"
  stats=$(python3 "$here/benchmarks/nav_error_stats.py" "$run/fuse/nav.csv" "$run/sim/truth.csv" --from-s "$from_s")
  fixes=$(python3 "$here/benchmarks/fix_error_stats.py" "$run/gnss.csv" "$run/sim/truth.csv" --from-s "$from_s")
  stats=$(python3 -c "import json,sys; d=json.loads(sys.argv[1]); d['fixes_horizontal_rms_m']=json.loads(sys.argv[2])['horizontal_rms_m']; print(json.dumps(d))" "$stats" "$fixes")
  if [ -n "$outage" ]; then
    read -r o_start o_len <<< "$outage"
    before=$(python3 "$here/benchmarks/nav_error_stats.py" "$run/fuse/nav.csv" "$run/sim/truth.csv" --from-s "$from_s" \
        --to-s "$o_start")
    after=$(python3 "$here/benchmarks/nav_error_stats.py" "$run/fuse/nav.csv" "$run/sim/truth.csv" \
        --from-s "$(python3 -c "print($o_start + $o_len + 30)")")
    fixes_before=$(python3 "$here/benchmarks/fix_error_stats.py" "$run/gnss.csv" "$run/sim/truth.csv" --from-s "$from_s" \
        --to-s "$o_start")
    fixes_after=$(python3 "$here/benchmarks/fix_error_stats.py" "$run/gnss.csv" "$run/sim/truth.csv" \
        --from-s "$(python3 -c "print($o_start + $o_len + 30)")")
    stats=$(python3 -c "import json,sys; d=json.loads(sys.argv[1]); [d.update({p + '_' + k: v for k, v in json.loads(a).items()}) for p, a in (('before', sys.argv[2]), ('after', sys.argv[3]))]; [d.update({p + '_fixes_horizontal_rms_m': json.loads(a)['horizontal_rms_m']}) for p, a in (('before', sys.argv[4]), ('after', sys.argv[5]))]; print(json.dumps(d))" "$stats" "$before" "$after" "$fixes_before" "$fixes_after")
  fi
  extra=$(python3 -c "import json,sys; s=json.load(open('$run/fuse/summary.json')); print(json.dumps({'rejected': s['fix_updates_rejected'], 'used': s['fixes_used'], 'recoveries': s['lockout_recoveries'], 'fix_model': s['fix_error_model']['kind']}))")
  echo "seed $seed $stats $extra"
done | tee "$out/runs.txt"
python3 - "$out/runs.txt" <<'PY'
import json, statistics, sys
rows = []
for line in open(sys.argv[1]):
    if not line.startswith("seed"):
        continue
    parts = line.split(" ", 2)[2]
    a, b = parts.rsplit("} {", 1)
    d = json.loads(a + "}")
    d.update(json.loads("{" + b))
    rows.append(d)
keys = ["horizontal_rms_m", "height_rms_m", "roll_rms_deg", "pitch_rms_deg", "yaw_rms_deg", "within_3sigma",
        "fixes_horizontal_rms_m"]
if "before_horizontal_rms_m" in rows[0]:
    keys += [p + k for p in ("before_", "after_")
             for k in ("horizontal_rms_m", "yaw_rms_deg", "within_3sigma", "fixes_horizontal_rms_m")]
print("| | " + " | ".join(keys) + " | rejected fixes | recoveries |")
print("|---" * (len(keys) + 3) + "|")
for name, f in (("median", statistics.median), ("worst", max)):
    vals = [f(r[k] for r in rows) if not (name == "worst" and k.endswith("within_3sigma")) else min(r[k] for r in rows) for k in keys]
    rej = f(r["rejected"] / r["used"] for r in rows)
    rec = f(r["recoveries"] for r in rows)
    print(f"| {name} of {len(rows)} | " + " | ".join(f"{v:.3f}" for v in vals) + f" | {100 * rej:.1f} % | {rec} |")
PY
