# SPDX-License-Identifier: GPL-3.0-or-later
"""Shared runs of the Python package's tests (pytest; ctest python.module runs `python3 -m pytest tests/python`).

One short simulation serves every IF test: 13 s of a static vehicle with three antennas (the array of
scenarios/attitude_antennas.toml), an HG1700AE IMU at rest and the shipped broadcast ephemeris
tests/data/brdc3540_0000-0200.14n; antenna 0's file is received with every coupling, acquired and snapshot, the three
files make the attitude run, whose attitude.csv with imu.csv makes the alignment. Each run is made once per session
through the module and, for the comparisons, once through the program.

Environment: PYTHONPATH holding build/python, ULTRATRACK_PROGRAM (the `ultratrack` program: needed by the
comparisons), ULTRATRACK_SOURCE_DIR (the checkout), ULTRATRACK_ARTEFACTS (a folder kept after the run: reports and
browser screenshots; default: the session's temporary folder), ULTRATRACK_CHROMIUM (the browser of the report test).
When the module was not built, no test is collected, the reason is printed and pytest exits 77 (ctest: skipped).
"""
import os
import subprocess

import pytest

try:
    import numpy  # noqa: F401
    import ultratrack as ut
    import ultratrack.report  # noqa: F401
    NOT_BUILT = None
except ImportError as e:
    ut = None
    NOT_BUILT = ("the Python module was not built (cmake -DULTRATRACK_PYTHON=ON needs pybind11-dev, python3-dev, "
                 "python3-numpy, python3-matplotlib): %s" % e)

SOURCE = os.path.abspath(os.environ.get("ULTRATRACK_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")))
NAV = os.path.join(SOURCE, "tests", "data", "brdc3540_0000-0200.14n")
ANTENNAS = os.path.join(SOURCE, "scenarios", "attitude_antennas.toml")
PROGRAM = os.environ.get("ULTRATRACK_PROGRAM", "")
LLH = (35.274016, 137.013759, 100.0)
WEEK, TOW0 = 1823, 518398.0  # sample 0; subframes end 2 s and 8 s in: the first fix after ~8.5 s
FS = 2.0e6
ATTITUDE_DEG = (2.0, -3.0, 35.0)
SCENARIO = """
[signal]
sample_rate_hz = 2.0e6
format = "i8"
duration_s = 13.0
cn0_dbhz = 45.0
seed = 7
[time]
gps_week = %d
tow_s = %r
[navigation]
rinex = "%s"
[receiver]
llh_deg_m = [%r, %r, %r]
attitude_deg = [%r, %r, %r]
[atmosphere]
ionosphere = true
troposphere = true
[trajectory]
profile = "static"
duration_s = 13.0
imu_rate_hz = 100.0
[imu]
preset = "hg1700ae"
seed = 3
[[antenna]]
lever_arm_body_m = [0.0, 0.0, 0.0]
phase_noise_m = 0.003
[[antenna]]
lever_arm_body_m = [1.0, 0.0, 0.0]
phase_noise_m = 0.003
[[antenna]]
lever_arm_body_m = [0.0, 1.025, 0.0]
phase_noise_m = 0.003
""" % ((WEEK, TOW0, NAV) + LLH + ATTITUDE_DEG)
# IMU and truth only (no [signal]) for fuse: a 30 s circle with a navigation-grade IMU, simulated in a fraction of a
# second.
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
COUPLINGS = ("scalar", "vector", "loose", "tight", "ultra-tight")
INERTIAL_COUPLINGS = ("loose", "tight", "ultra-tight")
# The vehicle is at rest: the GNSS/INS couplings start with a static alignment, over 5 s (the default 60 s would
# outlast the recording).
FUSION_CONFIG = "[alignment]\nstatic_duration_s = 5.0\n"


# Without the module the test files (which import it) are not collected; the session says why and exits 77.
collect_ignore_glob = ["test_*.py"] if NOT_BUILT else []


def pytest_sessionfinish(session, exitstatus):
    if NOT_BUILT:
        print("\nSKIPPED: " + NOT_BUILT)
        session.exitstatus = 77


def needs_program():
    if not (PROGRAM and os.path.exists(PROGRAM)):
        pytest.fail("ULTRATRACK_PROGRAM (the ultratrack program) is needed for the comparison; ctest gives it")
    return PROGRAM


def run_program(*args, expect_error=False):
    """Runs `ultratrack ARGS...`; returns the completed process (stderr as text). Fails the test on an unexpected
    exit status."""
    done = subprocess.run([needs_program()] + [str(a) for a in args], capture_output=True, text=True)
    if expect_error:
        assert done.returncode != 0, "the program accepted %s" % (args,)
    else:
        assert done.returncode == 0, done.stderr
    return done


def program_error(*args):
    """The message of the program's error line ("ultratrack: error: MESSAGE") for a run that must fail."""
    lines = [l for l in run_program(*args, expect_error=True).stderr.splitlines() if l.startswith("ultratrack: error: ")]
    assert lines, "no error line from the program for %s" % (args,)
    return lines[-1][len("ultratrack: error: "):]


def same_output(a, b, json_input=True):
    """Two output files are equal byte for byte, apart from a RINEX header's creation time and a JSON file's
    wall-clock lines (and its input line when json_input is False)."""
    volatile = (b"PGM / RUN BY / DATE", b'"wall_time_s"', b'"wall_s"', b'"realtime_factor"', b'"cpu_time_s"')
    volatile += () if json_input else (b'  "input": {"file": ',)
    with open(a, "rb") as fa, open(b, "rb") as fb:
        la, lb = fa.read().split(b"\n"), fb.read().split(b"\n")
    keep = lambda lines: [l for l in lines if not any(v in l for v in volatile)]
    return len(la) == len(lb) and keep(la) == keep(lb)


