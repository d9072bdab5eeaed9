"""Stop pressed in a real browser ends `pbp-drake run` cleanly every time: twenty runs, one
after the other in one process (each its page, its relays and their event loop), Stop
pressed in each, and not one line about a task destroyed while pending or an event loop
missing, nor any traceback; and the ended page has no button left that nothing answers.

Needs Debian's `chromium` and Playwright from PyPI; skipped where either is missing.
"""

import sys

import pytest
from browser_page import NEEDS_BROWSER, click, console_line, control, free_port, open_page, running

pytestmark = NEEDS_BROWSER

RUNS = 20
TOKEN = "twenty-runs-one-after-the-other"
# Twenty runs of the 2-D scene in one process, each ended by Stop in the page.
SCRIPT = f"""
import sys
from pbp_drake.cli import main
for run in range({RUNS}):
    code = main(["run", "diagrams/toy_alt_vs_cont.yaml", "--duration", "600",
                 "--port", sys.argv[1], "--token", "{TOKEN}", "--keep-page", "0"])
    print(f"run {{run}} exit {{code}}", flush=True)
"""


@pytest.mark.timeout(1200)
def test_twenty_runs_stopped_in_the_page_end_cleanly(repo):
    port = free_port()
    url = f"http://localhost:{port}/?token={TOKEN}"
    with running([sys.executable, "-c", SCRIPT, str(port)], cwd=repo) as (process, output):
        # A small page: the least for software WebGL to draw.
        with open_page("about:blank", (640, 400), timeout_ms=120_000) as page:
            for run in range(RUNS):
                assert output.wait_for(rf"^Meshcat: http://\S+:{port}/", timeout=60), (
                    output.text())
                page.goto(url, wait_until="load")
                click(page, "Stop", timeout_ms=120_000)
                console_line(page, "notice").filter(
                    has_text="you can close this page").wait_for()
                assert output.wait_for(rf"^run {run} exit 3$", timeout=60), output.text()
                # The ended page: no Stop nor slider that nothing answers any more.
                assert control(page, "Stop").count() == 0
                assert control(page, "Real-time rate").count() == 0
        assert process.wait(timeout=60) == 0
    output.wait_for(r"$^", timeout=2)  # the rest of the output
    text = "\n".join(output.lines)
    for sign in ("Task was destroyed", "no running event loop", "Traceback", "Exception"):
        assert sign not in text, text
