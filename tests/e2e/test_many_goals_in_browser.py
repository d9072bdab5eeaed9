"""Ten thousand candidate goals, live: a keyboard run of the reaching task with
`--goals 10000` in headless Chromium keeps real time from Start on, and the page's status
keeps up with the simulation (the page is sent what a few goals' page is sent)."""

import sys
import time

import pytest
from browser_page import (
    NEEDS_BROWSER, click, console_line, free_port, open_page, running, simulated_time)

pytestmark = NEEDS_BROWSER

TOKEN = "many-goals-test-token-0123456789"
GOALS = 10_000
MAX_LAG = 1.0  # s, for nine samples in ten
# A software-rendered Chromium on a shared 2-core machine stalls now and then for a sample
# (1.25 s seen once in a run whose other samples were 0.2 to 0.75 s); a page that fell
# behind would stay behind, past both bounds.
MAX_STALL = 2.0  # s


def server_time(port):
    return simulated_time(port, TOKEN)


@pytest.mark.timeout(240)
def test_ten_thousand_goals_run_live_in_the_browser(repo):
    port = free_port()
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--goals", str(GOALS), "--operator", "keyboard", "--duration", "30",
               "--port", str(port), "--token", TOKEN, "--keep-page", "0"]
    with running(command, cwd=repo) as (process, output):
        url = output.wait_for(r"^Meshcat: (http://\S+)", timeout=60)
        assert url, f"no Meshcat URL from pbp-drake:\n{output.text()}"
        with open_page(url.group(1), (1024, 640), timeout_ms=120_000) as page:
            status = console_line(page, "status")
            status.filter(has_text="press Start when ready").wait_for()
            click(page, "Start", timeout_ms=120_000)
            first_time, first_wall = server_time(port), time.monotonic()
            lags = []
            while time.monotonic() - first_wall < 12.0 and process.poll() is None:
                now = server_time(port)
                shown = page.evaluate(
                    "() => document.getElementById('pbp-status').getAttribute('data-time')")
                lags.append(now - float(shown))
                time.sleep(0.25)
            rate = (server_time(port) - first_time) / (time.monotonic() - first_wall)
    print(f"simulated s per wall s {rate:.2f}; lags (s):", [round(lag, 2) for lag in lags])
    # Real time, measured from outside: a loop that could not keep up would fall below.
    assert rate >= 0.9, rate
    ninth_decile = sorted(lags)[int(0.9 * len(lags))] if lags else float("inf")
    assert len(lags) >= 10 and ninth_decile <= MAX_LAG and max(lags) <= MAX_STALL, [
        round(lag, 2) for lag in lags]
