#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""NEES of position, velocity and attitude over a Monte Carlo of fused runs (Bar-Shalom's consistency test).

Each run is a pair NAV.csv (of `fuse`) and TRUTH.csv. At each nav row at a truth time (from --from-s on), the
normalised estimation error squared of each 3-vector with the filter's diagonal 1-sigmas (nav.csv has no cross
terms): position NED, velocity NED, attitude as the psi angles NED (C_nb_est = (I - [psi x]) C_nb_true). Averaged
over the M runs at each time, a consistent filter's value is chi-square with 3M degrees of freedom over M; the
two-sided 95 % band is [chi2(0.025, 3M) / M, chi2(0.975, 3M) / M]. Prints one JSON object: per block the NEES
averaged over runs and times, the band, the share of times whose run average lies inside the band, and each axis's
mean squared normalised error (1 when consistent). With --window-s W, also "windows": per window [t, t + W) of the
common times, each axis's mean squared normalised error, RMS error and RMS 1-sigma (which side is off, and when;
position m, velocity m/s, attitude deg), and each axis's mean normalised error (a bias shared by the runs). With
--per-run, also "per_run": each run's NEES of the three blocks averaged over its times (which runs carry the mean),
and their medians. --to-s ends the span (default: the end).

    benchmarks/nav_nees.py [--from-s 60] [--to-s T] [--window-s 20] [--per-run] NAV1.csv TRUTH1.csv [...]
"""
import argparse
import json
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from nav_error_stats import ned_error, rows  # noqa: E402


def dcm_nb(roll, pitch, yaw):
    cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), math.sin(yaw)
    return [
        [cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy],
        [cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy],
        [-sp, sr * cp, cr * cp],
    ]


def psi(est, tru):
    """Attitude error psi (NED, rad) with C_est = (I - [psi x]) C_true: [psi x] = I - C_est C_true'."""
    ce = dcm_nb(*[math.radians(est[k]) for k in ("roll_deg", "pitch_deg", "yaw_deg")])
    ct = dcm_nb(*[math.radians(tru[k]) for k in ("roll_deg", "pitch_deg", "yaw_deg")])
    m = [[sum(ce[i][k] * ct[j][k] for k in range(3)) for j in range(3)] for i in range(3)]  # C_est C_true'
    # I - m = [psi x]: psi_x = (m[1][2] - m[2][1]) / 2 ... (antisymmetric part, sign of -[psi x])
    return [0.5 * (m[1][2] - m[2][1]), 0.5 * (m[2][0] - m[0][2]), 0.5 * (m[0][1] - m[1][0])]


def run_nees(nav_path, truth_path, from_s, to_s):
    truth = {round(r["t_s"] * 1e6): r for r in rows(truth_path)}
    out = {}
    with open(nav_path, newline="") as f:
        reader = csv.reader(f)
        names = next(reader)
        for values in reader:  # only the rows at truth times are converted (nav.csv is at the IMU rate)
            t = float(values[0])
            key = round(t * 1e6)
            tr = truth.get(key)
            if t < from_s or t > to_s or tr is None:
                continue
            r = {k: float(v) for k, v in zip(names, values) if v}
            dp = ned_error(r, tr)
            dv = [r[f"vel_{a}_mps"] - tr[f"vel_{a}_mps"] for a in "ned"]
            da = psi(r, tr)
            sp = [r[f"sigma_{a}_m"] for a in "ned"]
            sv = [r[f"sigma_v{a}_mps"] for a in "ned"]
            sa = [math.radians(r[f"sigma_att_{a}_deg"]) for a in "ned"]
            out[key] = [(e, s) for err, sig in ((dp, sp), (dv, sv), (da, sa)) for e, s in zip(err, sig)]
    return out


AXES = [f"{b}_{a}" for b in ("pos", "vel", "att") for a in "ned"]


