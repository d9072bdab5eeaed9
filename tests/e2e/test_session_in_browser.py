"""A keyboard participant's session through `pbp-drake run ... --participant`, in headless
Chromium: the page's Start buttons, the questionnaire's buttons and Next, clicked in the
control panel as a person would; the session saves both runs and the answers, and nothing is
asked on the terminal. (The person presses no key: the runs end at their short time limit.)

Needs Debian's `chromium` and Playwright from PyPI, as tests/e2e/test_browser_end_to_end.py.
"""

import json
import subprocess
import sys

import pytest

from pbp_drake.console.questionnaire import answer_labels, next_label, start_label
from test_browser_end_to_end import (
    CHROMIUM, CHROMIUM_ARGS, Output, free_port, sync_playwright)

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed"),
    pytest.mark.skipif(sync_playwright is None, reason="playwright is not installed"),
]


def label_of(question, value):
    return next(label for label, v in answer_labels(question).items() if v == value)


@pytest.mark.timeout(180)
def test_a_keyboard_session_is_run_from_the_page(repo, tmp_path):
    output = tmp_path / "P03"
    # P03 rotates teleop,pbp_alternated by 3 % 2 = 1: PBP-Alt comes first.
    clicks = [start_label("pbp_alternated", 1, 2), label_of("tiredness", 4),
              label_of("ease", 3), next_label(2, 2), start_label("teleop", 2, 2),
              label_of("tiredness", 1), label_of("ease", 5)]
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--operator", "keyboard", "--participant", "P03", "--methods",
               "teleop,pbp_alternated", "--duration", "2", "--port", str(free_port()),
               "--output", str(output), "--wait-for-browser", "60"]
    process = subprocess.Popen(command, cwd=repo, stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        lines = Output(process.stdout)
        url = lines.wait_for(r"^Meshcat: (http://\S+)", timeout=60)
        assert url, f"no Meshcat URL from pbp-drake:\n{lines.text()}"
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS,
                                                 timeout=30_000)
            try:
                page = browser.new_page(viewport={"width": 1280, "height": 720})
                page.goto(url.group(1), wait_until="load")
                page.get_by_text("Open Controls", exact=True).click(timeout=30_000)
                for label in clicks:
                    name = page.locator("span.property-name").get_by_text(label, exact=True)
                    button = page.locator("li.cr.function", has=name)
                    button.click(timeout=60_000)  # waits until the page shows it
            finally:
                browser.close()
        done = lines.wait_for(r"^Session saved in ", timeout=60)
        assert done, f"the session did not end:\n{lines.text()}"
        assert process.wait(timeout=30) == 1  # no key pressed: both runs failed
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(timeout=10)
    assert json.loads((output / "questionnaire.json").read_text()) == {
        "pbp_alternated": {"tiredness": 4, "ease": 3}, "teleop": {"tiredness": 1, "ease": 5}}
    assert sorted(p.parent.name for p in (output / "trials").rglob("seed_0.json")) == [
        "pbp_alternated", "teleop"]
    assert "Press Enter" not in lines.text()
