# SPDX-License-Identifier: GPL-3.0-or-later
"""A run's results on one HTML page: python3 -m ultratrack.report RUN_DIR [--truth truth.csv] [--out DIR] [--prn N]

Figures (matplotlib, Agg) from the files the run wrote, each skipped when its file is absent: C/N0 per satellite
vs time, tracking state with lock/loss events and one satellite's prompt I/Q (tracking.csv), position on a local east/north map, errors
east/north/up vs time against a truth (solution.csv, nav.csv; truth.csv of the simulation), velocity, satellites
used and DOP (solution.csv), NIS (ultratight.csv) and normalised innovations (vector.csv), attitude with 1-sigma (attitude.csv,
nav.csv), and the summary table (summary.json). Each figure is written as a PNG into the output folder (default:
RUN_DIR/report) and embedded in report.html, which therefore stands alone.
"""
import argparse
import base64
import html
import io
import json
import os
import sys

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from . import readers  # noqa: E402
from ._ultratrack import InputError  # noqa: E402

_A = 6378137.0                  # WGS-84 semi-major axis, m
_E2 = 6.69437999014e-3          # WGS-84 first eccentricity squared


def _ecef(lat_deg, lon_deg, h_m):
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    n = _A / np.sqrt(1.0 - _E2 * np.sin(lat) ** 2)
    return np.stack([(n + h_m) * np.cos(lat) * np.cos(lon), (n + h_m) * np.cos(lat) * np.sin(lon),
                     (n * (1.0 - _E2) + h_m) * np.sin(lat)], axis=-1)


def _enu_rotation(lat_deg, lon_deg):
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    return np.array([[-np.sin(lon), np.cos(lon), 0.0],
                     [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)],
                     [np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)]])


def _optional(reader, path):
    try:
        rows = reader(path)
    except InputError:
        return None
    return rows if rows.size else None


class _Page:
    """The figures made so far: (name, title, PNG bytes)."""

    def __init__(self, out_dir):
        self.out_dir = out_dir
        self.figures = []

    def add(self, name, title, fig):
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=100, bbox_inches="tight")
        plt.close(fig)
        png = buffer.getvalue()
        with open(os.path.join(self.out_dir, name + ".png"), "wb") as f:
            f.write(png)
        self.figures.append((name, title, png))


def _time_series(page, name, title, t, series, xlabel, ylabel):
    """One figure of curves against time: series is a list of (values, label)."""
    fig, ax = plt.subplots(figsize=(10, 4))
    for values, label in series:
        ax.plot(t, values, lw=0.8, label=label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    page.add(name, title, fig)


def _tracking_figures(page, tracking):
    prns = np.unique(tracking["prn"])
    fig, ax = plt.subplots(figsize=(10, 4.5))
    for prn in prns:
        rows = tracking[tracking["prn"] == prn]
        ax.plot(rows["time_s"], rows["cn0_dbhz"], lw=0.8, label="PRN %d" % prn)
    ax.set_xlabel("time since the first sample (s)")
    ax.set_ylabel("C/N0 (dB-Hz)")
    ax.set_title("C/N0 per satellite")
    ax.grid(True, alpha=0.3)
    ax.legend(ncol=1 + len(prns) // 16, fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    page.add("cn0", "C/N0 per satellite", fig)

    if "state" not in tracking.dtype.names:
        return
    states = ["pull-in", "phase-locked", "bit-synced", "coasting", "lost"]
    colours = {"pull-in": "tab:orange", "phase-locked": "tab:blue", "bit-synced": "tab:green",
               "coasting": "tab:purple", "lost": "tab:red"}
    fig, ax = plt.subplots(figsize=(10, 0.35 * len(prns) + 1.5))
    for i, prn in enumerate(prns):
        rows = tracking[tracking["prn"] == prn]
        for state in states:
            at = rows["state"] == state
            if at.any():
                ax.scatter(rows["time_s"][at], np.full(at.sum(), i), s=4, marker="|", color=colours[state],
                           label=state if i == 0 or state not in ax.get_legend_handles_labels()[1] else None)
        if "phase_locked" in rows.dtype.names:
            locked = rows["phase_locked"].astype(int)
            losses = np.flatnonzero((locked[:-1] == 1) & (locked[1:] == 0)) + 1
            gains = np.flatnonzero((locked[:-1] == 0) & (locked[1:] == 1)) + 1
            ax.scatter(rows["time_s"][gains], np.full(gains.size, i + 0.3), marker="^", color="k", s=18,
                       label="lock" if "lock" not in ax.get_legend_handles_labels()[1] else None)
            ax.scatter(rows["time_s"][losses], np.full(losses.size, i + 0.3), marker="x", color="r", s=22,
                       label="loss of lock" if "loss of lock" not in ax.get_legend_handles_labels()[1] else None)
    ax.set_yticks(range(len(prns)), ["PRN %d" % p for p in prns])
    ax.set_xlabel("time since the first sample (s)")
    ax.set_title("Tracking state, phase lock gained (^) and lost (x)")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0), markerscale=3)
    page.add("tracking_state", "Tracking state and lock/loss events", fig)


