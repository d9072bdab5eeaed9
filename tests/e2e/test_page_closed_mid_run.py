"""A person's run whose page is closed mid-run, in a real browser: `pbp-drake run` an HSR
keyboard task, press Start, close the browser; the terminal says the run is paused with no
page, the simulated time stands where it was, and reopening the URL brings back the page
with its state and buttons and the run goes on to its end.

Needs Debian's `chromium` and Playwright from PyPI; skipped where either is missing.
"""

import re
import sys

import pytest
from browser_page import (
    NEEDS_BROWSER, click, console_line, control, free_port, open_page, running,
    simulated_time)

pytestmark = NEEDS_BROWSER

TOKEN = "a-page-closed-mid-run"
DURATION = 6.0


def page_time(page):
    """The simulated time of the page's status line, once it has one."""
    status = console_line(page, "status")
    return float(status.get_attribute("data-time") or "nan")


@pytest.mark.timeout(300)
def test_a_run_without_its_page_stands_still_until_it_is_reopened(repo):
    port = free_port()
    url = f"http://localhost:{port}/?token={TOKEN}"
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--operator", "keyboard", "--duration", str(DURATION), "--port", str(port),
               "--token", TOKEN, "--keep-page", "0"]
    with running(command, cwd=repo) as (process, output):
        assert output.wait_for(r"^Meshcat: http://", timeout=120), output.text()
        with open_page(url, (640, 400), timeout_ms=120_000) as page:
            click(page, "Start", timeout_ms=120_000)
            # The run goes: its status has passed 1 s of simulated time.
            page.wait_for_function("() => Number(document.getElementById('pbp-status')"
                                   ".getAttribute('data-time')) >= 1.0", timeout=120_000)
        # The browser is gone: the run waits, in one line.
        paused = output.wait_for(r"Paused at (\d+\.\d) s: no page is open and in view, so "
                                 rf"nobody drives; reopen {re.escape(url)} or bring its tab "
                                 "back to go on", timeout=60)
        assert paused, output.text()
        held = float(paused.group(1))
        assert 1.0 <= held < DURATION
        # The clock stands still: the page front's state says the same time, read after
        # read, as long as no page is open.
        times = {simulated_time(port, TOKEN) for _ in range(20)}
        assert len(times) == 1 and abs(times.pop() - held) <= 0.05 + 1e-9, times
        with open_page(url, (640, 400), timeout_ms=120_000) as page:
            assert output.wait_for(r"A page is in view again: the run goes on", timeout=60), (
                output.text())
            # The reopened page has the run's state and its buttons.
            console_line(page, "title").filter(has_text="PBP-Alt, seed 0").wait_for()
            try:
                control(page, "Stop").wait_for(state="attached", timeout=30_000)
            except Exception as error:  # Playwright's TimeoutError: say what the run said
                output.wait_for(r"^hsr_reach \[", timeout=15)
                raise AssertionError(f"no Stop on the reopened page (its body's class: "
                                     f"{page.evaluate('document.body.className')!r}): "
                                     f"{error}\n{output.text()}") from None
            assert page_time(page) >= held - 1e-9
            end = output.wait_for(r"^hsr_reach \[pbp_alternated, seed 0\]: (.*)$",
                                  timeout=120)
            assert end, output.text()
        assert process.wait(timeout=60) in (0, 1), output.text()
    assert "stopped" not in end.group(1), end.group(0)
