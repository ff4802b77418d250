# SPDX-License-Identifier: GPL-3.0-or-later
"""A run's results on one HTML page: python3 -m ultratrack.report RUN_DIR [--truth truth.csv] [--out DIR] [--prn N]

Figures (matplotlib, Agg) from the files the run wrote, each skipped when its file is absent: the sky plot
(solution.nmea's GSV sentences, or snapshot.json's satellites), C/N0 per satellite vs time, tracking state with
lock/loss events and one satellite's prompt I/Q (tracking.csv), position on a local east/north map and errors
east/north/up vs time against a truth (solution.csv, nav.csv; truth.csv of the simulation), velocity, satellites used
and DOP (solution.csv), the ultra-tight filter's NIS and innovations (ultratight.csv) and the vector filter's
normalised innovations and NIS (vector.csv) with their bands, attitude with 1-sigma (attitude.csv, nav.csv,
alignment.csv), and the summary table (summary.json, snapshot.json or alignment.json). An attitude run's position
files are read from its position/ folder. Each figure is written as a PNG into the output folder (default:
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
ANGLES = ("roll_deg", "pitch_deg", "yaw_deg")


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
        # zlib level 1: a third less time to write than the default level, files ~3 % larger.
        fig.savefig(buffer, format="png", dpi=100, bbox_inches="tight", pil_kwargs={"compress_level": 1})
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

    if solution.size < 2:  # a snapshot's single fix: no time series
        return
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

    sigmas = {"roll_deg": "sigma_att_n_deg", "pitch_deg": "sigma_att_e_deg", "yaw_deg": "sigma_att_d_deg"}
    _attitude_panels(page, "nav_attitude", "GNSS/INS attitude with 1-sigma",
                     "GNSS/INS attitude (nav.csv) with 1-sigma", t,
                     {angle: (nav[angle], nav[sigma]) for angle, sigma in sigmas.items()},
                     None if truth is None else (truth["t_s"], truth), "t_s (s)")

    _time_series(page, "nav_velocity", "GNSS/INS velocity (nav.csv, NED)", t,
                 [(nav[c], c) for c in ("vel_n_mps", "vel_e_mps", "vel_d_mps")], "t_s (s)", "velocity (m/s)")


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


def _attitude_panels(page, name, title, figure_title, t, angles, truth, xlabel, final=None):
    """Roll, pitch and yaw against time, each with its 1-sigma band. angles: {angle: (values, sigmas)}; truth:
    (its times on the same axis, its rows) or None, drawn over the span of t; final: {angle: a final estimate}."""
    fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    for k, (angle, (value, sigma)) in enumerate(angles.items()):
        axes[k].plot(t, value, lw=0.8, label=angle)
        axes[k].fill_between(t, value - sigma, value + sigma, alpha=0.3, label="1-sigma")
        if final is not None and angle in final:
            axes[k].axhline(final[angle], color="k", lw=0.6, ls="--", label="final estimate")
        if truth is not None and angle in truth[1].dtype.names:
            at = (truth[0] >= t[0]) & (truth[0] <= t[-1])
            axes[k].plot(truth[0][at], truth[1][angle][at], "k", lw=0.8, label="truth")
        axes[k].set_ylabel(angle)
        axes[k].grid(True, alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[0].set_title(figure_title)
    axes[-1].set_xlabel(xlabel)
    page.add(name, title, fig)


def _attitude_figure(page, attitude, truth):
    t0 = attitude["tow_s"][0]
    _attitude_panels(page, "attitude", "Attitude with 1-sigma",
                     "Multi-antenna attitude (attitude.csv) with 1-sigma; %d of %d epochs fixed"
                     % (int(np.sum(attitude["fixed"])), attitude.size), attitude["tow_s"] - t0,
                     {angle: (attitude[angle], attitude["sigma_" + angle]) for angle in ANGLES},
                     None if truth is None else (truth["tow_s"] - t0, truth), "time since the first epoch (s)")


def _chi2_quantile(m, p):
    """The p-quantile of a chi-square of m degrees of freedom (Wilson-Hilferty; within ~1 % for m >= 1 at the 2.5 %
    and 97.5 % points, enough for a plotted band; scipy is not a dependency)."""
    z = {0.025: -1.959964, 0.975: 1.959964}[p]
    c = 2.0 / (9.0 * m)
    return m * max(1.0 - c + z * np.sqrt(c), 0.0) ** 3


def _sky_figure(page, sky, title, used=None):
    """Sky plot: azimuth clockwise from north, elevation 90 deg at the centre; each satellite's track over the run
    (a point for a snapshot), labelled with its PRN and coloured by C/N0."""
    fig = plt.figure(figsize=(6.5, 6))
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_rlim(0, 90)
    ax.set_rticks([15, 30, 45, 60, 75, 90], labels=["75", "60", "45", "30", "15", "0"])
    theta, r = np.radians(sky["azimuth_deg"]), 90.0 - sky["elevation_deg"]
    points = ax.scatter(theta, r, c=sky["cn0_dbhz"], cmap="viridis", s=12, vmin=30, vmax=50)
    for prn in np.unique(sky["prn"]):
        last = np.flatnonzero(sky["prn"] == prn)[-1]
        unused = used is not None and prn not in used
        ax.annotate("%d%s" % (prn, " (not used)" if unused else ""), (theta[last], r[last]), fontsize=8,
                    xytext=(4, 4), textcoords="offset points", color="tab:red" if unused else "k")
    fig.colorbar(points, ax=ax, shrink=0.7, pad=0.1, label="C/N0 (dB-Hz)")
    ax.set_title(title, pad=20)
    page.add("sky", "Sky plot", fig)


def _snapshot_sky(snapshot):
    rows = [(0, s["prn"], s["elevation_deg"], s["azimuth_deg"], s["cn0_dbhz"]) for s in snapshot.get("satellites", [])
            if "elevation_deg" in s]
    sky = np.array(rows, dtype=readers._GSV_DTYPE) if rows else None
    used = {s["prn"] for s in snapshot.get("satellites", []) if s.get("used")}
    return sky, used


def _snapshot_residuals(page, snapshot):
    """Each paired satellite's pseudorange residual with its 1-sigma (snapshot.json)."""
    sats = [s for s in snapshot.get("satellites", []) if "residual_m" in s]
    if not sats:
        return
    fig, ax = plt.subplots(figsize=(8, 3.5))
    x = np.arange(len(sats))
    colours = ["tab:blue" if s["used"] else "tab:red" for s in sats]
    ax.bar(x, [s["residual_m"] for s in sats], color=colours)
    ax.errorbar(x, np.zeros(len(sats)), yerr=[s["sigma_m"] for s in sats], fmt="none", ecolor="k", capsize=3,
                label="+-1 sigma")
    ax.set_xticks(x, ["PRN %d" % s["prn"] for s in sats], fontsize=8)
    ax.set_ylabel("residual (m)")
    ax.set_title("Snapshot pseudorange residuals (red: excluded), %s" % ("fix" if snapshot.get("valid")
                                                                         else "no fix: %s" % snapshot.get("failure")))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    page.add("snapshot_residuals", "Snapshot residuals", fig)