def assert_same_folders(ours, theirs, ignore=(), json_input=True):
    """Every file of the program's folder is in ours, equal (same_output), and ours has no other. json_input=False:
    the line of summary.json naming the input file is left out (a numpy array's is a temporary file)."""
    def files(root):
        return sorted(os.path.relpath(os.path.join(d, f), root) for d, _, names in os.walk(root) for f in names
                      if f not in ignore)
    assert files(ours) == files(theirs)
    assert files(theirs), "the program wrote nothing into " + theirs
    for name in files(theirs):
        assert same_output(os.path.join(ours, name), os.path.join(theirs, name), json_input), name


@pytest.fixture(scope="session")
def workdir(tmp_path_factory):
    return str(tmp_path_factory.mktemp("ultratrack"))


@pytest.fixture(scope="session")
def artefacts(workdir):
    folder = os.environ.get("ULTRATRACK_ARTEFACTS") or os.path.join(workdir, "artefacts")
    os.makedirs(folder, exist_ok=True)
    return folder


@pytest.fixture(scope="session")
def sim(workdir):
    """The session's simulation (SCENARIO): its summary dict, with "dir" and "input" (antenna 0's file). The sample
    files are removed at the end of the session."""
    folder = os.path.join(workdir, "sim")
    result = ut.simulate(SCENARIO, folder)
    result["dir"] = folder
    result["input"] = result["sample_files"][0]
    yield result
    for f in result["sample_files"]:  # 52 MB each; pytest keeps its last three session folders
        os.remove(f)


class Runs:
    """Runs made once per session, on demand: receive per coupling, attitude, align, snapshot."""

    def __init__(self, workdir, sim, artefacts):
        self.workdir, self.sim, self.artefacts, self.made = workdir, sim, artefacts, {}

    def _once(self, name, make):
        if name not in self.made:
            self.made[name] = make(os.path.join(self.workdir, name))
        return self.made[name]

    def fusion_config(self):
        path = os.path.join(self.workdir, "fusion.toml")
        with open(path, "w") as f:
            f.write(FUSION_CONFIG)
        return path

    def receive(self, coupling):
        fusion = {}
        if coupling in INERTIAL_COUPLINGS:
            fusion = dict(imu=os.path.join(self.sim["dir"], "imu.csv"), align="static",
                          fusion_config=self.fusion_config())
        return self._once("receive_" + coupling, lambda out: ut.receive(
            input=self.sim["input"], format="i8", fs=FS, nav=NAV, coupling=coupling, out=out, threads=2, **fusion))

    def attitude(self):
        return self._once("attitude", lambda out: ut.attitude(
            self.sim["sample_files"], "i8", FS, ANTENNAS, out, nav=NAV, threads=2))

    def align(self):
        attitude = os.path.join(self.attitude()["out"], "attitude.csv")
        return self._once("align", lambda out: ut.align(
            os.path.join(self.sim["dir"], "imu.csv"), attitude, out, position=LLH, attitude_origin=(WEEK, TOW0),
            duration=0))

    def run(self, name):
        """The run of a command or coupling by name: a coupling of receive, or attitude, align, snapshot, fuse."""
        return self.receive(name) if name in COUPLINGS else getattr(self, name)()

    def inertial(self):
        """The INERTIAL simulation and GNSS fixes at 1 Hz from its truth itself (sigma 1 m): files imu, gnss, truth."""
        def make(folder):
            ut.simulate(INERTIAL, folder)
            truth = ut.read_truth(folder)
            step = int(round(1.0 / (truth["t_s"][1] - truth["t_s"][0])))
            gnss = os.path.join(folder, "gnss.csv")
            with open(gnss, "w") as f:
                f.write("t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m\n")
                for row in truth[::step]:
                    f.write("%.6f,%.10f,%.10f,%.4f,%.5f,%.5f,%.5f,1,1,1\n" % (
                        row["t_s"], row["lat_deg"], row["lon_deg"], row["height_m"], row["vel_n_mps"],
                        row["vel_e_mps"], row["vel_d_mps"]))
            return {"imu": os.path.join(folder, "imu.csv"), "gnss": gnss, "truth": os.path.join(folder, "truth.csv")}
        return self._once("inertial", make)

    def fuse(self):
        files = self.inertial()
        return self._once("fuse", lambda out: ut.fuse(files["imu"], files["gnss"], out, truth=files["truth"]))

    def report(self, name):
        """The report of run(name) against the simulation's truth, made once by `python3 -m ultratrack.report`'s
        main into the artefacts folder (report_NAME); returns the folder."""
        def make(_):
            out = os.path.join(self.artefacts, "report_" + name)
            truth = self.inertial()["truth"] if name == "fuse" else os.path.join(self.sim["dir"], "truth.csv")
            assert ultratrack.report.main([self.run(name)["out"], "--truth", truth, "--out", out]) == 0
            return out
        return self._once("report_" + name, make)

    def snapshot(self):
        return self._once("snapshot", lambda out: ut.snapshot(
            self.sim["input"], NAV, (WEEK, TOW0 + 1.0), out, format="i8", fs=FS, skip=1.0, ms=60,
            approx_llh=(35.3, 137.0, 0.0)))


@pytest.fixture(scope="session")
def runs(workdir, sim, artefacts):
    return Runs(workdir, sim, artefacts)
