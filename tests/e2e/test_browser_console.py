"""The operator's console in a real browser: `pbp-drake run` an HSR keyboard
task from a terminal (a pseudo-terminal here), open its page in headless Chromium, read the
live status (the method, the time left, then the result) and the Stop, Restart and Next
scene buttons in the page's controls; Next scene runs the next seed, and Stop ends it and
the process.

Needs Debian's `chromium` and Playwright from PyPI; skipped where either is missing.
"""

import os
import pty
import re
import sys

import pytest
from browser_page import NEEDS_BROWSER, free_port, open_page, running

pytestmark = NEEDS_BROWSER

DURATION = 4.0  # the time limit: the keyboard task fails without keys, and the page stays


def controls_of(page):
    """`control(label)`: the row of the page's control panel (Meshcat's dat.gui) whose label
    is exactly `label`, a regular expression."""
    return lambda label: page.locator(".dg li.cr").filter(
        has=page.locator(".property-name", has_text=re.compile(f"^{label}$")))


@pytest.mark.timeout(120)
def test_the_page_shows_the_run_and_stop_ends_it(repo):
    port = free_port()
    # A terminal on stdin: an interactive run, whose page stays live after the task.
    terminal, stdin = pty.openpty()
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--operator", "keyboard", "--camera", "robot", "--duration", str(DURATION),
               "--port", str(port)]
    try:
        with running(command, cwd=repo, stdin=stdin) as (process, output):
            os.close(stdin)  # the process holds the terminal now
            url = output.wait_for(r"^Meshcat: (http://\S+)", timeout=60)
            assert url, f"no Meshcat URL from pbp-drake:\n{output.text()}"
            with open_page(url.group(1)) as page:
                control = controls_of(page)
                control("PBP-Alt, seed 0").wait_for(state="attached")
                control(r"time left \d+ s · 0 target switches · intervention 0 %").wait_for(
                    state="attached")
                control("Result: failed: time limit").wait_for(
                    state="attached", timeout=(DURATION + 20) * 1000)
                assert process.poll() is None, "the run quit before Stop"
                assert all(control(name).count() == 1
                           for name in ("Stop", "Restart", "Next scene"))
                # The panel may be folded: send the click its row would. Next scene runs
                # seed 1 at once; Stop then ends it, and the process, mid-run.
                control("Next scene").dispatch_event("click")
                control("PBP-Alt, seed 1").wait_for(state="attached")
                control("Stop").dispatch_event("click")
                code = process.wait(timeout=20)
    finally:
        os.close(terminal)
    output.wait_for(r"$^", timeout=2)  # the rest of the output, for the messages below
    assert code == 1, output.text()  # the task failed: no keys were pressed
    text = output.text()
    assert re.search(r"^hsr_reach \[pbp_alternated, seed 0\]: FAILED in [34]\.\d\d s",
                     text, re.M), text
    assert "Stop (or Enter, or Ctrl-C) quits" in text
    assert "Next scene: seed 1." in text
    assert re.search(r"^hsr_reach \[pbp_alternated, seed 1\]: FAILED in [0-3]\.\d\d s",
                     text, re.M), text
