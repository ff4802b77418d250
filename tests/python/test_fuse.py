# SPDX-License-Identifier: GPL-3.0-or-later
"""ultratrack.fuse against the program on the same IMU and GNSS files, and against the simulation's truth."""
import os

import pytest

import ultratrack as ut
from conftest import assert_same_folders, program_error, run_program


def test_fuse_writes_the_programs_files(runs, workdir):
    inertial, summary = runs.inertial(), runs.fuse()
    assert summary == ut.read_summary(summary["out"]) | {"out": summary["out"]}
    out = os.path.join(workdir, "fuse_cli")
    run_program("fuse", "--imu", inertial["imu"], "--gnss", inertial["gnss"], "--truth", inertial["truth"], "--out",
                out, "--quiet")
    assert_same_folders(summary["out"], out)
    nav = ut.read_nav(summary["out"])
    assert nav.size > 500 and nav["t_s"][-1] < 30.0 + 1e-6
    assert summary["fixes_used"] + summary["fixes_before_start"] == 31  # 0..30 s at 1 Hz
    assert summary["rms_all"]["position_3d_m"] < 1.0
    assert summary["rms_all"]["within_3sigma"] > 0.95


def test_fuse_bad_input_raises_the_programs_message(runs, workdir):
    inertial = runs.inertial()
    bad = os.path.join(workdir, "gnss_bad.csv")
    with open(bad, "w") as f:
        f.write("t_s,lat_deg\n0,1\n")
    with pytest.raises(ut.InputError) as caught:
        ut.fuse(inertial["imu"], bad, os.path.join(workdir, "fuse_bad"))
    assert str(caught.value) == program_error("fuse", "--imu", inertial["imu"], "--gnss", bad, "--out",
                                              os.path.join(workdir, "fuse_bad_cli"))
    with pytest.raises(ut.InputError, match="gnss.csv.missing"):
        ut.fuse(inertial["imu"], inertial["gnss"] + ".missing", os.path.join(workdir, "fuse_missing"))
