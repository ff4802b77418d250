#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The weak-signal table of docs/validation.md (section 6) from the run folders of campaigns/weak_signal*.toml.

    benchmarks/validation/weak_signal_table.py OUT [OUT...]   (each the --out of a `campaign run`)

Per oscillator, trajectory, mode and C/N0 level, over the campaign's files: satellites kept after the step by the
receiver's own loss rule (lock_outcomes.csv: kept of kept + lost; not locked at the step and not acquired left out)
and by the common rule from the simulator's truth (truth_lock_outcomes.csv: kept of tracked), and the 3-D RMS of
solution.csv after the step per file (weak_rms_3d_m; '-' where a file had no fix after it). Reads only complete
runs; prints a markdown table, then per oscillator, trajectory and mode the 90 % threshold of the pooled fractions by
each rule, found as `campaign report` finds it (the lowest level above which every level keeps >= 90 %, interpolated
linearly from the level below): over several campaigns' folders (weak_signal_told and _more) it pools what one
campaign's report cannot. The campaign's own `campaign report` gives the same counts with intervals.
"""
import csv
import os
import sys
from collections import defaultdict


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def crossing(points):
    """The lowest level above which the kept fraction stays >= 0.9 (points: sorted (level, fraction))."""
    for i in range(len(points)):
        if all(v >= 0.9 for _, v in points[i:]):
            if i == 0:
                return f"<= {points[0][0]:.1f}"
            (l0, v0), (l1, v1) = points[i - 1], points[i]
            return f"{l0 + (0.9 - v0) * (l1 - l0) / (v1 - v0):.2f}"
    return "none"


def main(outs):
    table = defaultdict(lambda: {"own": [0, 0], "common": [0, 0], "rms": []})
    for out in outs:
        runs = os.path.join(out, "runs")
        for name in sorted(os.listdir(runs)):
            d = os.path.join(runs, name)
            if not os.path.exists(os.path.join(d, "complete.csv")):
                continue
            p = {r["name"]: r["value"] for r in rows(os.path.join(d, "parameters.csv"))}
            s = {r["name"]: r["value"] for r in rows(os.path.join(d, "complete.csv"))}
            key = (p.get("oscillator", ""), p["trajectory"], p["mode"], float(p["cn0_dbhz"]))
            t = table[key]
            for r in rows(os.path.join(d, "lock_outcomes.csv")):
                if r["outcome"] in ("kept", "lost"):
                    t["own"][0] += r["outcome"] == "kept"
                    t["own"][1] += 1
            truth = os.path.join(d, "truth_lock_outcomes.csv")
            if os.path.exists(truth):
                for r in rows(truth):
                    if r["outcome"] in ("kept", "lost"):
                        t["common"][0] += r["outcome"] == "kept"
                        t["common"][1] += 1
            t["rms"].append((int(p["file"]), s.get("weak_rms_3d_m")))
    print("| clock | trajectory | mode | C/N0 dB-Hz | kept, own rule | kept, common rule | solution.csv 3-D RMS per file [m] |")
    print("|---|---|---|---:|---:|---:|---|")
    for key in sorted(table):
        t = table[key]
        rms = " ".join(v if v is not None else "-" for _, v in sorted(t["rms"]))
        print(f"| {key[0]} | {key[1]} | {key[2]} | {key[3]:g} | {t['own'][0]}/{t['own'][1]} | "
              f"{t['common'][0]}/{t['common'][1]} | {rms} |")
    print()
    print("90 % threshold of the pooled fractions, dB-Hz: own rule / common rule")
    groups = sorted({key[:3] for key in table})
    for g in groups:
        curves = []
        for rule in ("own", "common"):
            pts = [(key[3], table[key][rule][0] / table[key][rule][1])
                   for key in sorted(table) if key[:3] == g and table[key][rule][1] > 0]
            curves.append(crossing(pts) if pts else "-")
        print(f"  {' '.join(x for x in g if x)}: {curves[0]} / {curves[1]}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
