# SPDX-License-Identifier: GPL-3.0-or-later
"""Ultratrack from Python: the library's runs (simulate, receive, acquire, fuse, attitude, snapshot, align) and readers that return
numpy structured arrays for the files a run writes (readers.py). Every run writes the same files as the
`ultratrack` command of the same name with the same settings; option names are the command line's with
underscores (--elevation-mask-deg -> elevation_mask_deg). Bad input raises ultratrack.InputError (a ValueError)
with the library's message, which names the file or setting.

    import ultratrack as ut
    run = ut.receive(input="antenna0.i8.bin", format="i8", fs=2.6e6, nav="brdc.n", out="run")
    sol = ut.read_solution(run["out"])          # sol["lat_deg"], sol["tow_s"], ...
"""
import datetime as _datetime
import json as _json
import os as _os
import tempfile as _tempfile

import numpy as _np

from . import _ultratrack
from ._ultratrack import InputError
from .readers import *  # noqa: F401,F403  (read_solution, read_tracking, read_nav, ...)
from .readers import __all__ as _reader_names

__all__ = ["InputError", "simulate", "receive", "acquire", "fuse", "attitude", "snapshot", "align"] + list(_reader_names)


def _path(p):
    return "" if p is None else _os.fspath(p)


def _current_gps_week():
    # The GPS week of today, for the 10-bit week number when neither nav nor reference_week dates a recording.
    return (_datetime.date.today() - _datetime.date(1980, 1, 6)).days // 7


def simulate(scenario, out):
    """Simulates a scenario (a TOML file's path, or TOML text: a string with a newline) into the folder `out` as
    `ultratrack simulate` does. Returns a dict: sample_files, satellites in view, signal_s, format, fs_hz, ..."""
    text = scenario if isinstance(scenario, str) and "\n" in scenario else ""
    return _ultratrack._simulate("" if text else _path(scenario), text, _path(out))


def _samples_file(samples, folder):
    """A numpy array of baseband samples as a file the library reads, and its format: int8 or int16 arrays of
    interleaved I, Q (flat, or shape (N, 2)) as i8 or i16 (so they give exactly what the file they came from gives),
    complex arrays as f32 (interleaved float32 I/Q, exact for complex64)."""
    samples = _np.asarray(samples)
    if samples.dtype in (_np.int8, _np.int16):
        if samples.ndim == 2 and samples.shape[1] != 2 or samples.ndim > 2 or samples.size % 2:
            raise InputError("python: integer samples are interleaved I, Q: a flat array of even length or shape (N, 2)")
        name = "i8" if samples.dtype == _np.int8 else "i16"
        data = _np.ascontiguousarray(samples, dtype="<i2" if name == "i16" else _np.int8)
    elif _np.iscomplexobj(samples):
        if samples.ndim != 1:
            raise InputError("python: complex samples must be a one-dimensional array")
        name, data = "f32", _np.ascontiguousarray(samples, dtype=_np.complex64)
    else:
        raise InputError("python: samples must be complex, or int8 / int16 interleaved I, Q; got %s" % samples.dtype)
    path = _os.path.join(folder, "samples." + name + ".bin")
    data.tofile(path)
    return path, name


def receive(input, format=None, fs=None, if_hz=0.0, coupling="scalar", imu=None, nav=None, out=None, **options):
    """Receives a recording into the folder `out` (a fresh temporary folder when None) as `ultratrack receive`
    does, and returns its summary as a dict (fixes, ttff_s, mean_lat_deg, satellites_tracked, ..., and `out`).

    input: a file name, or a numpy array of baseband samples (int8 / int16 interleaved I, Q, or complex), written
    to a temporary file of the matching format (i8, i16, f32) that the run reads as it reads any file; format is
    then implied and if_hz must be 0. Receiving the array of a file's samples gives the file's results. options: the command line's other settings by name: config, nav_bits,
    elevation_mask_deg, troposphere (bool), ionosphere (bool), channels, threads, prn (list of int), duration, skip,
    reference_week, iq_swap, q_negate, two_bit_coding, two_bit_order; with coupling loose, tight or ultra-tight:
    filter, align, fusion_config, imu_time_origin ("sample0", "tow" or seconds), ut_measurement, ut_pipelined,
    ut_clock_loop_bw_hz (the common clock loop's bandwidth, 0: off);
    with coupling vector: vector_carrier."""
    if fs is None:
        raise TypeError("receive: fs (the sample rate, Hz) is required")
    out = _path(out) or _tempfile.mkdtemp(prefix="ultratrack_receive_")
    week = _current_gps_week()
    if isinstance(input, _np.ndarray):
        if if_hz:
            raise InputError("python: samples given as an array are complex baseband: if_hz must be 0")
        with _tempfile.TemporaryDirectory(prefix="ultratrack_samples_") as folder:
            path, name = _samples_file(input, folder)
            return _ultratrack._receive(path, name, float(fs), 0.0, coupling, _path(imu), _path(nav), out, week,
                                        dict(options))
    if format is None:
        raise TypeError("receive: format is required with a file input")
    return _ultratrack._receive(_path(input), format, float(fs), float(if_hz), coupling, _path(imu), _path(nav), out,
                                week, dict(options))


