# SPDX-License-Identifier: GPL-3.0-or-later
"""ultratrack.attitude, ultratrack.align and ultratrack.snapshot against the program on the same files, numpy input
against the file, bad input against the program's message, and the results against the simulated attitude and
position."""
import math
import os

import numpy as np
import pytest

import ultratrack as ut
from conftest import (ANTENNAS, ATTITUDE_DEG, FS, LLH, NAV, TOW0, WEEK, assert_same_folders, program_error,
                      run_program)


def test_attitude_writes_the_programs_files(runs, sim, workdir):
    ours = runs.attitude()
    theirs = os.path.join(workdir, "cli_attitude")
    run_program("attitude", "--input", *sim["sample_files"], "--format", "i8", "--fs", FS, "--antennas", ANTENNAS,
                "--nav", NAV, "--threads", 2, "--out", theirs, "--quiet")
    assert_same_folders(ours["out"], theirs)
    attitude = ut.read_attitude(ours["out"])
    assert ours["epochs"] == attitude.size and ours["fixed_epochs"] == int(attitude["fixed"].sum()) > 0
    fixed = attitude[attitude["fixed"] == 1]
    # The simulated attitude (2, -3, 35 deg): within 3 sigma + 0.2 deg at every fixed epoch.
    for angle, truth in zip(("roll_deg", "pitch_deg", "yaw_deg"), ATTITUDE_DEG):
        assert np.all(np.abs(fixed[angle] - truth) < 3 * fixed["sigma_" + angle] + 0.2), angle
    assert ut.read_solution(ours["out"]).size > 0  # position/solution.csv


def test_attitude_checks_its_files_against_the_array(sim, workdir):
    with pytest.raises(ut.InputError, match="1 files for the 3 antennas of " + ANTENNAS):
        ut.attitude([sim["input"]], "i8", FS, ANTENNAS, os.path.join(workdir, "attitude_bad"), nav=NAV)
    with pytest.raises(ut.InputError, match="give navigation data or a reference week"):
        ut.attitude(sim["sample_files"], "i8", FS, ANTENNAS, os.path.join(workdir, "attitude_bad"))
    bad = os.path.join(workdir, "bad_antennas.toml")  # a lever arm of two numbers
    with open(ANTENNAS) as f, open(bad, "w") as g:
        g.write(f.read().replace("[1.0, 0.0, 0.0]", "[1.0, 0.0]"))
    with pytest.raises(ut.InputError) as caught:
        ut.attitude(sim["sample_files"], "i8", FS, bad, os.path.join(workdir, "attitude_bad"), nav=NAV)
    assert str(caught.value) == program_error("attitude", "--input", *sim["sample_files"], "--format", "i8", "--fs",
                                              FS, "--antennas", bad, "--nav", NAV, "--out",
                                              os.path.join(workdir, "att_bad"))
    assert bad in str(caught.value)


def test_align_writes_the_programs_files(runs, sim, workdir):
    ours = runs.align()
    theirs = os.path.join(workdir, "cli_align")
    run_program("align", "--imu", os.path.join(sim["dir"], "imu.csv"), "--attitude",
                os.path.join(runs.attitude()["out"], "attitude.csv"), "--position", *LLH, "--attitude-origin", WEEK,
                TOW0, "--duration", 0, "--out", theirs, "--quiet")
    assert_same_folders(ours["out"], theirs)
    assert ours == ut.read_alignment(ours["out"]) | {"out": ours["out"]}
    epochs = ut.read_alignment_epochs(ours["out"])
    assert epochs.size > 0 and epochs["attitude_used"].sum() > 0
    # The IMU's attitude is the simulated body attitude (no mounting in the scenario).
    for angle, truth in zip(("roll_deg", "pitch_deg", "yaw_deg"), ATTITUDE_DEG):
        assert abs(ours[angle] - truth) < 3 * ours["sigma_" + angle] + 0.1, angle