def windows(runs, common, width):
    """Per window of the common times: each axis's NEES, RMS error, RMS sigma and mean normalised error."""
    times = sorted(common)
    out = []
    start = times[0]
    while start <= times[-1]:
        ts = [t for t in times if start <= t < start + round(width * 1e6)]
        start += round(width * 1e6)
        if not ts:
            continue
        n = len(ts) * len(runs)
        w = {"from_s": round(ts[0] * 1e-6, 3), "to_s": round(ts[-1] * 1e-6, 3)}
        for i, name in enumerate(AXES):
            scale = math.degrees(1.0) if name.startswith("att") else 1.0
            es = [r[t][i] for r in runs for t in ts]
            w[name] = {"nees": round(sum((e / s) ** 2 for e, s in es) / n, 3),
                       "rms_error": round(scale * math.sqrt(sum(e * e for e, _ in es) / n), 4),
                       "rms_sigma": round(scale * math.sqrt(sum(s * s for _, s in es) / n), 4),
                       "mean_normalised": round(sum(e / s for e, s in es) / n, 3)}
        out.append(w)
    return out


def chi2_quantile(p, k):
    """Wilson-Hilferty: accurate to a fraction of a percent for k >= 30."""
    # Standard normal quantile (Acklam's rational approximation).
    a = [-3.969683028665376e01, 2.209460984245205e02, -2.759285104469687e02, 1.383577518672690e02,
         -3.066479806614716e01, 2.506628277459239e00]
    b = [-5.447609879822406e01, 1.615858368580409e02, -1.556989798598866e02, 6.680131188771972e01,
         -1.328068155288572e01]
    c = [-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e00, -2.549732539343734e00,
         4.374664141464968e00, 2.938163982698783e00]
    d = [7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e00, 3.754408661907416e00]
    if p < 0.02425:
        q = math.sqrt(-2 * math.log(p))
        z = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) / ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1)
    elif p > 1 - 0.02425:
        q = math.sqrt(-2 * math.log(1 - p))
        z = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) / ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1)
    else:
        q = p - 0.5
        r = q * q
        z = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q / (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1)
    h = 2.0 / (9.0 * k)
    return k * (1.0 - h + z * math.sqrt(h)) ** 3


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--from-s", type=float, default=60.0)
    p.add_argument("--to-s", type=float, default=math.inf)
    p.add_argument("--window-s", type=float, default=0.0)
    p.add_argument("--per-run", action="store_true")
    p.add_argument("files", nargs="+")
    a = p.parse_args()
    if len(a.files) % 2:
        sys.exit("nav_nees: give NAV.csv TRUTH.csv pairs")
    runs = [run_nees(a.files[i], a.files[i + 1], a.from_s, a.to_s) for i in range(0, len(a.files), 2)]
    errors = runs
    runs = [{t: [(e / s) ** 2 for e, s in v] for t, v in r.items()} for r in errors]
    common = set(runs[0])
    for r in runs[1:]:
        common &= set(r)
    if not common:
        sys.exit("nav_nees: no time common to every run")
    m = len(runs)
    lo, hi = chi2_quantile(0.025, 3 * m) / m, chi2_quantile(0.975, 3 * m) / m
    result = {"runs": m, "times": len(common), "band_95": [round(lo, 3), round(hi, 3)]}
    for b, name in enumerate(("position", "velocity", "attitude")):
        per_time = [sum(sum(r[t][3 * b:3 * b + 3]) for r in runs) / m for t in common]
        mean = sum(per_time) / len(per_time)
        inside = sum(lo <= v <= hi for v in per_time) / len(per_time)
        # Each axis's mean squared normalised error (1 when consistent): which axis is off.
        axes = [round(sum(r[t][3 * b + i] for r in runs for t in common) / (m * len(common)), 3) for i in range(3)]
        result[name] = {"mean_nees": round(mean, 3), "in_band": lo <= mean <= hi, "times_inside_band": round(inside, 3),
                        "per_axis_ned": axes}
    if a.window_s > 0.0:
        result["windows"] = windows(errors, common, a.window_s)
    if a.per_run:
        blocks = ("position", "velocity", "attitude")
        per_run = [dict({"nav": a.files[2 * i]}, **{name: round(sum(sum(r[t][3 * b:3 * b + 3]) for t in common) / len(common), 3)
                                                    for b, name in enumerate(blocks)}) for i, r in enumerate(runs)]
        result["per_run"] = per_run
        result["per_run_median"] = {name: sorted(x[name] for x in per_run)[m // 2] for name in blocks}
    print(json.dumps(result))


if __name__ == "__main__":
    main()