def _nis_bands(ax, m, label_prefix=""):
    lo, hi = _chi2_quantile(m, 0.025), _chi2_quantile(m, 0.975)
    ax.axhline(m, color="k", lw=1, label="%sE[NIS] = m = %d" % (label_prefix, m))
    ax.axhspan(lo, hi, color="tab:gray", alpha=0.2, label="%s95 %% band [%.2g, %.3g]" % (label_prefix, lo, hi))


def _ultratight_figures(page, rows):
    """NIS per satellite with the chi-square 95 % band of its dimension, and the innovations: with the I/Q form
    (six columns) in unit-noise units, so that +-1 and +-3 are bands; with the discriminator form (two) in m, m/s."""
    if "nis" not in rows.dtype.names:
        return
    innovations = [c for c in rows.dtype.names if c.startswith("innovation_")]
    updated = rows[np.isfinite(rows["nis"])]
    if not updated.size:
        return
    dims = sum(np.isfinite(updated[c]).astype(int) for c in innovations)
    m = int(np.round(np.median(dims))) if innovations else 0
    fig, ax = plt.subplots(figsize=(10, 4))
    for prn in np.unique(updated["prn"]):
        r = updated[updated["prn"] == prn]
        ax.plot(r["time_s"], r["nis"], ".", ms=2, label="PRN %d" % prn)
    if m:
        _nis_bands(ax, m)
        inside = np.mean((updated["nis"] >= _chi2_quantile(m, 0.025)) & (updated["nis"] <= _chi2_quantile(m, 0.975)))
    ax.set_yscale("log")
    ax.set_xlabel("time since the first sample (s)")
    ax.set_ylabel("NIS")
    ax.set_title("Ultra-tight filter NIS per satellite%s" % (" (%.0f %% inside the 95 %% band)" % (100 * inside)
                                                            if m else ""))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    page.add("ultratight_nis", "Ultra-tight filter NIS with its 95 % band", fig)

    used = [c for c in innovations if np.isfinite(updated[c]).any()]
    if not used:
        return
    iq = len(used) == 6
    names = ["I_E", "I_P", "I_L", "Q_E", "Q_P", "Q_L"] if iq else ["range (m)", "range rate (m/s)"]
    fig, axes = plt.subplots(len(used), 1, figsize=(10, 1.6 * len(used) + 1), sharex=True, squeeze=False)
    for k, c in enumerate(used):
        a = axes[k, 0]
        a.plot(updated["time_s"], updated[c], ".", ms=1.5, color="tab:blue")
        if iq:
            for level, style in ((1, "--"), (3, ":")):
                a.axhline(level, color="k", ls=style, lw=0.8)
                a.axhline(-level, color="k", ls=style, lw=0.8)
        a.set_ylabel(names[k] if k < len(names) else c, fontsize=8)
        a.grid(True, alpha=0.3)
    axes[0, 0].set_title("Ultra-tight filter innovations, all satellites (%s)" %
                         ("I/Q form, unit-noise units: bands +-1 (--) and +-3 (..)" if iq else "discriminator form"))
    axes[-1, 0].set_xlabel("time since the first sample (s)")
    page.add("ultratight_innovations", "Ultra-tight filter innovations", fig)


