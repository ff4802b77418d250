#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Errors of a navigation solution (nav.csv of `fuse`/`ins`/`receive --imu`) against a truth.csv, from a given time on.

Prints one JSON object: horizontal, height, 3-D position RMS (m), roll/pitch/yaw RMS (deg), the fraction of rows with
every position axis inside 3 sigma, and the number of rows compared. Rows are compared where the nav time equals a
truth time (within 1 us); positions by WGS-84 radii of curvature at the truth point, angles wrapped to +-180 deg.

    benchmarks/nav_error_stats.py NAV.csv TRUTH.csv [--from-s 60] [--to-s T]
"""
import argparse
import csv
import json
import math
import sys

A = 6378137.0
E2 = 6.69437999014e-3


def rows(path):
    with open(path, newline="") as f:
        return [{k: float(v) for k, v in r.items() if v not in ("", None)} for r in csv.DictReader(f)]


def ned_error(r, tr):
    """Position error north, east, down (m) of a row against a truth row (lat_deg, lon_deg, height_m)."""
    lat = math.radians(tr["lat_deg"])
    w = math.sqrt(1.0 - E2 * math.sin(lat) ** 2)
    rm = A * (1.0 - E2) / w**3 + tr["height_m"]
    rn = A / w + tr["height_m"]
    dn = math.radians(r["lat_deg"] - tr["lat_deg"]) * rm
    de = math.radians(r["lon_deg"] - tr["lon_deg"]) * rn * math.cos(lat)
    return dn, de, -(r["height_m"] - tr["height_m"])


def wrap(d):
    return (d + 180.0) % 360.0 - 180.0


def main():
    p = argparse.ArgumentParser()
    p.add_argument("nav")
    p.add_argument("truth")
    p.add_argument("--from-s", type=float, default=0.0)
    p.add_argument("--to-s", type=float, default=math.inf)
    a = p.parse_args()
    truth = {round(r["t_s"] * 1e6): r for r in rows(a.truth)}
    n = 0
    h2 = v2 = inside = 0.0
    att2 = [0.0, 0.0, 0.0]
    for r in rows(a.nav):
        t = r["t_s"]
        if t < a.from_s or t > a.to_s:
            continue
        tr = truth.get(round(t * 1e6))
        if tr is None:
            continue
        dn, de, dd = ned_error(r, tr)
        n += 1
        h2 += dn * dn + de * de
        v2 += dd * dd
        for i, k in enumerate(("roll_deg", "pitch_deg", "yaw_deg")):
            att2[i] += wrap(r[k] - tr[k]) ** 2
        if "sigma_n_m" in r and all(
            abs(e) <= 3.0 * r[s] for e, s in ((dn, "sigma_n_m"), (de, "sigma_e_m"), (dd, "sigma_d_m"))
        ):
            inside += 1
    if n == 0:
        sys.exit(f"nav_error_stats: no nav row at a truth time in [{a.from_s}, {a.to_s}] s")
    print(json.dumps({
        "rows": n,
        "horizontal_rms_m": round(math.sqrt(h2 / n), 4),
        "height_rms_m": round(math.sqrt(v2 / n), 4),
        "position_3d_rms_m": round(math.sqrt((h2 + v2) / n), 4),
        "roll_rms_deg": round(math.sqrt(att2[0] / n), 4),
        "pitch_rms_deg": round(math.sqrt(att2[1] / n), 4),
        "yaw_rms_deg": round(math.sqrt(att2[2] / n), 4),
        "within_3sigma": round(inside / n, 4),
    }))


if __name__ == "__main__":
    main()
