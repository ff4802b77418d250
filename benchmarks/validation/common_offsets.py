#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""How far all of an ultra-tight run's replicas run from the filter's prediction together: the common mode that the
carrier-runaway test (each channel against the median of all) cannot see (docs/validation.md, section 6).

    benchmarks/validation/common_offsets.py CAMPAIGN_OUT [CAMPAIGN_OUT...]   (weak_signal*, their runs/NNNN)

Per vector epoch of ultratight.csv with at least 4 channels: the median of the channels' carrier offsets (replica
carrier minus the filter's predicted Doppler). Its 1 s block means from 17 s on (after the C/N0 step at 16 s); per
run the largest |block mean|, in Hz, with the run's mode, C/N0 and seed and how many satellites the simulator's truth
rule lost (truth_lock_outcomes.csv). Prints the ultra-tight runs, largest first, and the largest below and at or
above 20 dB-Hz.
"""
import csv
import os
import statistics
import sys
from collections import defaultdict


def largest_common_offset(run):
    epochs = defaultdict(list)
    for r in csv.DictReader(open(os.path.join(run, "rx", "ultratight.csv"))):
        offset = float(r["carrier_offset_hz"])
        t = float(r["time_s"])
        if offset == offset and t >= 17.0:
            epochs[r["sample"]].append((t, offset))
    blocks = defaultdict(list)
    for channels in epochs.values():
        if len(channels) >= 4:
            blocks[int(channels[0][0])].append(statistics.median(v for _, v in channels))
    return max(((abs(statistics.mean(v)), second) for second, v in blocks.items()), default=(0.0, 0))


def main(outs):
    rows = []
    for out in outs:
        runs = os.path.join(out, "runs")
        for name in sorted(os.listdir(runs)):
            run = os.path.join(runs, name)
            p = dict(csv.reader(open(os.path.join(run, "parameters.csv"))))
            if not p.get("mode", "").startswith("ut-") or not os.path.exists(os.path.join(run, "rx", "ultratight.csv")):
                continue
            lost = sum(1 for r in csv.DictReader(open(os.path.join(run, "truth_lock_outcomes.csv")))
                       if r["outcome"] == "lost")
            hz, second = largest_common_offset(run)
            rows.append((hz, second, float(p["cn0_dbhz"]), p.get("trajectory", ""), p["mode"], p.get("seed", ""), lost,
                         run))
    rows.sort(reverse=True)
    print("max |1 s mean| Hz  at s  C/N0  trajectory  mode  seed  lost  run")
    for hz, second, cn0, trajectory, mode, seed, lost, run in rows:
        print(f"{hz:8.2f} {second:5d} {cn0:5.1f}  {trajectory:8s} {mode:14s} {seed:>4s} {lost:3d}  {run}")
    for label, keep in (("below 20 dB-Hz", lambda c: c < 20.0), ("at or above 20 dB-Hz", lambda c: c >= 20.0)):
        chosen = [r for r in rows if keep(r[2])]
        if chosen:
            print(f"{label}: {len(chosen)} runs, largest {chosen[0][0]:.2f} Hz")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