def _iq_figure(page, tracking, prn):
    """Prompt I/Q of one satellite (the one with most rows when prn is None): a phase-locked channel's points lie
    along I, split by the data bit; bit-synced rows only when there are any (one integration length)."""
    if not all(c in tracking.dtype.names for c in ("prompt_i", "prompt_q")):
        return
    if prn is None:
        prns, counts = np.unique(tracking["prn"], return_counts=True)
        prn = int(prns[np.argmax(counts)])
    rows = tracking[tracking["prn"] == prn]
    if not rows.size:
        return
    if "state" in rows.dtype.names and (rows["state"] == "bit-synced").any():
        rows = rows[rows["state"] == "bit-synced"]
    fig, ax = plt.subplots(figsize=(5.5, 5.5))
    ax.plot(rows["prompt_i"], rows["prompt_q"], ".", ms=2)
    limit = 1.05 * np.nanmax(np.abs(np.concatenate([rows["prompt_i"], rows["prompt_q"]])))
    ax.set_xlim(-limit, limit)
    ax.set_ylim(-limit, limit)
    ax.set_aspect("equal")
    ax.set_xlabel("prompt I")
    ax.set_ylabel("prompt Q")
    ax.set_title("Prompt I/Q of PRN %d (%d epochs)" % (prn, rows.size))
    ax.grid(True, alpha=0.3)
    page.add("prompt_iq", "Prompt I/Q of PRN %d" % prn, fig)


def _truth_ecef_at(truth, tow_s):
    """The truth's ECEF position interpolated at GPS times of week (nan outside it)."""
    order = np.argsort(truth["tow_s"])
    t = truth["tow_s"][order]
    columns = [np.interp(tow_s, t, truth[c][order], left=np.nan, right=np.nan)
               for c in ("ecef_x_m", "ecef_y_m", "ecef_z_m")]
    return np.stack(columns, axis=-1)