def _vector_nis_figure(page, rows):
    """Each channel's NIS of the vector filter, as the sum of its squared normalised pseudorange and pseudorange-rate
    innovations (epochs where both were used), with the chi-square 95 % band of dimension 2: a proxy, since
    vector.csv does not hold the two innovations' correlation."""
    needed = ("pr_used", "pr_innovation_m", "pr_sigma_m", "rate_used", "rate_innovation_mps", "rate_sigma_mps")
    if any(c not in rows.dtype.names for c in needed):
        return
    both = rows[(rows["pr_used"] == 1) & (rows["rate_used"] == 1) & (rows["pr_sigma_m"] > 0) &
                (rows["rate_sigma_mps"] > 0)]
    if not both.size:
        return
    nis = (both["pr_innovation_m"] / both["pr_sigma_m"]) ** 2 + (both["rate_innovation_mps"] / both["rate_sigma_mps"]) ** 2
    fig, ax = plt.subplots(figsize=(10, 4))
    for prn in np.unique(both["prn"]):
        at = both["prn"] == prn
        ax.plot(both["time_s"][at], nis[at], ".", ms=2, label="PRN %d" % prn)
    _nis_bands(ax, 2)
    inside = np.mean((nis >= _chi2_quantile(2, 0.025)) & (nis <= _chi2_quantile(2, 0.975)))
    ax.set_yscale("log")
    ax.set_xlabel("time since the first sample (s)")
    ax.set_ylabel("NIS (pseudorange + rate)")
    ax.set_title("Vector filter NIS per channel (%.0f %% inside the 95 %% band)" % (100 * inside))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    page.add("vector_nis", "Vector filter NIS with its 95 % band", fig)


