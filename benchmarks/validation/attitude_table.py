#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""One row per run of the attitude table of docs/validation.md (section 8): `ultratrack attitude`'s attitude.csv
against the simulator's truth.csv.

    benchmarks/validation/attitude_table.py LABEL ATTITUDE_CSV TRUTH_CSV [LABEL ATTITUDE_CSV TRUTH_CSV ...]

Per run: the attitude epochs (rows of attitude.csv), the share fixed (column fixed = 1), and over the fixed epochs the
RMS error of roll, pitch and yaw against the truth (interpolated linearly at each epoch's tow_s; yaw differences
wrapped to +-180 deg), the RMS of the solver's own 1-sigma, and the largest error. Degrees. Prints a markdown table.
"""
import csv
import math
import sys
from bisect import bisect_left


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def wrap(d):
    return (d + 180.0) % 360.0 - 180.0


def truth_at(truth, times, t):
    i = min(max(bisect_left(times, t), 1), len(times) - 1)
    t0, t1 = times[i - 1], times[i]
    w = 0.0 if t1 == t0 else (t - t0) / (t1 - t0)
    out = []
    for key in ("roll_deg", "pitch_deg", "yaw_deg"):
        a, b = float(truth[i - 1][key]), float(truth[i][key])
        out.append(a + w * wrap(b - a))
    return out


def row(label, attitude_csv, truth_csv):
    epochs = read(attitude_csv)
    truth = read(truth_csv)
    times = [float(r["tow_s"]) for r in truth]
    fixed = [e for e in epochs if e["fixed"] == "1"]
    err = [[], [], []]
    sig = [[], [], []]
    for e in fixed:
        ref = truth_at(truth, times, float(e["tow_s"]))
        for k, key in enumerate(("roll", "pitch", "yaw")):
            err[k].append(wrap(float(e[key + "_deg"]) - ref[k]))
            sig[k].append(float(e["sigma_" + key + "_deg"]))
    rms = lambda xs: math.sqrt(sum(x * x for x in xs) / len(xs)) if xs else float("nan")
    share = 100.0 * len(fixed) / len(epochs) if epochs else float("nan")
    return "| {} | {} | {:.1f} % | {} | {} | {} |".format(
        label, len(epochs), share,
        " / ".join("{:.3f}".format(rms(e)) for e in err),
        " / ".join("{:.3f}".format(rms(s)) for s in sig),
        " / ".join("{:.2f}".format(max((abs(x) for x in e), default=float("nan"))) for e in err))


def main(args):
    if len(args) < 3 or len(args) % 3:
        sys.exit(__doc__)
    print("| run | epochs | fixed | RMS roll / pitch / yaw, deg | solver 1-sigma, deg | max error, deg |")
    print("|---|---|---|---|---|---|")
    for i in range(0, len(args), 3):
        print(row(*args[i:i + 3]))


if __name__ == "__main__":
    main(sys.argv[1:])
