"""A keyboard participant's whole session through `pbp-drake run ... --participant`, in
headless Chromium: its methods (two, PBP-Alt and teleop; the order of the default three is
tested headless, tests/builder/test_hsr_task.py) started from the page's Start buttons and
driven with the arrow keys, the questionnaire answered with clicks, Next clicked; while each
method runs the page shows the live status (the method's name, the time left, then the
result) and the Stop, Restart and Next scene buttons; Next scene ends teleop's run as it
stands. The session then holds every method's trial, with the keys' input in it (teleop's
ended early), and `questionnaire.json` the clicked answers; the page
ends on "Session complete", never on Meshcat's reconnect banner.

Needs Debian's `chromium` and Playwright from PyPI, as tests/e2e/test_browser_end_to_end.py.
"""

import json
import re
import sys
import time

import pytest
from browser_page import (
    NEEDS_BROWSER, banner_shown, click, console_line, control, free_port, open_page, running)

from pbp_drake.console.questionnaire import answer_labels, next_label, start_label
from pbp_drake.console.text import method_name
from pbp_drake.studies.sessions import session_order

pytestmark = NEEDS_BROWSER

# Each run's time limit (s): the session moves on when it passes. Long enough for the keys
# to land: a page rendered in software handles them seconds late while the robot moves,
# over ten seconds on a busy machine (at 10 s a run saw none of them in two fresh-clone
# runs of the suite of five).
DURATION = 20.0
ANSWERS = {"pbp_alternated": (4, 3), "teleop": (1, 0)}
COMPLETE = "Session complete - you can close this page"
# Next scene ends this method's run as it stands (saved): teleop's robot never reaches the
# target with the left arrow alone, so nothing else ends it before its time limit.
ENDED_BY_NEXT_SCENE = "teleop"


def label_of(question, value):
    return next(label for label, v in answer_labels(question).items() if v == value)


def hold_left(page, seconds):
    """The Left arrow held for `seconds`, as a browser's key auto-repeat sends it."""
    end = time.monotonic() + seconds
    while (now := time.monotonic()) < end:
        page.keyboard.press("ArrowLeft")
        time.sleep(max(0.0, 0.05 - (time.monotonic() - now)))


@pytest.mark.timeout(480)
def test_a_whole_keyboard_session_is_run_from_the_page(repo, tmp_path):
    output = tmp_path / "P03"
    order = session_order(list(ANSWERS), "P03")
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--operator", "keyboard", "--participant", "P03", "--methods", ",".join(ANSWERS),
               "--duration", str(DURATION),
               "--port", str(free_port()), "--output", str(output),
               "--wait-for-browser", "60"]
    seen = {}
    with running(command, cwd=repo) as (process, lines):
        url = lines.wait_for(r"^Meshcat: (http://\S+)", timeout=60)
        assert url, f"no Meshcat URL from pbp-drake:\n{lines.text()}"
        with open_page(url.group(1), (800, 600), timeout_ms=30_000) as page:
            for position, method in enumerate(order, start=1):
                click(page, start_label(method, position, len(order)))
                # The keys work once the page has the keyboard operator's buttons and
                # this method's run has started (its title shows once its scene is in
                # the page, with its Start): press at once, while it runs.
                page.wait_for_selector("text=Left (←)", state="attached")
                console_line(page, "title").filter(
                    has_text=f"{method_name(method)}, seed 0").wait_for()
                # Held until the status counts it: a page rendered in software may handle
                # the keys seconds late, the later the busier the machine (at most the run).
                status = console_line(page, "status")
                counts = r"^time left \d+ s · \d+ target switch(es)? · intervention "
                hold_left(page, 1.5)
                deadline = time.monotonic() + DURATION
                while (not status.filter(has_text=re.compile(counts + r"[1-9]\d* %$")).count()
                       and time.monotonic() < deadline):
                    hold_left(page, 0.5)
                status.filter(has_text=re.compile(counts + r"\d+ %$")).wait_for()
                seen[method] = {b: control(page, b).count()
                                for b in ("Stop", "Restart", "Next scene")}
                if method == ENDED_BY_NEXT_SCENE:
                    click(page, "Next scene")
                    ended = r"^Result: stopped at \d+\.\d s$"
                else:
                    ended = r"^Result: (success in|failed: time limit)"
                # A run is paced at real time when the machine keeps up; on a loaded one its
                # 20 simulated seconds took over 50 s of wall time (a failure of the suite):
                # wait up to four times the run, which a quiet machine never needs.
                console_line(page, "result").filter(has_text=re.compile(ended)).wait_for(
                    timeout=(4 * DURATION + 30) * 1000)
                tiredness, ease = ANSWERS[method]
                click(page, label_of("tiredness", tiredness))
                click(page, label_of("ease", ease))
                if position < len(order):
                    click(page, next_label(position + 1, len(order)))
            done = lines.wait_for(r"^Session saved in ", timeout=60)
            assert done, f"the session did not end:\n{lines.text()}"
            # The page says the session is complete, and stays so once the command ends.
            console_line(page, "title").filter(has_text=COMPLETE).wait_for()
            click(page, "Close")
            process.wait(timeout=30)
            console_line(page, "notice").filter(has_text=COMPLETE).wait_for()
            page.wait_for_timeout(2_500)  # Meshcat's page would have shown its banner by now
            assert not banner_shown(page)
    assert seen == {m: {"Stop": 1, "Restart": 1, "Next scene": 1} for m in order}
    assert json.loads((output / "questionnaire.json").read_text())["answers"] == {
        method: {"tiredness": t, "ease": e} for method, (t, e) in ANSWERS.items()}
    trials = {method: json.loads((output / "trials" / method / "seed_0.json").read_text())
              for method in order}
    # The held arrow reached the robot: the person's input is in every method's run, the
    # one ended by Next scene too, which ended before its time limit.
    assert all(trials[m]["intervention_ratio"] > 0 for m in order), {
        m: trials[m]["intervention_ratio"] for m in order}
    assert not trials[ENDED_BY_NEXT_SCENE]["success"]
    assert trials[ENDED_BY_NEXT_SCENE]["task_time"] < DURATION - 1.0
    assert "Press Enter" not in lines.text()
