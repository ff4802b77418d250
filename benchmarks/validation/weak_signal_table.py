#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The weak-signal table of docs/validation.md (section 6) from the run folders of campaigns/weak_signal*.toml.

    benchmarks/validation/weak_signal_table.py OUT [OUT...]   (each the --out of a `campaign run`)

Per oscillator, trajectory, mode and C/N0 level, over the campaign's files: satellites kept after the step by the
receiver's own loss rule (lock_outcomes.csv: kept of kept + lost; not locked at the step and not acquired left out)
and by the common rule from the simulator's truth (truth_lock_outcomes.csv: kept of tracked), and the 3-D RMS of
solution.csv after the step per file (weak_rms_3d_m; '-' where a file had no fix after it). Reads only complete
runs; prints a markdown table. The campaign's own `campaign report` gives the same counts with intervals.
"""
import csv
import os
import sys
from collections import defaultdict


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


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


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
