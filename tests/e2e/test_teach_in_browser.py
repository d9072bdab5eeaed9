"""Teaching a primitive in a real browser: `pbp-drake teach` with the keyboard, its page in
headless Chromium: Start, the Left arrow held (the hand goes to its left), Stop; the
primitive is saved, its demonstration the path driven, and the drive's rows beside it.

Needs Debian's `chromium` and Playwright from PyPI; skipped where either is missing.
"""

import json
import re
import sys
import time

import pytest
from browser_page import NEEDS_BROWSER, click, console_line, free_port, open_page, running

from pbp_drake.cli_types import EXIT_SUCCESS

pytestmark = NEEDS_BROWSER


@pytest.mark.timeout(180)
def test_start_drive_stop_saves_the_primitive_of_the_path_driven(repo, tmp_path):
    output = tmp_path / "taught.json"
    command = [sys.executable, "-m", "pbp_drake", "teach", "diagrams/hsr_reach.yaml",
               "--operator", "keyboard", "--output", str(output), "--port", str(free_port())]
    with running(command, cwd=repo) as (process, lines):
        url = lines.wait_for(r"^Meshcat: (http://\S+)", timeout=60)
        assert url, f"no Meshcat URL from pbp-drake teach:\n{lines.text()}"
        with open_page(url.group(1), (1024, 640), timeout_ms=60_000) as page:
            status = console_line(page, "status")
            status.filter(has_text="press Start when ready").wait_for()
            page.wait_for_selector("text=Left (←)", state="attached")
            click(page, "Start")
            status.filter(has_text=re.compile(r"^time left")).wait_for()
            # Held as a key's auto-repeat holds it, for 3 s: the hand goes left.
            end = time.monotonic() + 3.0
            while (now := time.monotonic()) < end:
                page.keyboard.press("ArrowLeft")
                time.sleep(max(0.0, 0.05 - (time.monotonic() - now)))
            time.sleep(0.5)
            click(page, "Stop")
            code = process.wait(timeout=60)
        saved = lines.wait_for(r"^Taught from \d+ samples .* Saved to ", timeout=10)
    assert code == EXIT_SUCCESS and saved, lines.text()
    document = json.loads(output.read_text())
    positions = document["demonstration"]["positions"]
    assert positions[-1][1] - positions[0][1] > 0.1, positions[-1]  # to the hand's left
    assert output.with_suffix(".csv").read_text().startswith("time,ee_x,ee_y,ee_z")
