"""The operator's console in a real browser: `pbp-drake run` an HSR keyboard task, open
its page in headless Chromium, press Start, read the live status in the console panel (the
method, the time left) and the Stop, Restart and Next scene buttons; Next scene runs the
next seed, and Stop ends it: `stopped at` in the terminal and in the page, the exit code of
a stop, and the page left on its result, never on Meshcat's reconnect banner.

Needs Debian's `chromium` and Playwright from PyPI; skipped where either is missing.
"""

import re
import sys

import pytest
from browser_page import (
    NEEDS_BROWSER, banner_shown, click, console_line, control, free_port, open_page, running)

from pbp_drake.cli_types import EXIT_STOPPED

pytestmark = NEEDS_BROWSER

DURATION = 30.0  # the time limit: long enough that Stop, not the limit, ends seed 1
KEYS_AND_CHOICES = {"Back (↓)", "Left (←)", "Right (→)", "Turn left (Q)", "Turn right (E)",
                    "Real-time rate", "Stop", "Restart", "Next scene", "Start"}


def controls_in_order(page):
    """The labels of the run's controls (the keys, the slider, the choices) as the page
    lists them, top to bottom."""
    names = page.evaluate("() => Array.from(document.querySelectorAll("
                          "'.dg li.cr .property-name')).map(e => e.textContent)")
    return [name for name in names if name in KEYS_AND_CHOICES]


@pytest.mark.timeout(180)
def test_stop_ends_the_run_honestly_and_the_page_keeps_the_result(repo, tmp_path):
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--operator", "keyboard", "--duration", str(DURATION), "--port",
               str(free_port())]
    with running(command, cwd=repo) as (process, output):
        url = output.wait_for(r"^Meshcat: (http://\S+)", timeout=60)
        assert url, f"no Meshcat URL from pbp-drake:\n{output.text()}"
        with open_page(url.group(1), (1024, 640), timeout_ms=60_000) as page:
            title, status, result = (console_line(page, name)
                                     for name in ("title", "status", "result"))
            title.filter(has_text="PBP-Alt, seed 0").wait_for()
            status.filter(has_text="press Start when ready").wait_for()
            click(page, "Start")
            status.filter(has_text=re.compile(
                r"^time left \d+ s · 0 target switches · intervention 0 %$")).wait_for()
            assert all(control(page, name).count() == 1
                       for name in ("Stop", "Restart", "Next scene"))
            # Readable at 1024 x 640: the console's lines and its buttons on screen (the
            # scene tree folded), not below Meshcat's whole tree.
            for element in (status, control(page, "Stop"), control(page, "Next scene")):
                box = element.bounding_box()
                assert box and box["y"] + box["height"] <= 640 and box["x"] >= 0, box
            order = controls_in_order(page)
            # Next scene runs seed 1, which waits for its Start again; Stop then ends it,
            # and the command, mid-run.
            click(page, "Next scene")
            title.filter(has_text="PBP-Alt, seed 1").wait_for()
            control(page, "Start").wait_for(state="attached")
            # The keys come back, and everything keeps its place.
            assert controls_in_order(page) == order + ["Start"], controls_in_order(page)
            click(page, "Start")
            status.filter(has_text=re.compile(r"^time left \d+ s")).wait_for()
            click(page, "Stop")
            code = process.wait(timeout=60)
            # The command has ended: the page still shows the result, and says the run is
            # over instead of Meshcat's "No connection to server".
            result.filter(has_text=re.compile(r"^Result: stopped at \d+\.\d s")).wait_for()
            console_line(page, "notice").filter(has_text="you can close this page").wait_for()
            page.wait_for_timeout(2_500)  # Meshcat's page would have shown its banner by now
            assert not banner_shown(page)
            page.screenshot(path=str(tmp_path / "after_stop.png"))
    output.wait_for(r"$^", timeout=2)  # the rest of the output, for the messages below
    text = output.text()
    assert code == EXIT_STOPPED, text
    assert "Next scene: seed 1." in text
    # Next scene ended seed 0 as it stood, Stop seed 1: the person's choice, not a failure.
    assert re.search(r"^hsr_reach \[pbp_alternated, seed 0\]: stopped at \d+\.\d\d s, ",
                     text, re.M), text
    assert re.search(r"^hsr_reach \[pbp_alternated, seed 1\]: stopped at \d+\.\d\d s, ",
                     text, re.M), text
    assert "FAILED" not in text, text