def test_align_bad_input_raises_the_programs_message(runs, sim, workdir):
    imu = os.path.join(sim["dir"], "imu.csv")
    unfixed = os.path.join(workdir, "attitude_unfixed.csv")
    with open(os.path.join(runs.attitude()["out"], "attitude.csv")) as f, open(unfixed, "w") as g:
        lines = f.read().splitlines()
        fields = [l.split(",") for l in lines[1:]]  # fixed (column 9) set to 0 on every row
        g.write("\n".join(lines[:1] + [",".join(f[:9] + ["0"] + f[10:]) for f in fields]) + "\n")
    with pytest.raises(ut.InputError) as caught:
        ut.align(imu, unfixed, os.path.join(workdir, "align_bad"), position=LLH, attitude_origin=(WEEK, TOW0))
    assert str(caught.value) == program_error("align", "--imu", imu, "--attitude", unfixed, "--position", *LLH,
                                              "--attitude-origin", WEEK, TOW0, "--out", os.path.join(workdir, "ab"))
    assert "no fixed attitude rows" in str(caught.value)
    with pytest.raises(ut.InputError, match="no_such_imu.csv"):
        ut.align(imu + ".x/no_such_imu.csv", unfixed, os.path.join(workdir, "align_bad"), position=LLH)


def test_snapshot_writes_the_programs_files(runs, sim, workdir):
    ours = runs.snapshot()
    theirs = os.path.join(workdir, "cli_snapshot")
    run_program("snapshot", "--input", sim["input"], "--format", "i8", "--fs", FS, "--nav", NAV, "--time",
                "%d:%r" % (WEEK, TOW0 + 1.0), "--skip", 1.0, "--ms", 60, "--approx-llh", "35.3,137.0,0.0", "--out",
                theirs, "--quiet")
    assert_same_folders(ours["out"], theirs)
    assert ours == ut.read_snapshot(ours["out"]) | {"out": ours["out"]}
    assert ours["valid"], ours["failure"]
    solution = ut.read_solution(ours["out"])
    assert solution.size == 1
    # Against the scenario: within 30 m, and the time correction within 10 ms (the approximate time is exact).
    llh = ours["llh"]
    north = math.radians(llh["lat_deg"] - LLH[0]) * 6371e3
    east = math.radians(llh["lon_deg"] - LLH[1]) * 6371e3 * math.cos(math.radians(LLH[0]))
    assert math.hypot(north, east) < 30.0 and abs(llh["height_m"] - LLH[2]) < 60.0
    assert abs(ours["time_correction_s"]) < 0.01


def test_snapshot_of_an_array_equals_the_file(runs, sim, workdir):
    start, count = int(1.0 * FS), int(0.060 * FS)
    samples = np.fromfile(sim["input"], dtype=np.int8, count=2 * (start + count))[2 * start:]
    ours = ut.snapshot(samples, NAV, (WEEK, TOW0 + 1.0), os.path.join(workdir, "snapshot_numpy"), fs=FS, ms=60,
                       approx_llh=(35.3, 137.0, 0.0))
    from_file = dict(runs.snapshot())
    for key in ("input", "wall_time_s", "out"):
        ours.pop(key), from_file.pop(key)
    assert ours == from_file
    with open(os.path.join(runs.snapshot()["out"], "solution.csv"), "rb") as a, \
            open(os.path.join(workdir, "snapshot_numpy", "solution.csv"), "rb") as b:
        assert a.read() == b.read()


def test_snapshot_bad_input_raises_the_programs_message(sim, workdir):
    empty_nav = os.path.join(workdir, "empty.nav")
    with open(NAV) as f, open(empty_nav, "w") as g:  # the header alone: no ephemeris
        for line in f:
            g.write(line)
            if "END OF HEADER" in line:
                break
    with pytest.raises(ut.InputError) as caught:
        ut.snapshot(sim["input"], empty_nav, (WEEK, TOW0), os.path.join(workdir, "snap_bad"), format="i8", fs=FS)
    assert str(caught.value) == program_error("snapshot", "--input", sim["input"], "--format", "i8", "--fs", FS,
                                              "--nav", empty_nav, "--time", "%d:%r" % (WEEK, TOW0), "--out",
                                              os.path.join(workdir, "snap_bad_cli"))
    with pytest.raises(ut.InputError, match=r"ms must be in \[2, 10000\]"):
        ut.snapshot(sim["input"], NAV, (WEEK, TOW0), os.path.join(workdir, "snap_bad"), format="i8", fs=FS, ms=1)