def acquire(input, format=None, fs=None, if_hz=0.0, ms=1, noncoh=10, prn=range(1, 33), doppler_max=5000.0,
            doppler_step=0.0, pfa=1e-3, iq_swap=False, q_negate=False, all=False):
    """FFT acquisition of the first noncoh x ms of a recording (a file name with format, or a numpy array of
    complex baseband samples, searched in memory), as `ultratrack acquire`. Returns a numpy structured array, one row per detected PRN (every
    searched PRN with all=True): prn, detected, doppler_hz, code_phase_chips, code_phase_samples, cn0_dbhz, metric,
    threshold."""
    if fs is None:
        raise TypeError("acquire: fs (the sample rate, Hz) is required")
    source = input if isinstance(input, _np.ndarray) else _path(input)
    if not isinstance(input, _np.ndarray) and format is None:
        raise TypeError("acquire: format is required with a file input")
    rows = _ultratrack._acquire(source, format or "", float(fs), float(if_hz), int(ms), int(noncoh),
                                [int(p) for p in prn], float(doppler_max), float(doppler_step), float(pfa),
                                bool(iq_swap), bool(q_negate), bool(all))
    dtype = [("prn", "i4"), ("detected", "?"), ("doppler_hz", "f8"), ("code_phase_chips", "f8"),
             ("code_phase_samples", "f8"), ("cn0_dbhz", "f8"), ("metric", "f8"), ("threshold", "f8")]
    return _np.array([tuple(r[name] for name, _ in dtype) for r in rows], dtype=dtype)


def fuse(imu, gnss, out, truth=None, filter="ekf", align="motion", config=None, outage=(), attitude=None,
         attitude_origin=None, decimate=1):
    """Loosely coupled GNSS/INS (`ultratrack fuse`) into out/nav.csv and out/summary.json; returns summary.json
    as a dict. outage: (start_s, duration_s) pairs; attitude_origin: (week, tow_s) of IMU t = 0."""
    summary = _ultratrack._fuse(_path(imu), _path(gnss), _path(out), _path(truth), filter, align, _path(config),
                                [(float(a), float(b)) for a, b in outage], _path(attitude),
                                None if attitude_origin is None else (int(attitude_origin[0]),
                                                                      float(attitude_origin[1])),
                                int(decimate))
    result = _json.loads(summary)
    result["out"] = _path(out)
    return result


def attitude(inputs, format, fs, antennas, out, if_hz=0.0, nav=None, **options):
    """The multi-antenna receiver (`ultratrack attitude`) on one file per antenna (master first) with the array of
    the antenna file `antennas`; returns a dict (epochs, attitude_epochs, fixed_epochs, fix_rate, ...).
    options: prn, threads, interval, duration, reference_week."""
    return _ultratrack._attitude([_path(p) for p in inputs], format, float(fs), float(if_hz), _path(antennas),
                                 _path(nav), _path(out), dict(options))


def snapshot(input, nav, time, out, format=None, fs=None, if_hz=0.0, time_sigma_s=10.0, approx_llh=None, ms=100.0,
             skip=0.0, prn=range(1, 33), doppler_max=5000.0, pfa=1e-3, spacing_chips=0.5, iq_swap=False,
             q_negate=False):
    """A position from a short recording (`ultratrack snapshot`): coarse-time navigation with the broadcast
    ephemerides of `nav` and the approximate GPS time `time` = (week, tow_s) of the snapshot's first sample, into
    out/snapshot.json and out/solution.csv. input: a file name with format, or a numpy array of samples (as for
    receive). approx_llh: (lat_deg, lon_deg, height_m), else a Doppler fix and a grid search. Returns snapshot.json
    as a dict (valid, failure, llh, satellites, ...); no fix is no exception (valid False, failure says why)."""
    if fs is None:
        raise TypeError("snapshot: fs (the sample rate, Hz) is required")
    week, tow = time
    llh = None if approx_llh is None else [float(v) for v in approx_llh]

    def run(path, name, if_hz):
        return _ultratrack._snapshot(path, name, float(fs), float(if_hz), _path(nav), int(week), float(tow), _path(out),
                                     float(time_sigma_s), llh, float(ms), float(skip), [int(p) for p in prn],
                                     float(doppler_max), float(pfa), float(spacing_chips), bool(iq_swap),
                                     bool(q_negate))

    if isinstance(input, _np.ndarray):
        if if_hz:
            raise InputError("python: samples given as an array are complex baseband: if_hz must be 0")
        with _tempfile.TemporaryDirectory(prefix="ultratrack_samples_") as folder:
            run(*_samples_file(input, folder), 0.0)
    else:
        if format is None:
            raise TypeError("snapshot: format is required with a file input")
        run(_path(input), format, if_hz)
    result = read_snapshot(out)
    result["out"] = _path(out)
    return result


def align(imu, attitude, out, position=None, attitude_origin=None, imu_pps=None, reference_attitude=None,
          duration=100.0, filter_interval=1.0, config=None, filter="ekf"):
    """Stationary fine alignment (`ultratrack align`) from an IMU CSV at rest and an attitude run's attitude.csv
    into out/alignment.json and out/alignment.csv; returns alignment.json as a dict (roll_deg, sigma_roll_deg,
    biases, mounting, warnings, ...). position: (lat_deg, lon_deg, height_m), else [initial] position_deg_m of
    config; attitude_origin: (week, tow_s) of IMU t = 0; imu_pps: a PPS CSV that puts a local IMU clock on GPS time;
    reference_attitude: (roll, pitch, yaw, sigma_roll, sigma_pitch, sigma_yaw) in deg, for the mounting estimate."""
    summary = _ultratrack._align(_path(imu), _path(attitude), _path(out), _path(config),
                                 None if position is None else [float(v) for v in position],
                                 None if attitude_origin is None else (int(attitude_origin[0]),
                                                                       float(attitude_origin[1])),
                                 _path(imu_pps),
                                 None if reference_attitude is None else [float(v) for v in reference_attitude],
                                 float(duration), float(filter_interval), filter)
    result = _json.loads(summary)
    result["out"] = _path(out)
    return result
