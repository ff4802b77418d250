# SPDX-License-Identifier: GPL-3.0-or-later
"""ultratrack.receive and ultratrack.acquire against the program on the same recording, numpy input against the
file, and the summary dict against the files of the run and the scenario's truth."""
import json
import math
import os
import subprocess

import numpy as np
import pytest

import ultratrack as ut
from conftest import (COUPLINGS, FS, INERTIAL_COUPLINGS, LLH, NAV, assert_same_folders, program_error, run_program)


def ecef(lat_deg, lon_deg, h_m):
    a, e2 = 6378137.0, 6.69437999014e-3
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    n = a / math.sqrt(1.0 - e2 * math.sin(lat) ** 2)
    return ((n + h_m) * math.cos(lat) * math.cos(lon), (n + h_m) * math.cos(lat) * math.sin(lon),
            (n * (1.0 - e2) + h_m) * math.sin(lat))


@pytest.mark.parametrize("coupling", COUPLINGS)
def test_receive_writes_the_programs_files(runs, sim, workdir, coupling):
    ours = runs.receive(coupling)
    theirs = os.path.join(workdir, "cli_receive_" + coupling)
    args = ["receive", "--input", sim["input"], "--format", "i8", "--fs", FS, "--nav", NAV, "--coupling", coupling,
            "--threads", 2, "--out", theirs, "--quiet"]
    if coupling in INERTIAL_COUPLINGS:
        args += ["--imu", os.path.join(sim["dir"], "imu.csv"), "--align", "static", "--fusion-config",
                 runs.fusion_config()]
    run_program(*args)
    assert_same_folders(ours["out"], theirs)
    assert ours["coupling"] == coupling
    assert ours["fixes"] > 0
    if coupling in INERTIAL_COUPLINGS:
        assert ours["navigation_started"] and ours["navigation_rows"] == ut.read_nav(ours["out"]).size
    if coupling == "ultra-tight":
        assert ours["handed_over"] > 0 and ours["ultratight_channel_epochs"] > 0
        assert ut.read_ultratight(ours["out"]).size > 0
    if coupling == "vector":
        assert ours["vector_epochs"] > 0 and ut.read_vector(ours["out"]).size > 0


def test_summary_agrees_with_the_files_and_the_truth(runs):
    run = runs.receive("scalar")
    out = run["out"]
    solution, summary = ut.read_solution(out), ut.read_summary(out)
    assert run["fixes"] == solution.size == summary["fixes"]
    assert run["ttff_s"] == pytest.approx(summary["ttff_s"], abs=1e-3)  # printed with 3 decimals
    assert run["satellites_tracked"] == len(summary["satellites_tracked"])
    assert run["satellites_used"] == len(summary["satellites_used"])
    assert run["mean_lat_deg"] == pytest.approx(float(np.mean(solution["lat_deg"])), abs=1e-8)
    assert run["mean_height_m"] == pytest.approx(float(np.mean(solution["height_m"])), abs=1e-3)
    assert set(ut.read_tracking(out)["prn"].tolist()) == set(summary["satellites_tracked"])
    # Against the scenario (independent of the receiver): a static fix within 15 m.
    fix = ecef(run["mean_lat_deg"], run["mean_lon_deg"], run["mean_height_m"])
    assert math.dist(fix, ecef(*LLH)) < 15.0
    # The sky of solution.nmea: the satellites used, at the simulation's elevation and azimuth (to NMEA's degree).
    sky = ut.read_sky(out)
    truth = {int(r["prn"]): r for r in ut.read_satellites(runs.sim["dir"])}
    assert set(sky["prn"].tolist()) <= set(truth)
    for row in sky[sky["epoch"] == sky["epoch"][-1]]:
        assert abs(row["elevation_deg"] - truth[int(row["prn"])]["elevation_deg"]) < 1.5
        assert abs((row["azimuth_deg"] - truth[int(row["prn"])]["azimuth_deg"] + 180) % 360 - 180) < 1.5


def test_numpy_samples_equal_the_file(runs, sim, workdir):
    samples = np.fromfile(sim["input"], dtype=np.int8)
    run = ut.receive(samples, fs=FS, nav=NAV, out=os.path.join(workdir, "receive_numpy"), threads=2)
    assert_same_folders(run["out"], runs.receive("scalar")["out"], json_input=False)
    with pytest.raises(ut.InputError, match="if_hz must be 0"):
        ut.receive(samples, fs=FS, if_hz=1.0e3, out=os.path.join(workdir, "receive_numpy_if"))