def _solution_figures(page, solution, truth):
    t = solution["tow_s"] - solution["tow_s"][0]
    origin = (truth["lat_deg"][0], truth["lon_deg"][0], truth["height_m"][0]) if truth is not None else \
        (solution["lat_deg"][0], solution["lon_deg"][0], solution["height_m"][0])
    r_enu = _enu_rotation(origin[0], origin[1])
    ecef = np.stack([solution["ecef_x_m"], solution["ecef_y_m"], solution["ecef_z_m"]], axis=-1)
    enu = (ecef - _ecef(*origin)) @ r_enu.T

    fig, ax = plt.subplots(figsize=(6, 6))
    ax.plot(enu[:, 0], enu[:, 1], ".", ms=2, label="solution.csv")
    if truth is not None:
        truth_enu = (np.stack([truth["ecef_x_m"], truth["ecef_y_m"], truth["ecef_z_m"]], axis=-1) - _ecef(*origin)) \
            @ r_enu.T
        ax.plot(truth_enu[:, 0], truth_enu[:, 1], "-", lw=1, color="k", label="truth")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title("Position on a local map (origin %.6f, %.6f deg)" % origin[:2])
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    page.add("position_map", "Position on a local east/north map", fig)

    if truth is not None:
        truth_at = _truth_ecef_at(truth, solution["tow_s"])
        errors = np.array([_enu_rotation(la, lo) @ d for la, lo, d in
                           zip(solution["lat_deg"], solution["lon_deg"], ecef - truth_at)])
        _time_series(page, "position_error", "Position error of solution.csv against the truth", t,
                     [(errors[:, k], "%s (RMS %.2f m)" % (axis, np.sqrt(np.nanmean(errors[:, k] ** 2))))
                      for k, axis in enumerate(("east", "north", "up"))], "time since the first fix (s)", "error (m)")

    _time_series(page, "velocity", "Velocity of solution.csv (east, north, up)", t,
                 [(solution[c], label) for c, label in (("vel_e_mps", "east"), ("vel_n_mps", "north"),
                                                        ("vel_u_mps", "up"))],
                 "time since the first fix (s)", "velocity (m/s)")

    fig, ax = plt.subplots(figsize=(10, 4))
    ax.step(t, solution["num_sats"], where="post", color="k", label="satellites used")
    ax.set_xlabel("time since the first fix (s)")
    ax.set_ylabel("satellites used")
    ax2 = ax.twinx()
    for c in ("pdop", "hdop", "vdop"):
        ax2.plot(t, solution[c], lw=0.8, label=c.upper())
    ax2.set_ylabel("DOP")
    ax.set_title("Satellites used and dilution of precision")
    ax.grid(True, alpha=0.3)
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], fontsize=8, loc="lower right")
    page.add("satellites_dop", "Satellites used and DOP", fig)


