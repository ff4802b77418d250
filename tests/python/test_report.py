# SPDX-License-Identifier: GPL-3.0-or-later
"""python3 -m ultratrack.report on the output of every command: the figures each run's files give (and no other),
every figure a non-empty PNG named in the page, and a folder with nothing to plot still a page. The reports are
kept in the artefacts folder (ULTRATRACK_ARTEFACTS) for a look."""
import os
import subprocess
import sys

import pytest

import ultratrack as ut
import ultratrack.report

TRACKING = {"sky", "cn0", "tracking_state", "prompt_iq", "position_map", "position_error", "velocity",
            "satellites_dop"}
INERTIAL = {"nav_position_error", "nav_attitude", "nav_velocity"}
FIGURES = {
    "scalar": TRACKING,
    "vector": TRACKING | {"vector_innovations", "vector_nis"},
    "loose": TRACKING | INERTIAL,
    "tight": TRACKING | INERTIAL,
    "ultra-tight": TRACKING | INERTIAL | {"ultratight_nis", "ultratight_innovations"},
    "attitude": TRACKING | {"attitude"},
    "align": {"alignment_attitude", "alignment_biases"},
    "snapshot": {"sky", "position_map", "position_error", "snapshot_residuals"},
    "fuse": INERTIAL,
}
TABLES = {"align": "alignment.json", "snapshot": "snapshot.json"}


def check_report(folder, expected, table):
    with open(os.path.join(folder, "report.html")) as f:
        page = f.read()
    figures = sorted(n for n in os.listdir(folder) if n.endswith(".png"))
    assert {n[:-4] for n in figures} == expected
    for name in figures:
        assert os.path.getsize(os.path.join(folder, name)) > 1000, name
        assert 'href="%s"' % name in page and 'alt="%s"' % name in page
    assert "Summary (%s)" % table in page
    return page


@pytest.mark.parametrize("name", sorted(FIGURES))
def test_report_of_every_command(runs, name):
    page = check_report(runs.report(name), FIGURES[name], TABLES.get(name, "summary.json"))
    if name == "scalar":
        assert "<td>fixes</td>" in page


def test_report_as_a_command(runs, workdir):
    out = os.path.join(workdir, "report_prn")
    run = runs.receive("scalar")
    prn = int(ut.read_tracking(run["out"])["prn"][0])
    done = subprocess.run([sys.executable, "-m", "ultratrack.report", run["out"], "--out", out, "--prn", str(prn)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    page = check_report(out, TRACKING - {"position_error"}, "summary.json")  # no truth: no errors
    assert "Prompt I/Q of PRN %d" % prn in page
    empty = os.path.join(workdir, "empty_run")
    os.makedirs(empty)
    done = subprocess.run([sys.executable, "-m", "ultratrack.report", empty], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    with open(os.path.join(empty, "report", "report.html")) as f:
        assert "No file of this folder has a figure." in f.read()
    done = subprocess.run([sys.executable, "-m", "ultratrack.report", os.path.join(workdir, "no_such_run")],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "no_such_run: not a folder" in done.stderr
