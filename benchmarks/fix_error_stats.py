#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Errors of a file of GNSS fixes (gnss.csv of `gnsssim` or a user's) against a truth.csv, in a time window.

Prints one JSON object: the fixes' horizontal and height RMS (m) and how many fixes were compared. The truth is
interpolated linearly to each fix's time (it is at the IMU rate); positions as benchmarks/nav_error_stats.py does.
What a fused track is measured against when the fixes' errors are correlated in time: it cannot average them down.

    benchmarks/fix_error_stats.py GNSS.csv TRUTH.csv [--from-s 60] [--to-s T]
"""
import argparse
import bisect
import json
import math

from nav_error_stats import ned_error, rows


def main():
    p = argparse.ArgumentParser()
    p.add_argument("gnss")
    p.add_argument("truth")
    p.add_argument("--from-s", type=float, default=0.0)
    p.add_argument("--to-s", type=float, default=math.inf)
    a = p.parse_args()
    truth = rows(a.truth)
    times = [r["t_s"] for r in truth]
    n = 0
    h2 = v2 = 0.0
    for f in rows(a.gnss):
        t = f["t_s"]
        i = bisect.bisect_left(times, t)
        if t < a.from_s or t > a.to_s or i == 0 or i >= len(times):
            continue
        t0, t1 = truth[i - 1], truth[i]
        w = (t - t0["t_s"]) / (t1["t_s"] - t0["t_s"])
        tr = {k: t0[k] + w * (t1[k] - t0[k]) for k in ("lat_deg", "lon_deg", "height_m")}
        dn, de, dd = ned_error(f, tr)
        n += 1
        h2 += dn * dn + de * de
        v2 += dd * dd
    if n == 0:
        raise SystemExit(f"{a.gnss}: no fix inside the window and the truth's span")
    print(json.dumps({"fixes": n, "horizontal_rms_m": round(math.sqrt(h2 / n), 4),
                      "height_rms_m": round(math.sqrt(v2 / n), 4)}))


if __name__ == "__main__":
    main()