def _alignment_figure(page, epochs, alignment, truth):
    """The alignment filter's attitude per epoch with its 1-sigma, the final estimate (alignment.json) and the truth's
    attitude on the IMU time line (t_s) when given."""
    t = epochs["t_s"]
    _attitude_panels(page, "alignment_attitude", "Alignment attitude with 1-sigma",
                     "Stationary alignment (alignment.csv) with 1-sigma; dashed: alignment.json", t,
                     {angle: (epochs[angle], epochs["sigma_" + angle]) for angle in ANGLES},
                     None if truth is None or "t_s" not in truth.dtype.names else (truth["t_s"], truth),
                     "IMU time t_s (s)", alignment)
    biases = [c for c in epochs.dtype.names if c.startswith(("accel_bias_", "gyro_bias_"))]
    if biases:
        fig, axes = plt.subplots(2, 1, figsize=(10, 5), sharex=True)
        for c in biases:
            axes[0 if c.startswith("accel") else 1].plot(t, epochs[c], lw=0.8, label=c)
        axes[0].set_ylabel("m/s^2")
        axes[1].set_ylabel("deg/h")
        for a in axes:
            a.grid(True, alpha=0.3)
            a.legend(fontsize=7)
        axes[0].set_title("Alignment bias estimates")
        axes[-1].set_xlabel("IMU time t_s (s)")
        page.add("alignment_biases", "Alignment bias estimates", fig)


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


def _optional_json(reader, path):
    try:
        return reader(path)
    except InputError:
        return None


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
    snapshot = _optional_json(readers.read_snapshot, run_dir)
    alignment = _optional_json(readers.read_alignment, run_dir)
    summary = _optional_json(readers.read_summary, run_dir)

    sky = _optional(readers.read_sky, run_dir)
    if sky is not None:
        _sky_figure(page, sky, "Satellites in view over the run (solution.nmea)")
    elif snapshot is not None:
        snapshot_sky, used = _snapshot_sky(snapshot)
        if snapshot_sky is not None:
            _sky_figure(page, snapshot_sky, "Satellites of the snapshot (snapshot.json)", used)
    tracking = _optional(readers.read_tracking, run_dir)
    if tracking is not None:
        _tracking_figures(page, tracking)
        _iq_figure(page, tracking, prn)
    solution = _optional(readers.read_solution, run_dir)
    if solution is not None:
        _solution_figures(page, solution, truth_rows)
    if snapshot is not None:
        _snapshot_residuals(page, snapshot)
    nav = _optional(readers.read_nav, run_dir)
    if nav is not None:
        _nav_figures(page, nav, truth_rows)
    ultratight = _optional(readers.read_ultratight, run_dir)
    if ultratight is not None:
        _ultratight_figures(page, ultratight)
    vector = _optional(readers.read_vector, run_dir)
    if vector is not None:
        _vector_innovation_figure(page, vector)
        _vector_nis_figure(page, vector)
    attitude = _optional(readers.read_attitude, run_dir)
    if attitude is not None:
        _attitude_figure(page, attitude, truth_rows)
    epochs = _optional(readers.read_alignment_epochs, run_dir)
    if epochs is not None:
        _alignment_figure(page, epochs, alignment, truth_rows)
    tables = [(name, data) for name, data in (("summary.json", summary), ("snapshot.json", snapshot),
                                              ("alignment.json", alignment)) if data is not None]

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
    for name, data in tables:
        parts.append("<h2 id=\"%s\">Summary (%s)</h2><table>" % (name.split(".")[0], name))
        parts += ["<tr><td>%s</td><td>%s</td></tr>" % (html.escape(k), html.escape(v))
                  for k, v in _summary_rows(data)]
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
