# SPDX-License-Identifier: GPL-3.0-or-later
"""The Python package end to end (ctest python.module): a 12 s static scenario on the shipped broadcast ephemeris is
simulated and received through the module; the summary dict is checked against the files the run wrote and the
scenario's truth, the module's files against the program's on the same input (byte for byte), a numpy array of the
file's samples against the file, bad input against its message, and the report against the figures it made.

Environment: PYTHONPATH holding build/python, ULTRATRACK_PROGRAM (the `ultratrack` program; its comparison is
skipped without it), ULTRATRACK_SOURCE_DIR (the checkout). Exits 77 (ctest: skipped) when the module was not built.
"""
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

try:
    import numpy as np
    import ultratrack as ut
    import ultratrack.report
except ImportError as e:
    print("SKIPPED: the Python module was not built (cmake -DULTRATRACK_PYTHON=ON needs pybind11-dev, python3-dev, "
          "python3-numpy, python3-matplotlib): %s" % e)
    sys.exit(77)

SOURCE = os.environ.get("ULTRATRACK_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
NAV = os.path.abspath(os.path.join(SOURCE, "tests", "data", "brdc3540_0000-0200.14n"))
PROGRAM = os.environ.get("ULTRATRACK_PROGRAM", "")
LLH = (35.274016, 137.013759, 100.0)
# Subframes start 2 s and 8 s into the signal: the first fix comes after the second preamble (~8-9 s).
SCENARIO = """
[signal]
sample_rate_hz = 2.0e6
format = "i8"
duration_s = 12.0
cn0_dbhz = 45.0
seed = 7
[time]
gps_week = 1823
tow_s = 518398.0
[navigation]
rinex = "%s"
[receiver]
llh_deg_m = [%r, %r, %r]
[atmosphere]
ionosphere = true
troposphere = true
""" % ((NAV,) + LLH)
# IMU and truth only (no [signal]): a 60 s circle with a navigation-grade IMU, simulated in a fraction of a second.
INERTIAL = """
[time]
gps_week = 1823
tow_s = 518400.0
[receiver]
llh_deg_m = [%r, %r, %r]
[trajectory]
profile = "circle"
duration_s = 60.0
imu_rate_hz = 100.0
[imu]
preset = "hg1700ae"
seed = 3
""" % LLH
OUTPUTS = ("solution.csv", "tracking.csv", "observations.rnx", "navigation.rnx", "solution.nmea", "solution.kml")


def same_output(a, b):
    """Two output files are equal byte for byte, apart from a RINEX header's creation time."""
    with open(a, "rb") as fa, open(b, "rb") as fb:
        la, lb = fa.read().split(b"\n"), fb.read().split(b"\n")
    keep = lambda lines: [l for l in lines if not l.rstrip().endswith(b"PGM / RUN BY / DATE")]
    return len(la) == len(lb) and keep(la) == keep(lb)


def ecef(lat_deg, lon_deg, h_m):
    a, e2 = 6378137.0, 6.69437999014e-3
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    n = a / math.sqrt(1.0 - e2 * math.sin(lat) ** 2)
    return ((n + h_m) * math.cos(lat) * math.cos(lon), (n + h_m) * math.cos(lat) * math.sin(lon),
            (n * (1.0 - e2) + h_m) * math.sin(lat))


class ModuleTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="ultratrack_python_test_")
        cls.sim = ut.simulate(SCENARIO, os.path.join(cls.dir, "sim"))
        cls.input = cls.sim["sample_files"][0]
        cls.rx = ut.receive(input=cls.input, format="i8", fs=2.0e6, nav=NAV, out=os.path.join(cls.dir, "run"),
                             threads=2)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_simulate_reports_its_files(self):
        self.assertEqual(self.sim["format"], "i8")
        self.assertAlmostEqual(self.sim["signal_s"], 12.0)
        self.assertEqual(os.path.getsize(self.input), 2 * self.sim["samples"])  # i8: two bytes a sample
        truth = ut.read_truth(os.path.join(self.dir, "sim"))
        self.assertEqual(truth.size, self.sim["truth_rows"])
        prns = set(ut.read_satellites(os.path.join(self.dir, "sim"))["prn"].tolist())
        self.assertEqual(prns, {s["prn"] for s in self.sim["satellites"]})

    def test_summary_agrees_with_the_files_written(self):
        run, out = self.rx, self.rx["out"]
        solution = ut.read_solution(out)
        summary = ut.read_summary(out)
        self.assertGreater(run["fixes"], 0)
        self.assertEqual(run["fixes"], solution.size)
        self.assertEqual(run["fixes"], summary["fixes"])
        self.assertEqual(summary["coupling"], run["coupling"])
        self.assertAlmostEqual(run["ttff_s"], summary["ttff_s"], delta=1e-3)  # printed with 3 decimals
        self.assertEqual(run["satellites_tracked"], len(summary["satellites_tracked"]))
        self.assertEqual(run["satellites_used"], len(summary["satellites_used"]))
        self.assertAlmostEqual(run["mean_lat_deg"], summary["mean_llh"]["lat_deg"], delta=1e-9)
        self.assertAlmostEqual(run["mean_lon_deg"], summary["mean_llh"]["lon_deg"], delta=1e-9)
        self.assertAlmostEqual(run["mean_lat_deg"], float(np.mean(solution["lat_deg"])), delta=1e-8)
        self.assertAlmostEqual(run["mean_height_m"], float(np.mean(solution["height_m"])), delta=1e-3)
        tracked = set(ut.read_tracking(out)["prn"].tolist())
        self.assertEqual(tracked, set(summary["satellites_tracked"]))
        self.assertLessEqual(run["processed_s"], 12.0 + 1e-9)
        # Against the scenario's truth (independent of the receiver): a static fix within 15 m.
        fix = ecef(run["mean_lat_deg"], run["mean_lon_deg"], run["mean_height_m"])
        self.assertLess(math.dist(fix, ecef(*LLH)), 15.0)

    @unittest.skipUnless(PROGRAM and os.path.exists(PROGRAM), "ULTRATRACK_PROGRAM not given")
    def test_files_equal_the_programs(self):
        out = os.path.join(self.dir, "cli")
        subprocess.run([PROGRAM, "receive", "--input", self.input, "--format", "i8", "--fs", "2e6", "--nav", NAV,
                        "--threads", "2", "--out", out, "--quiet"], check=True, stdout=subprocess.DEVNULL)
        for name in OUTPUTS:
            self.assertTrue(same_output(os.path.join(out, name), os.path.join(self.rx["out"], name)), name)
        ours, theirs = ut.read_summary(self.rx["out"]), ut.read_summary(out)
        for key in ("wall_time_s", "realtime_factor"):
            ours.pop(key), theirs.pop(key)
        self.assertEqual(ours, theirs)

    def test_numpy_samples_equal_the_file(self):
        samples = np.fromfile(self.input, dtype=np.int8)
        run = ut.receive(samples, fs=2.0e6, nav=NAV, out=os.path.join(self.dir, "numpy"), threads=2)
        self.assertEqual(run["fixes"], self.rx["fixes"])
        for name in OUTPUTS:
            self.assertTrue(same_output(os.path.join(run["out"], name), os.path.join(self.rx["out"], name)), name)

    def test_acquire_on_an_array_equals_the_file(self):
        from_file = ut.acquire(self.input, format="i8", fs=2.0e6, ms=1, noncoh=4)
        raw = np.fromfile(self.input, dtype=np.int8, count=2 * 2000 * 4).astype(np.float32)
        from_array = ut.acquire(raw[0::2] + 1j * raw[1::2], fs=2.0e6, ms=1, noncoh=4)
        self.assertGreater(from_file.size, 3)
        np.testing.assert_array_equal(from_file, from_array)
        # The detections are the satellites in view above the horizon, at their simulated Doppler.
        in_view = {s["prn"]: s for s in self.sim["satellites"]}
        for row in from_file:
            self.assertIn(int(row["prn"]), in_view)
            self.assertLess(abs(row["doppler_hz"] - in_view[int(row["prn"])]["doppler_hz"]), 100.0)

    def test_a_missing_file_raises_with_its_name(self):
        missing = os.path.join(self.dir, "no_such_recording.i8.bin")
        with self.assertRaises(ut.InputError) as caught:
            ut.receive(input=missing, format="i8", fs=2.0e6, out=os.path.join(self.dir, "missing"))
        self.assertIn("no_such_recording.i8.bin", str(caught.exception))
        self.assertIsInstance(caught.exception, ValueError)
        with self.assertRaises(ut.InputError) as caught:
            ut.receive(input=self.input, format="i8", fs=2.0e6, nav=missing + ".nav", out=os.path.join(self.dir, "m2"))
        self.assertIn("no_such_recording.i8.bin.nav", str(caught.exception))
        with self.assertRaises(ut.InputError) as caught:
            ut.read_solution(os.path.join(self.dir, "missing_run"))
        self.assertIn("solution.csv", str(caught.exception))

    def test_attitude_checks_its_files_against_the_array(self):
        antennas = os.path.join(SOURCE, "scenarios", "attitude_antennas.toml")  # three antennas
        with self.assertRaises(ut.InputError) as caught:
            ut.attitude([self.input], "i8", 2.0e6, antennas, os.path.join(self.dir, "attitude"), nav=NAV)
        self.assertIn("1 files for the 3 antennas of " + antennas, str(caught.exception))
        with self.assertRaises(ut.InputError) as caught:
            ut.attitude([self.input] * 3, "i8", 2.0e6, antennas, os.path.join(self.dir, "attitude"))
        self.assertIn("reference week", str(caught.exception))

    def test_bad_settings_raise_the_librarys_messages(self):
        with self.assertRaises(ut.InputError) as caught:
            ut.receive(input=self.input, format="i9", fs=2.0e6, out=os.path.join(self.dir, "bad"))
        self.assertIn("unknown sample format 'i9'", str(caught.exception))
        with self.assertRaises(ut.InputError) as caught:
            ut.receive(input=self.input, format="i8", fs=2.0e6, coupling="tight", out=os.path.join(self.dir, "bad"))
        self.assertIn("needs imu", str(caught.exception))
        with self.assertRaises(TypeError) as caught:
            ut.receive(input=self.input, format="i8", fs=2.0e6, out=os.path.join(self.dir, "bad"), no_such_option=1)
        self.assertIn("no_such_option", str(caught.exception))

    def test_fuse_writes_what_the_program_writes(self):
        folder = os.path.join(self.dir, "inertial")
        ut.simulate(INERTIAL, folder)
        truth = ut.read_truth(folder)
        self.assertIn("yaw_deg", truth.dtype.names)
        # Fixes at 1 Hz from the truth itself (sigma 1 m): the filter must stay within a few metres of it.
        step = int(round(1.0 / (truth["t_s"][1] - truth["t_s"][0])))
        gnss = os.path.join(folder, "gnss.csv")
        with open(gnss, "w") as f:
            f.write("t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m\n")
            for row in truth[::step]:
                f.write("%.6f,%.10f,%.10f,%.4f,%.5f,%.5f,%.5f,1,1,1\n" % (
                    row["t_s"], row["lat_deg"], row["lon_deg"], row["height_m"], row["vel_n_mps"], row["vel_e_mps"],
                    row["vel_d_mps"]))
        imu, truth_file = os.path.join(folder, "imu.csv"), os.path.join(folder, "truth.csv")
        summary = ut.fuse(imu, gnss, os.path.join(self.dir, "fuse"), truth=truth_file)
        self.assertEqual(summary, ut.read_summary(os.path.join(self.dir, "fuse")) | {"out": summary["out"]})
        nav = ut.read_nav(summary["out"])
        self.assertGreater(nav.size, 1000)
        self.assertLess(nav["t_s"][-1], 60.0 + 1e-6)
        self.assertEqual(summary["fixes_used"] + summary["fixes_before_start"], 61)  # 0..60 s at 1 Hz
        self.assertLess(summary["rms_all"]["position_3d_m"], 1.0)
        self.assertGreater(summary["rms_all"]["within_3sigma"], 0.95)
        if PROGRAM and os.path.exists(PROGRAM):
            out = os.path.join(self.dir, "fuse_cli")
            subprocess.run([PROGRAM, "fuse", "--imu", imu, "--gnss", gnss, "--truth", truth_file, "--out", out,
                            "--quiet"], check=True, stdout=subprocess.DEVNULL)
            self.assertTrue(same_output(os.path.join(out, "nav.csv"), os.path.join(summary["out"], "nav.csv")))
            self.assertTrue(same_output(os.path.join(out, "summary.json"),
                                        os.path.join(summary["out"], "summary.json")))
        # The report of a fuse run: the GNSS/INS figures, errors against the truth with the filter's 1-sigma.
        report = os.path.join(self.dir, "fuse_report")
        self.assertEqual(ultratrack.report.main([summary["out"], "--truth", truth_file, "--out", report]), 0)
        self.assertEqual({n[:-4] for n in os.listdir(report) if n.endswith(".png")},
                         {"nav_position_error", "nav_attitude", "nav_velocity"})
        with self.assertRaises(ut.InputError) as caught:
            ut.fuse(imu, gnss + ".missing", os.path.join(self.dir, "fuse_missing"))
        self.assertIn("gnss.csv.missing", str(caught.exception))

    def test_report_names_every_figure_it_made(self):
        out = os.path.join(self.dir, "report")
        truth = os.path.join(self.dir, "sim", "truth.csv")
        code = ultratrack.report.main([self.rx["out"], "--truth", truth, "--out", out, "--prn", "3"])
        self.assertEqual(code, 0)
        with open(os.path.join(out, "report.html")) as f:
            page = f.read()
        figures = sorted(n for n in os.listdir(out) if n.endswith(".png"))
        expected = {"cn0", "tracking_state", "prompt_iq", "position_map", "position_error", "velocity", "satellites_dop"}
        self.assertEqual({n[:-4] for n in figures}, expected)
        for name in figures:
            self.assertGreater(os.path.getsize(os.path.join(out, name)), 1000, name)
            self.assertIn('href="%s"' % name, page)
            self.assertIn('alt="%s"' % name, page)
        self.assertIn("summary.json", page)
        self.assertIn("<td>fixes</td>", page)
        self.assertIn("Prompt I/Q of PRN 3", page)
        # As a command: python3 -m ultratrack.report, on a folder with no files to plot, still a page.
        empty = os.path.join(self.dir, "empty_run")
        os.makedirs(empty)
        done = subprocess.run([sys.executable, "-m", "ultratrack.report", empty], capture_output=True, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertTrue(os.path.isfile(os.path.join(empty, "report", "report.html")))


if __name__ == "__main__":
    unittest.main(verbosity=2)
