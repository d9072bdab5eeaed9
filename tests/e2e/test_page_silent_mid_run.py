"""A person's run whose page stays connected but cannot be driven, in a real browser: its
tab hidden, then its script stopped (a frozen tab, a sleeping laptop: the socket open, the
page silent). Each time the terminal says the run is paused, the simulated time stands
still, and the run goes on once the page is in view and heard again.

The page is stopped by pausing its script with the DevTools protocol (`Debugger.pause`):
headless Chromium ignores `Page.setWebLifecycleState` "frozen" for a page in view. Needs
Debian's `chromium` and Playwright from PyPI; skipped where either is missing.
"""

import sys

import pytest
from browser_page import NEEDS_BROWSER, click, free_port, open_page, running, simulated_time

pytestmark = NEEDS_BROWSER

TOKEN = "a-page-silent-mid-run"
# s: room, after the hidden tab, for a silence to be noticed (`front.SILENCE_LIMIT`).
DURATION = 20.0
PAUSED = r"Paused at (\d+\.\d) s: no page is open and in view"
BACK = r"A page is in view again: the run goes on"
# The tab's visibility as the browser would report it, announced as the browser would.
SET_HIDDEN = """hidden => {
  Object.defineProperty(document, "hidden", {value: hidden, configurable: true});
  document.dispatchEvent(new Event("visibilitychange"));
}"""


def stands_still(port, held):
    """The page front's simulated time, read after read, is the one the run paused at."""
    times = {simulated_time(port, TOKEN) for _ in range(20)}
    return len(times) == 1 and abs(times.pop() - held) <= 0.05 + 1e-9


@pytest.mark.timeout(300)
def test_a_run_stands_still_while_its_page_is_hidden_or_silent(repo):
    port = free_port()
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--operator", "keyboard", "--duration", str(DURATION), "--port", str(port),
               "--token", TOKEN, "--keep-page", "0"]
    with running(command, cwd=repo) as (process, output):
        assert output.wait_for(r"^Meshcat: http://", timeout=120), output.text()
        url = f"http://localhost:{port}/?token={TOKEN}"
        with open_page(url, (640, 400), timeout_ms=120_000) as page:
            click(page, "Start", timeout_ms=120_000)
            page.wait_for_function("() => Number(document.getElementById('pbp-status')"
                                   ".getAttribute('data-time')) >= 1.0", timeout=120_000)
            page.evaluate(SET_HIDDEN, True)
            paused = output.wait_for(PAUSED, timeout=60)
            assert paused, output.text()
            assert stands_still(port, float(paused.group(1)))
            page.evaluate(SET_HIDDEN, False)
            assert output.wait_for(BACK, timeout=60), output.text()
            page.wait_for_function("held => Number(document.getElementById('pbp-status')"
                                   ".getAttribute('data-time')) >= held + 0.5",
                                   arg=float(paused.group(1)), timeout=120_000)
            devtools = page.context.new_cdp_session(page)
            devtools.send("Debugger.enable")
            devtools.send("Debugger.pause")  # the page says nothing more, its socket open
            paused = output.wait_for(PAUSED, timeout=60)
            assert paused, output.text()
            assert stands_still(port, float(paused.group(1)))
            devtools.send("Debugger.resume")
            assert output.wait_for(BACK, timeout=60), output.text()
            end = output.wait_for(r"^hsr_reach \[pbp_alternated, seed 0\]: (.*)$",
                                  timeout=120)
            assert end, output.text()
        assert process.wait(timeout=60) in (0, 1), output.text()
    assert "stopped" not in end.group(1), end.group(0)
