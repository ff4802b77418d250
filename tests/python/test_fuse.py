# SPDX-License-Identifier: GPL-3.0-or-later
"""ultratrack.fuse against the program on the same IMU and GNSS files, and against the simulation's truth."""
import os

import pytest

import ultratrack as ut
from conftest import assert_same_folders, program_error, run_program

# IMU and truth only (no [signal]): a 30 s circle with a navigation-grade IMU, simulated in a fraction of a second.
INERTIAL = """
[time]
gps_week = 1823
tow_s = 518400.0
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
[trajectory]
profile = "circle"
duration_s = 30.0
imu_rate_hz = 100.0
[imu]
preset = "hg1700ae"
seed = 3
"""


@pytest.fixture(scope="module")
def inertial(workdir):
    folder = os.path.join(workdir, "inertial")
    ut.simulate(INERTIAL, folder)
    truth = ut.read_truth(folder)
    # Fixes at 1 Hz from the truth itself (sigma 1 m): the filter must stay within a few metres of it.
    step = int(round(1.0 / (truth["t_s"][1] - truth["t_s"][0])))
    gnss = os.path.join(folder, "gnss.csv")
    with open(gnss, "w") as f:
        f.write("t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m\n")
        for row in truth[::step]:
            f.write("%.6f,%.10f,%.10f,%.4f,%.5f,%.5f,%.5f,1,1,1\n" % (
                row["t_s"], row["lat_deg"], row["lon_deg"], row["height_m"], row["vel_n_mps"], row["vel_e_mps"],
                row["vel_d_mps"]))
    return {"imu": os.path.join(folder, "imu.csv"), "gnss": gnss, "truth": os.path.join(folder, "truth.csv")}


def test_fuse_writes_the_programs_files(inertial, workdir):
    summary = ut.fuse(inertial["imu"], inertial["gnss"], os.path.join(workdir, "fuse"), truth=inertial["truth"])
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


def test_fuse_bad_input_raises_the_programs_message(inertial, workdir):
    bad = os.path.join(workdir, "gnss_bad.csv")
    with open(bad, "w") as f:
        f.write("t_s,lat_deg\n0,1\n")
    with pytest.raises(ut.InputError) as caught:
        ut.fuse(inertial["imu"], bad, os.path.join(workdir, "fuse_bad"))
    assert str(caught.value) == program_error("fuse", "--imu", inertial["imu"], "--gnss", bad, "--out",
                                              os.path.join(workdir, "fuse_bad_cli"))
    with pytest.raises(ut.InputError, match="gnss.csv.missing"):
        ut.fuse(inertial["imu"], inertial["gnss"] + ".missing", os.path.join(workdir, "fuse_missing"))
