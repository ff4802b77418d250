#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The GPS-attitude-aiding table of docs/validation.md (section 11): the banked 500 km/h circle of
# scenarios/attitude_moving.toml through `ultratrack attitude` (10 Hz, and 1 Hz as seed 003), the same trajectory's IMU
# from `imusim` (HG1700AE and MEMS, seed 3), 1 Hz fixes from `gnsssim` (1.5/1.5/3 m, 0.05 m/s, seed 5), and `fuse`
# without GPS attitude (in-motion alignment) and with it (aligned on the first fixed GPS attitude). Attitude errors in
# NED over 15-59.9 s against the simulator's truth (attitude_error_stats.py), the receiver's own attitude first.
#   benchmarks/validation/gps_attitude_aiding_table.sh [--out DIR] [--ultratrack build/tools/ultratrack] [--keep]
# Cost: about 1 CPU-min; 470 MB of scratch (deleted unless --keep).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
name=gps_attitude_aiding_table.sh; out=/tmp/ultratrack_gps_attitude_aiding
source "$here/table_options.sh"
sim=$out/sim
u() { "$ultratrack" "$@" --quiet > /dev/null; }
u simulate --scenario "$root/scenarios/attitude_moving.toml" --out "$sim"
for interval in 0.1 1.0; do
  u attitude --input "$sim"/antenna0.i8.bin "$sim"/antenna1.i8.bin "$sim"/antenna2.i8.bin --format i8 --fs 2.6e6 \
    --antennas "$root/scenarios/attitude_antennas.toml" --nav "$root/tests/data/brdc3540_0000-0200.14n" \
    --interval "$interval" --out "$out/rx_$interval"
done
[ "$keep" = 1 ] || rm -f "$sim"/antenna*.bin
"$ultratrack" gnsssim --truth "$sim/truth.csv" --rate 1 --first 0.37 --seed 5 --out "$out/gnss.csv" > /dev/null
stats() { python3 "$here/attitude_error_stats.py" "$@" --from-s 15 --to-s 59.9; }
echo "| IMU | GPS attitude | rows | error RMS N / E / D, deg (15-59.9 s) | 3-D, deg | rows inside 3 sigma |"
echo "|---|---|---|---|---|---|"
stats "$out/rx_0.1/attitude.csv" "$sim/truth.csv" --label "(receiver alone, 10 Hz) | -"
for preset in hg1700ae mems; do
  "$ultratrack" imusim --profile circle --duration 60 --rate 100 --preset "$preset" --seed 3 --lat-deg 35.274016 \
    --lon-deg 137.013759 --height-m 1000 --out "$out/imu_$preset" > /dev/null
  printf '[imu]\npreset = "%s"\n' "$preset" > "$out/$preset.toml"
  common=(--imu "$out/imu_$preset/imu.csv" --gnss "$out/gnss.csv" --truth "$sim/truth.csv" --config "$out/$preset.toml")
  u fuse "${common[@]}" --align motion --out "$out/f_${preset}_none"
  stats "$out/f_${preset}_none/nav.csv" "$sim/truth.csv" --label "$preset | none"
  for interval in 0.1 1.0; do
    u fuse "${common[@]}" --attitude "$out/rx_$interval/attitude.csv" --attitude-origin 1823 530396 --align attitude \
      --out "$out/f_${preset}_$interval"
    stats "$out/f_${preset}_$interval/nav.csv" "$sim/truth.csv" --label "$preset | every $interval s"
  done
done
