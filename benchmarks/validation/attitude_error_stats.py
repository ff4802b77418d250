#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Attitude errors of a navigation or attitude file against the simulator's truth.csv, as small-angle rotation
errors in the NED frame (deg): north and east are the tilt, down the heading.

    benchmarks/validation/attitude_error_stats.py FILE TRUTH.csv [--from-s 15] [--to-s 59.9] [--label L]

FILE is `fuse`/`receive --imu`'s nav.csv (time t_s on the truth's time line; 1-sigmas sigma_att_n/e/d_deg) or
`attitude`'s attitude.csv (time tow_s against the truth's tow_s; unfixed rows left out; no NED sigma). The truth is
interpolated linearly at each row's time (yaw unwrapped). Prints a markdown row: label, rows, RMS north / east / down,
the RMS of the 3-D angle, and the share of rows with every axis inside 3 sigma ('-' without sigmas).
"""
import argparse
import csv
import math
from bisect import bisect_left


def rot(roll, pitch, yaw):
    """C_nb from roll, pitch, yaw (rad), 3-2-1."""
    cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), math.sin(yaw)
    return [[cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy],
            [cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy],
            [-sp, sr * cp, cr * cp]]


def error_ned_deg(est, true):
    """psi with C_est ~ (I - [psi x]) C_true: from dC = C_est C_true^T."""
    a, b = rot(*[math.radians(x) for x in est]), rot(*[math.radians(x) for x in true])
    d = [[sum(a[i][k] * b[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
    return [math.degrees(0.5 * (d[2][1] - d[1][2])), math.degrees(0.5 * (d[0][2] - d[2][0])),
            math.degrees(0.5 * (d[1][0] - d[0][1]))]


def wrap(d):
    return (d + 180.0) % 360.0 - 180.0


def main():
    p = argparse.ArgumentParser()
    p.add_argument("file")
    p.add_argument("truth")
    p.add_argument("--from-s", type=float, default=-math.inf)
    p.add_argument("--to-s", type=float, default=math.inf)
    p.add_argument("--label", default="")
    a = p.parse_args()
    truth = list(csv.DictReader(open(a.truth)))
    rows = list(csv.DictReader(open(a.file)))
    attitude_file = rows and "tow_s" in rows[0]
    key = "tow_s" if attitude_file else "t_s"
    times = [float(r[key]) for r in truth]
    t0 = float(truth[0]["tow_s"]) - float(truth[0]["t_s"])  # tow of t_s = 0
    n = 0
    sq = [0.0, 0.0, 0.0]
    inside = 0
    for r in rows:
        if attitude_file and r["fixed"] != "1":
            continue
        t = float(r[key])
        t_rel = t - t0 if attitude_file else t
        if t_rel < a.from_s or t_rel > a.to_s or t < times[0] or t > times[-1]:
            continue
        i = min(max(bisect_left(times, t), 1), len(times) - 1)
        w = (t - times[i - 1]) / (times[i] - times[i - 1]) if times[i] > times[i - 1] else 0.0
        ref = []
        for k in ("roll_deg", "pitch_deg", "yaw_deg"):
            x0, x1 = float(truth[i - 1][k]), float(truth[i][k])
            ref.append(x0 + w * wrap(x1 - x0))
        e = error_ned_deg([float(r["roll_deg"]), float(r["pitch_deg"]), float(r["yaw_deg"])], ref)
        n += 1
        for k in range(3):
            sq[k] += e[k] ** 2
        if not attitude_file and all(abs(e[k]) <= 3.0 * float(r[s]) for k, s in
                                     enumerate(("sigma_att_n_deg", "sigma_att_e_deg", "sigma_att_d_deg"))):
            inside += 1
    if n == 0:
        raise SystemExit(f"attitude_error_stats: no row of {a.file} in the window")
    rms = [math.sqrt(s / n) for s in sq]
    share = "-" if attitude_file else f"{100.0 * inside / n:.1f} %"
    print(f"| {a.label} | {n} | {rms[0]:.3f} / {rms[1]:.3f} / {rms[2]:.3f} | {math.sqrt(sum(sq) / n):.3f} | {share} |")


if __name__ == "__main__":
    main()
