#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Seed 004 Table 1 over many drives: is one yaw-rate threshold better than its neighbours beyond the drive-to-drive
spread? Reads a finished `campaign run campaigns/odometer_loop_seeds.toml --out DIR` (each run's parameters.csv and
complete.csv) and prints, per threshold, the mean of a metric over the seeds and its paired difference against a
reference threshold (the same seed, so the same drive and IMU draw), with the standard error of that difference.

    benchmarks/validation/odometer_threshold_pairs.py DIR [--metric horizontal_max_m] [--reference 1.50]
"""
import argparse
import csv
import math
import os
import statistics
import sys


def read_pairs(path):
    with open(path, newline="") as f:
        return {row["name"]: row["value"] for row in csv.DictReader(f)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("campaign_dir")
    ap.add_argument("--metric", default="horizontal_max_m")
    ap.add_argument("--reference", default="1.50")
    a = ap.parse_args()
    runs_dir = os.path.join(a.campaign_dir, "runs")
    if not os.path.isdir(runs_dir):
        sys.exit(f"odometer_threshold_pairs.py: {runs_dir}: no campaign runs there")
    by_threshold = {}  # threshold label -> {seed: value}
    for name in sorted(os.listdir(runs_dir)):
        done = os.path.join(runs_dir, name, "complete.csv")
        if not os.path.isfile(done):
            continue
        p = read_pairs(os.path.join(runs_dir, name, "parameters.csv"))
        v = read_pairs(done)
        if a.metric not in v:
            sys.exit(f"odometer_threshold_pairs.py: {done}: no metric '{a.metric}'")
        by_threshold.setdefault(p["threshold_dps"], {})[p["seed"]] = float(v[a.metric])
    if a.reference not in by_threshold:
        sys.exit(f"odometer_threshold_pairs.py: no runs at the reference threshold {a.reference}")
    ref = by_threshold[a.reference]
    print(f"| threshold | seeds | mean {a.metric} | minus {a.reference} (paired): mean +- standard error |")
    print("|---|---|---|---|")
    for label, values in by_threshold.items():
        seeds = sorted(set(values) & set(ref), key=int)
        d = [values[s] - ref[s] for s in seeds]
        se = statistics.stdev(d) / math.sqrt(len(d)) if len(d) > 1 else float("nan")
        diff = "-" if label == a.reference else f"{statistics.mean(d):+.3f} +- {se:.3f}"
        print(f"| {label} | {len(values)} | {statistics.mean(values.values()):.3f} | {diff} |")


if __name__ == "__main__":
    main()
