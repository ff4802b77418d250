# SPDX-License-Identifier: GPL-3.0-or-later
"""Readers of the files a run writes, as numpy structured arrays (one field per CSV column, named by the header).

Every reader takes the file itself or the run's folder (then the file's usual name in it; an attitude run's position
solution is in position/). Columns of numbers are float64 (int64 when every value is an integer), other columns
text. A missing or malformed file raises ultratrack.InputError naming it, like the library's readers.
"""
import csv
import json
import os
import re

import numpy as np

from ._ultratrack import InputError

__all__ = ["read_csv", "read_solution", "read_tracking", "read_nav", "read_vector", "read_vector_state",
           "read_ultratight", "read_attitude", "read_antenna_phases", "read_truth", "read_satellites", "read_imu",
           "read_summary", "read_snapshot", "read_alignment", "read_alignment_epochs", "read_sky", "find_output"]

_INT = re.compile(r"^[+-]?\d+$")
_SNIFF_ROWS = 500


def _column_type(values):
    values = list(values)
    if values and all(_INT.match(v) for v in values):
        return "i8"
    try:
        for v in values:
            float(v)  # accepts nan, inf
        return "f8"
    except ValueError:
        width = max([len(v) for v in values] + [1])
        return "U%d" % max(64, 4 * width)  # room for longer text in rows after the sniffed ones


def _read_slow(path, names):
    # Every row through the csv module: for files whose later rows do not fit the types of the first ones.
    with open(path, newline="") as f:
        rows = list(csv.reader(f))[1:]
    columns = list(zip(*rows)) if rows else [[] for _ in names]
    dtype = [(n, _column_type(c)) for n, c in zip(names, columns)]
    return np.array([tuple(r) for r in rows], dtype=dtype) if rows else np.zeros(0, dtype=dtype)


def read_csv(path):
    """Any CSV file of a run (a header line, then comma-separated rows) as a numpy structured array."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise InputError(path + ": file not found")
    with open(path, newline="") as f:
        reader = csv.reader(f)
        try:
            names = next(reader)
        except StopIteration:
            raise InputError(path + ": empty file (no header line)")
        head = [row for _, row in zip(range(_SNIFF_ROWS), reader)]
    if any(len(r) != len(names) for r in head):
        raise InputError(path + ": rows with a number of fields other than the header's %d" % len(names))
    columns = list(zip(*head)) if head else [[] for _ in names]
    dtype = [(n, _column_type(c) if head else "f8") for n, c in zip(names, columns)]
    if not head:
        return np.zeros(0, dtype=dtype)
    try:
        return np.atleast_1d(np.loadtxt(path, delimiter=",", skiprows=1, dtype=dtype, comments=None, ndmin=1))
    except ValueError:
        try:
            return _read_slow(path, names)
        except ValueError as e:
            raise InputError("%s: %s" % (path, e))


def find_output(path, name, subfolders=("position",)):
    """`path` itself when it is a file (or names a missing one: it has an extension); else path/name, or
    path/<subfolder>/name when only that exists."""
    path = os.fspath(path)
    if os.path.isfile(path) or (not os.path.isdir(path) and os.path.splitext(path)[1]):
        return path
    candidates = [os.path.join(path, name)] + [os.path.join(path, s, name) for s in subfolders]
    for c in candidates:
        if os.path.isfile(c):
            return c
    return candidates[0]


def read_solution(path):
    """solution.csv: gps_week, tow_s, lat_deg, lon_deg, height_m, ecef_*_m, vel_e/n/u_mps, clock, num_sats, DOPs."""
    return read_csv(find_output(path, "solution.csv"))


def read_tracking(path):
    """tracking.csv: prn, sample, time_s, prompt I/Q, cn0_dbhz, doppler_hz, code phase, state, lock flags."""
    return read_csv(find_output(path, "tracking.csv"))


def read_nav(path):
    """nav.csv of a GNSS/INS run (fuse, receive loose/tight/ultra-tight): t_s, position, NED velocity, attitude, sigmas."""
    return read_csv(find_output(path, "nav.csv"))


def read_vector(path):
    """vector.csv of receive --coupling vector: per channel and epoch, measurements and the filter's predictions."""
    return read_csv(find_output(path, "vector.csv"))