def _nav_figures(page, nav, truth):
    t = nav["t_s"]
    if truth is not None and "t_s" in truth.dtype.names:
        ecef = _ecef(nav["lat_deg"], nav["lon_deg"], nav["height_m"])
        order = np.argsort(truth["t_s"])
        truth_at = np.stack([np.interp(t, truth["t_s"][order], truth[c][order], left=np.nan, right=np.nan)
                             for c in ("ecef_x_m", "ecef_y_m", "ecef_z_m")], axis=-1)
        r = _enu_rotation(nav["lat_deg"][0], nav["lon_deg"][0])
        errors = (ecef - truth_at) @ r.T
        sigma = {"east": nav["sigma_e_m"], "north": nav["sigma_n_m"], "up": nav["sigma_d_m"]}
        fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
        for k, axis in enumerate(("east", "north", "up")):
            axes[k].plot(t, errors[:, k], lw=0.8, label="error")
            axes[k].fill_between(t, -sigma[axis], sigma[axis], color="tab:gray", alpha=0.3, label="1-sigma")
            axes[k].set_ylabel("%s (m)" % axis)
            axes[k].grid(True, alpha=0.3)
        axes[0].legend(fontsize=8)
        axes[0].set_title("GNSS/INS (nav.csv) position error against the truth, with the filter's 1-sigma")
        axes[-1].set_xlabel("t_s (s)")
        page.add("nav_position_error", "GNSS/INS position error with 1-sigma", fig)

    fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    for k, (angle, sigma) in enumerate((("roll_deg", "sigma_att_n_deg"), ("pitch_deg", "sigma_att_e_deg"),
                                        ("yaw_deg", "sigma_att_d_deg"))):
        axes[k].plot(t, nav[angle], lw=0.8, label=angle)
        axes[k].fill_between(t, nav[angle] - nav[sigma], nav[angle] + nav[sigma], alpha=0.3, label="1-sigma")
        if truth is not None and angle in truth.dtype.names:
            axes[k].plot(truth["t_s"], truth[angle], "k", lw=0.6, label="truth")
        axes[k].set_ylabel(angle)
        axes[k].grid(True, alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[0].set_title("GNSS/INS attitude (nav.csv) with 1-sigma")
    axes[-1].set_xlabel("t_s (s)")
    page.add("nav_attitude", "GNSS/INS attitude with 1-sigma", fig)

    _time_series(page, "nav_velocity", "GNSS/INS velocity (nav.csv, NED)", t,
                 [(nav[c], c) for c in ("vel_n_mps", "vel_e_mps", "vel_d_mps")], "t_s (s)", "velocity (m/s)")


def _nis_figure(page, rows, name, title):
    """Each satellite's normalised innovation squared, with its expectation: the measurement's dimension m (the
    innovation_k columns it fills), E[NIS] = m for a consistent filter."""
    if "nis" not in rows.dtype.names:
        return
    innovations = [c for c in rows.dtype.names if c.startswith("innovation_")]
    fig, ax = plt.subplots(figsize=(10, 4))
    for prn in np.unique(rows["prn"]):
        r = rows[(rows["prn"] == prn) & np.isfinite(rows["nis"])]
        if r.size:
            ax.plot(r["time_s"], r["nis"], ".", ms=2, label="PRN %d" % prn)
    updated = rows[np.isfinite(rows["nis"])]
    if innovations and updated.size:
        m = np.mean(sum(np.isfinite(updated[c]).astype(int) for c in innovations))
        ax.axhline(m, color="k", lw=1, label="E[NIS] = m = %.3g" % m)
    ax.set_yscale("log")
    ax.set_xlabel("time since the first sample (s)")
    ax.set_ylabel("NIS")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    page.add(name, title, fig)


def _vector_innovation_figure(page, rows):
    """The vector filter's pseudorange innovations over their predicted 1-sigma, with the +-1 and +-3 bands."""
    needed = ("pr_used", "pr_innovation_m", "pr_sigma_m")
    if any(c not in rows.dtype.names for c in needed):
        return
    used = rows[(rows["pr_used"] == 1) & (rows["pr_sigma_m"] > 0)]
    if not used.size:
        return
    fig, ax = plt.subplots(figsize=(10, 4))
    for prn in np.unique(used["prn"]):
        r = used[used["prn"] == prn]
        ax.plot(r["time_s"], r["pr_innovation_m"] / r["pr_sigma_m"], ".", ms=2, label="PRN %d" % prn)
    for k, style in ((1, "--"), (3, ":")):
        ax.axhline(k, color="k", ls=style, lw=1, label="+-%d sigma" % k)
        ax.axhline(-k, color="k", ls=style, lw=1)
    ax.set_xlabel("time since the first sample (s)")
    ax.set_ylabel("innovation / sigma")
    ax.set_title("Vector filter pseudorange innovations, normalised")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    page.add("vector_innovations", "Vector filter normalised pseudorange innovations", fig)


def _attitude_figure(page, attitude, truth):
    t = attitude["tow_s"] - attitude["tow_s"][0]
    fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    for k, angle in enumerate(("roll_deg", "pitch_deg", "yaw_deg")):
        value, sigma = attitude[angle], attitude["sigma_" + angle]
        axes[k].plot(t, value, lw=0.8, label=angle)
        axes[k].fill_between(t, value - sigma, value + sigma, alpha=0.3, label="1-sigma")
        if truth is not None and angle in truth.dtype.names:
            axes[k].plot(truth["tow_s"] - attitude["tow_s"][0], truth[angle], "k", lw=0.6, label="truth")
            axes[k].set_xlim(t[0], t[-1])
        axes[k].set_ylabel(angle)
        axes[k].grid(True, alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[0].set_title("Multi-antenna attitude (attitude.csv) with 1-sigma; %d of %d epochs fixed"
                      % (int(np.sum(attitude["fixed"])), attitude.size))
    axes[-1].set_xlabel("time since the first epoch (s)")
    page.add("attitude", "Attitude with 1-sigma", fig)


def _summary_rows(summary, prefix=""):
    rows = []
    for key, value in summary.items():
        if isinstance(value, dict):
            rows += _summary_rows(value, prefix + key + ".")
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            rows.append((prefix + key, "%d entries" % len(value)))
        else:
            rows.append((prefix + key, json.dumps(value)))
    return rows


def make_report(run_dir, truth=None, out_dir=None, prn=None):
    """Writes report.html and its PNG figures into out_dir (default RUN_DIR/report); returns the HTML's path.
    prn: the satellite of the prompt I/Q figure (default: the one tracked longest)."""
    run_dir = os.fspath(run_dir)
    if not os.path.isdir(run_dir):
        raise InputError(run_dir + ": not a folder")
    out_dir = os.fspath(out_dir) if out_dir else os.path.join(run_dir, "report")
    os.makedirs(out_dir, exist_ok=True)
    truth_rows = readers.read_truth(truth) if truth else None
    page = _Page(out_dir)

    tracking = _optional(readers.read_tracking, run_dir)
    if tracking is not None:
        _tracking_figures(page, tracking)
        _iq_figure(page, tracking, prn)
    solution = _optional(readers.read_solution, run_dir)
    if solution is not None:
        _solution_figures(page, solution, truth_rows)
    nav = _optional(readers.read_nav, run_dir)
    if nav is not None:
        _nav_figures(page, nav, truth_rows)
    ultratight = _optional(readers.read_ultratight, run_dir)
    if ultratight is not None:
        _nis_figure(page, ultratight, "ultratight_nis", "Ultra-tight filter NIS per satellite")
    vector = _optional(readers.read_vector, run_dir)
    if vector is not None:
        _vector_innovation_figure(page, vector)
    attitude = _optional(readers.read_attitude, run_dir)
    if attitude is not None:
        _attitude_figure(page, attitude, truth_rows)
    try:
        summary = readers.read_summary(run_dir)
    except InputError:
        summary = None

    parts = ["<!DOCTYPE html>", "<html><head><meta charset=\"utf-8\">",
             "<title>Ultratrack report: %s</title>" % html.escape(run_dir),
             "<style>body{font-family:sans-serif;margin:2em;max-width:1100px}img{max-width:100%}"
             "table{border-collapse:collapse}td{border:1px solid #ccc;padding:2px 6px;font-size:90%}</style>",
             "</head><body>", "<h1>Ultratrack report</h1>",
             "<p>Run folder: <code>%s</code>%s</p>" % (html.escape(run_dir), "; truth: <code>%s</code>"
                                                         % html.escape(os.fspath(truth)) if truth else "")]
    if not page.figures:
        parts.append("<p>No file of this folder has a figure.</p>")
    for name, title, png in page.figures:
        parts.append("<h2 id=\"%s\">%s</h2>" % (name, html.escape(title)))
        parts.append("<p><img alt=\"%s.png\" src=\"data:image/png;base64,%s\"><br><a href=\"%s.png\">%s.png</a></p>"
                     % (name, base64.b64encode(png).decode("ascii"), name, name))
    if summary is not None:
        parts.append("<h2 id=\"summary\">Summary (summary.json)</h2><table>")
        parts += ["<tr><td>%s</td><td>%s</td></tr>" % (html.escape(k), html.escape(v))
                  for k, v in _summary_rows(summary)]
        parts.append("</table>")
    parts.append("</body></html>")
    path = os.path.join(out_dir, "report.html")
    with open(path, "w") as f:
        f.write("\n".join(parts) + "\n")
    return path


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m ultratrack.report", description=__doc__.split("\n\n")[0])
    parser.add_argument("run_dir", help="the output folder of a run (receive, fuse, attitude, ...)")
    parser.add_argument("--truth", help="truth.csv of the simulation: position errors against it")
    parser.add_argument("--out", help="folder for report.html and its figures (default RUN_DIR/report)")
    parser.add_argument("--prn", type=int, help="satellite of the prompt I/Q figure (default: tracked longest)")
    args = parser.parse_args(argv)
    try:
        path = make_report(args.run_dir, args.truth, args.out, args.prn)
    except InputError as e:
        print("ultratrack.report: %s" % e, file=sys.stderr)
        return 2
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