def test_acquire_equals_the_program_and_an_array_the_file(sim):
    ours = ut.acquire(sim["input"], format="i8", fs=FS, ms=1, noncoh=4)
    done = run_program("acquire", "--input", sim["input"], "--format", "i8", "--fs", FS, "--ms", 1, "--noncoh", 4,
                       "--json")
    theirs = json.loads(done.stdout)["satellites"]
    assert len(theirs) == ours.size > 3
    for a, b in zip(ours, theirs):  # at the program's printed precision
        assert (int(a["prn"]), bool(a["detected"])) == (b["prn"], b["detected"])
        for key, digits in (("doppler_hz", 1), ("code_phase_chips", 3), ("code_phase_samples", 3), ("cn0_dbhz", 1),
                            ("metric", 2), ("threshold", 2)):
            assert "%.*f" % (digits, a[key]) == "%.*f" % (digits, b[key]), key
    raw = np.fromfile(sim["input"], dtype=np.int8, count=2 * 2000 * 4).astype(np.float32)
    np.testing.assert_array_equal(ut.acquire(raw[0::2] + 1j * raw[1::2], fs=FS, ms=1, noncoh=4), ours)
    # The detections are the satellites in view, at their simulated Doppler.
    in_view = {s["prn"]: s for s in sim["satellites"]}
    for row in ours:
        assert abs(row["doppler_hz"] - in_view[int(row["prn"])]["doppler_hz"]) < 100.0


def test_bad_input_raises_the_programs_message(sim, workdir):
    missing = os.path.join(workdir, "no_such_recording.i8.bin")
    with pytest.raises(ut.InputError) as caught:
        ut.receive(input=missing, format="i8", fs=FS, out=os.path.join(workdir, "missing"))
    assert isinstance(caught.value, ValueError)
    assert str(caught.value) == program_error("receive", "--input", missing, "--format", "i8", "--fs", FS, "--out",
                                              os.path.join(workdir, "missing_cli"))
    with pytest.raises(ut.InputError) as caught:
        ut.receive(input=sim["input"], format="i8", fs=FS, nav=missing + ".nav", out=os.path.join(workdir, "m2"))
    assert str(caught.value) == program_error("receive", "--input", sim["input"], "--format", "i8", "--fs", FS, "--nav",
                                              missing + ".nav", "--out", os.path.join(workdir, "m2_cli"))
    with pytest.raises(ut.InputError) as caught:
        ut.acquire(sim["input"], format="i8", fs=FS, ms=1, doppler_max=-5)
    assert str(caught.value).split(": ", 1)[1] == program_error(
        "acquire", "--input", sim["input"], "--format", "i8", "--fs", FS, "--doppler-max", -5).split(": ", 1)[1]
    bad_config = os.path.join(workdir, "bad_fusion.toml")
    with open(bad_config, "w") as f:
        f.write("[align]\nstatic_duration_s = 5.0\n")
    imu = os.path.join(sim["dir"], "imu.csv")
    with pytest.raises(ut.InputError) as caught:
        ut.receive(input=sim["input"], format="i8", fs=FS, nav=NAV, coupling="loose", imu=imu,
                   fusion_config=bad_config, out=os.path.join(workdir, "bad_config"))
    assert str(caught.value) == program_error("receive", "--input", sim["input"], "--format", "i8", "--fs", FS, "--nav",
                                              NAV, "--coupling", "loose", "--imu", imu, "--fusion-config", bad_config,
                                              "--out", os.path.join(workdir, "bad_config_cli"))
    with pytest.raises(ut.InputError, match="unknown sample format 'i9'"):
        ut.receive(input=sim["input"], format="i9", fs=FS, out=os.path.join(workdir, "bad"))
    with pytest.raises(ut.InputError, match="needs imu"):
        ut.receive(input=sim["input"], format="i8", fs=FS, coupling="tight", out=os.path.join(workdir, "bad"))
    with pytest.raises(TypeError, match="no_such_option"):
        ut.receive(input=sim["input"], format="i8", fs=FS, out=os.path.join(workdir, "bad"), no_such_option=1)
    with pytest.raises(ut.InputError, match="solution.csv"):
        ut.read_solution(os.path.join(workdir, "missing_run"))


def test_simulate_writes_the_programs_files(workdir):
    scenario = os.path.join(workdir, "inertial.toml")
    with open(scenario, "w") as f:
        f.write("[time]\ngps_week = 1823\ntow_s = 518400.0\n[receiver]\nllh_deg_m = [35.27, 137.01, 100.0]\n"
                "[trajectory]\nprofile = \"circle\"\nduration_s = 20.0\nimu_rate_hz = 100.0\n"
                "[imu]\npreset = \"hg1700ae\"\nseed = 3\n")
    ours = ut.simulate(scenario, os.path.join(workdir, "simulate"))
    run_program("simulate", "--scenario", scenario, "--out", os.path.join(workdir, "simulate_cli"), "--quiet")
    assert_same_folders(ours["out"], os.path.join(workdir, "simulate_cli"))
    assert ours["imu_rows"] == ut.read_imu(ours["out"]).size
    assert ours["truth_rows"] == ut.read_truth(ours["out"]).size