def read_vector_state(path):
    """vector_state.csv of receive --coupling vector: the vector filter's state per epoch."""
    return read_csv(find_output(path, "vector_state.csv"))


def read_ultratight(path):
    """ultratight.csv of receive --coupling ultra-tight: per channel and epoch, measurements, innovations, NIS."""
    return read_csv(find_output(path, "ultratight.csv"))


def read_attitude(path):
    """attitude.csv of an attitude run: gps_week, tow_s, roll/pitch/yaw_deg and their sigmas, num_sats, fixed, ratio."""
    return read_csv(find_output(path, "attitude.csv"))


def read_antenna_phases(path):
    """antenna_phases.csv of an attitude run: every antenna's phase per satellite and epoch with its flags."""
    return read_csv(find_output(path, "antenna_phases.csv"))


def read_truth(path):
    """truth.csv of a simulation: t_s, gps_week, tow_s, ECEF, lat/lon/height, NED velocity, clock[, attitude]."""
    return read_csv(find_output(path, "truth.csv"))


def read_satellites(path):
    """satellites.csv of a simulation: prn, elevation_deg, azimuth_deg, cn0_dbhz, doppler_hz, code_phase_chips."""
    return read_csv(find_output(path, "satellites.csv"))


def read_imu(path):
    """imu.csv: t_s and the body-frame increments dtheta_*_rad, dv_*_mps."""
    return read_csv(find_output(path, "imu.csv"))


def _read_json(path):
    if not os.path.isfile(path):
        raise InputError(path + ": file not found")
    with open(path) as f:
        try:
            return json.load(f)
        except ValueError as e:
            raise InputError("%s: %s" % (path, e))


def read_summary(path):
    """summary.json of any run, as a dict."""
    return _read_json(find_output(path, "summary.json", subfolders=()))


def read_snapshot(path):
    """snapshot.json of a snapshot run, as a dict: input, approximate_time, valid, failure, llh, sigma, satellites
    (each with prn, cn0_dbhz, doppler_hz, used, elevation_deg, azimuth_deg, residual_m when paired), ..."""
    return _read_json(find_output(path, "snapshot.json", subfolders=()))


def read_alignment(path):
    """alignment.json of an align run, as a dict: roll/pitch/yaw_deg and their sigmas, biases, mounting, warnings."""
    return _read_json(find_output(path, "alignment.json", subfolders=()))


def read_alignment_epochs(path):
    """alignment.csv of an align run, one row per filter epoch: t_s, attitude and its 1-sigma, NED velocity, bias
    estimates, attitude_used."""
    return read_csv(find_output(path, "alignment.csv", subfolders=()))


_GSV_DTYPE = [("epoch", "i8"), ("prn", "i8"), ("elevation_deg", "f8"), ("azimuth_deg", "f8"), ("cn0_dbhz", "f8")]


def read_sky(path):
    """The satellites in view per fix from solution.nmea's GSV sentences (whole degrees, as NMEA writes them):
    epoch (the fix's index, counted by GGA sentences), prn, elevation_deg, azimuth_deg, cn0_dbhz (nan when empty)."""
    path = find_output(path, "solution.nmea")
    if not os.path.isfile(path):
        raise InputError(path + ": file not found")
    rows, epoch = [], -1
    with open(path, newline="") as f:
        for number, line in enumerate(f, 1):
            body = line.strip().split("*")[0]
            if body.startswith("$GPGGA"):
                epoch += 1
            elif body.startswith("$GPGSV"):
                fields = body.split(",")
                try:
                    for k in range(4, len(fields) - 3, 4):
                        prn, el, az, cn0 = fields[k:k + 4]
                        rows.append((epoch, int(prn), float(el), float(az), float(cn0) if cn0 else float("nan")))
                except ValueError:
                    raise InputError("%s:%d: malformed GSV sentence" % (path, number))
    return np.array(rows, dtype=_GSV_DTYPE) if rows else np.zeros(0, dtype=_GSV_DTYPE)
