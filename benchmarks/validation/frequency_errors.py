#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Each channel's carrier frequency error against the simulator's truth over time, for reading how a weak-signal run
lost its satellites (docs/validation.md, section 6).

    benchmarks/validation/frequency_errors.py RUN_DIR T0 T1 [STEP_S]   (a campaign run: runs/NNNN)
    benchmarks/validation/frequency_errors.py --ringing RUN_DIR T0 T1

Per row of rx/tracking.csv from T0 to T1 s: its Doppler (the replica's carrier frequency) minus the truth's Doppler
of that satellite (sim/satellite_truth.csv, interpolated linearly), averaged per PRN over STEP_S (default 0.2 s).
Prints one line per interval: the start time, each PRN's mean error in Hz (nan: no row) and their median.

--ringing: the common part of those errors (their median over the PRNs per 20 ms, intervals with 4 or more) as one
series: its RMS (Hz) and its autocorrelation at lags of 0.1 and 0.2 s (a loop ringing at ~2.5-3 Hz reads strongly
negative at 0.2 s; docs/validation.md, section 16).
"""
import bisect
import csv
import statistics
import sys
from collections import defaultdict


def main(run, t0, t1, step, ringing=False):
    truth = defaultdict(list)
    for r in csv.DictReader(open(run + "/sim/satellite_truth.csv")):
        truth[int(r["prn"])].append((float(r["t_s"]), float(r["doppler_hz"])))
    times = {prn: [t for t, _ in rows] for prn, rows in truth.items()}

    def doppler(prn, t):
        rows = truth[prn]
        k = min(max(bisect.bisect(times[prn], t), 1), len(rows) - 1)
        (ta, da), (tb, db) = rows[k - 1], rows[k]
        return da + (db - da) * (t - ta) / (tb - ta)

    bins = defaultdict(lambda: defaultdict(list))
    for r in csv.DictReader(open(run + "/rx/tracking.csv")):
        t = float(r["time_s"])
        prn = int(r["prn"])
        if t0 <= t <= t1 and prn in truth:
            bins[int((t - t0) / step)][prn].append(float(r["doppler_hz"]) - doppler(prn, t))
    if ringing:
        series = [statistics.median([statistics.mean(v) for v in bins[k].values()]) for k in sorted(bins)
                  if len(bins[k]) >= 4]
        mean = statistics.fmean(series)
        var = sum((x - mean) ** 2 for x in series)

        def autocorrelation(lag):
            return sum((series[i] - mean) * (series[i + lag] - mean) for i in range(len(series) - lag)) / var

        rms = (sum(x * x for x in series) / len(series)) ** 0.5
        print(f"{run}: {len(series)} epochs, common error RMS {rms:.2f} Hz, autocorrelation "
              f"{autocorrelation(round(0.1 / step)):+.2f} at 0.1 s, {autocorrelation(round(0.2 / step)):+.2f} at 0.2 s")
        return
    prns = sorted({prn for b in bins.values() for prn in b})
    print("t_s   " + " ".join(f"{prn:6d}" for prn in prns) + "   median")
    for k in sorted(bins):
        row = [statistics.mean(bins[k][prn]) if bins[k].get(prn) else float("nan") for prn in prns]
        finite = [x for x in row if x == x]
        median = statistics.median(finite) if finite else float("nan")
        print(f"{t0 + k * step:5.1f} " + " ".join(f"{x:6.2f}" for x in row) + f"  {median:6.2f}")


if __name__ == "__main__":
    args = sys.argv[1:]
    ringing = bool(args) and args[0] == "--ringing"
    if ringing:
        args = args[1:]
    if len(args) < 3:
        sys.exit(__doc__)
    step = 0.02 if ringing else (float(args[3]) if len(args) > 3 else 0.2)
    main(args[0], float(args[1]), float(args[2]), step, ringing)
