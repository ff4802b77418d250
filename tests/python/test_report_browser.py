# SPDX-License-Identifier: GPL-3.0-or-later
"""The reports of a receive, an ultra-tight and an attitude run render in headless Chromium without a console
message (the page has no script: any is a problem); the screenshots are kept in the artefacts folder. A page with a
script error must be caught by the same check (else the check could not fail). Chromium does not log a missing
file:// image, so the page's links are checked against the folder instead."""
import os
import re
import shutil
import subprocess

import pytest

from matplotlib import image

CHROMIUM = os.environ.get("ULTRATRACK_CHROMIUM") or shutil.which("chromium") or ""
# Chromium's log line of a page's console message ("INFO:CONSOLE:1] "..."", source: ...), or of a failed load.
CONSOLE_PROBLEM = re.compile(r"CONSOLE[:(]|Uncaught|Failed to load resource|net::ERR_")


def render(html, screenshot, height, min_bytes=10000):
    """Loads the page in headless Chromium, screenshots it; returns the log lines that report a problem."""
    if not CHROMIUM:
        pytest.fail("chromium not found (Debian package chromium, as tools/run.sh test installs; or "
                    "ULTRATRACK_CHROMIUM=/path/to/chromium)")
    profile = screenshot + ".profile"
    done = subprocess.run(
        [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
         "--user-data-dir=" + profile, "--enable-logging=stderr", "--v=0", "--hide-scrollbars",
         "--window-size=1200,%d" % height, "--screenshot=" + screenshot, "file://" + os.path.abspath(html)],
        capture_output=True, text=True, timeout=120)
    shutil.rmtree(profile, ignore_errors=True)
    assert done.returncode == 0, done.stderr[-2000:]
    assert os.path.getsize(screenshot) > min_bytes, screenshot
    return [l for l in done.stderr.splitlines() if CONSOLE_PROBLEM.search(l)]


def test_the_check_catches_a_broken_page(artefacts):
    page = os.path.join(artefacts, "broken.html")
    with open(page, "w") as f:
        f.write("<!DOCTYPE html><html><body><p>broken</p><script>console.error('broken');"
                "no_such_function();</script></body></html>")
    problems = render(page, os.path.join(artefacts, "broken.png"), height=200, min_bytes=500)
    assert any("no_such_function" in l for l in problems), problems
    assert any("broken" in l for l in problems), problems


@pytest.mark.parametrize("name", ["scalar", "ultra-tight", "attitude"])
def test_report_renders_without_console_errors(runs, artefacts, name):
    out = runs.report(name)
    figures = [n for n in os.listdir(out) if n.endswith(".png")]
    assert len(figures) >= 8
    assert all(os.path.getsize(os.path.join(out, n)) > 1000 for n in figures)
    path = os.path.join(out, "report.html")
    with open(path) as f:
        links = re.findall(r'(?:href|src)="([^"]+)"', f.read())
    assert all(l.startswith("data:image/png;base64,") or os.path.isfile(os.path.join(out, l)) for l in links)
    screenshot = os.path.join(artefacts, "screenshot_%s.png" % name)
    assert render(path, screenshot, height=600 * len(figures) + 1500) == []
    pixels = image.imread(screenshot)
    assert pixels.shape[1] == 1200 and pixels.std() > 0.05  # drawn, not a blank page
