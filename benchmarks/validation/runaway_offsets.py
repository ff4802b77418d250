#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""How far an ultra-tight channel's carrier runs from the others', for the carrier-runaway test's threshold
(pipelines/ultratight_loop.hpp: runaway_relative_hz; docs/validation.md, section 6).

    benchmarks/validation/runaway_offsets.py RUN_DIR [RUN_DIR...]   (campaign runs: runs/NNNN of weak_signal_told*)

Per vector epoch of ultratight.csv: each channel's carrier offset (replica carrier minus the filter's predicted
Doppler), less the median offset of the epoch's channels (at least 4) below 30 dB-Hz: the channel's own offset, as the
runaway test forms it. Its 1 s block means (whole seconds from 17 s, after the C/N0 step at 16 s; blocks with at least
25 epochs) are split by the simulator's verdict (truth_lock_outcomes.csv): satellites kept to the end, and those
lost, up to the second before their loss. Prints the percentiles of |block mean| of the kept, and for each lost
satellite its largest |block mean| before the loss, in Hz.
"""
import csv
import os
import statistics
import sys
from collections import defaultdict


def block_means(run):
    outcomes = list(csv.DictReader(open(os.path.join(run, "truth_lock_outcomes.csv"))))
    verdict = {int(r["prn"]): r["outcome"] for r in outcomes}
    lost_s = {int(r["prn"]): float(r["lost_s"]) for r in outcomes if r["outcome"] == "lost"}
    epochs = defaultdict(dict)
    for r in csv.DictReader(open(os.path.join(run, "rx", "ultratight.csv"))):
        offset = float(r["carrier_offset_hz"])
        if offset == offset and float(r["cn0_dbhz"]) < 30.0:
            epochs[r["sample"]][int(r["prn"])] = (float(r["time_s"]), offset)
    blocks = defaultdict(list)
    for channels in epochs.values():
        if len(channels) < 4:
            continue
        median = statistics.median(v for _, v in channels.values())
        for prn, (t, v) in channels.items():
            blocks[(prn, int(t))].append(v - median)
    kept, lost = [], defaultdict(float)
    for (prn, second), values in blocks.items():
        if second < 17 or len(values) < 25:
            continue
        mean = abs(sum(values) / len(values))
        if verdict.get(prn) == "kept":
            kept.append(mean)
        elif prn in lost_s and second + 1 <= lost_s[prn]:
            lost[prn] = max(lost[prn], mean)
    return kept, list(lost.values())


def main(runs):
    kept, lost = [], []
    for run in runs:
        k, l = block_means(run)
        kept += k
        lost += l
    if not kept:
        sys.exit("no kept channel-seconds below 30 dB-Hz in these runs")
    kept.sort()
    n = len(kept)
    pct = lambda q: kept[min(n - 1, int(q * n))]
    print(f"kept: {n} channel-seconds; |1 s mean own offset| p50 {pct(0.5):.2f}, p99 {pct(0.99):.2f}, "
          f"p99.9 {pct(0.999):.2f}, max {kept[-1]:.2f} Hz; above 1 Hz: {sum(v > 1.0 for v in kept)}")
    lost.sort()
    print(f"lost: {len(lost)} satellites; each one's largest before the loss: " + " ".join(f"{v:.2f}" for v in lost))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
