"""A session in the Meshcat page, clicked through as a person would: the Start button names
the method that comes, the two questions are answered with their 0-5 buttons (both ends
saying what they mean), Next leads on, and the answers land in questionnaire.json beside the
questions as asked. The clicks come over a raw websocket, as the page
sends them (`foreign_page.ForeignPage`), and, in the slow test, from headless Chromium.

Meshcat is made and polled on the test's thread (Drake's rule); the clicker runs on a thread
of its own and, should it fail, interrupts the test's thread so that nothing waits forever.
"""

import _thread
import dataclasses
import json
import threading
import time

import pytest

from browser_page import CHROMIUM, open_page, sync_playwright
from foreign_page import ForeignPage
from pbp_drake.builder.run import run_task
from pbp_drake.console.questionnaire import (
    MeshcatSessionPage, answer_labels, next_label, start_label)
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.studies.sessions import run_session, session_order
from pbp_drake.studies.trial_files import trial_paths

TASK = "diagrams/hsr_reach.yaml"
METHODS = ["pbp_alternated", "teleop"]


def label_of(question, value):
    return next(label for label, v in answer_labels(question).items() if v == value)


# What a person clicks for P02 (order: PBP-Alt, then Teleop), and the answers it gives.
CLICKS = [start_label("pbp_alternated", 1, 2), label_of("tiredness", 2), label_of("ease", 5),
          next_label(2, 2), start_label("teleop", 2, 2), label_of("tiredness", 0),
          label_of("ease", 4)]
ANSWERS = {"pbp_alternated": {"tiredness": 2, "ease": 5},
           "teleop": {"tiredness": 0, "ease": 4}}


@pytest.fixture
def short_task(repo):
    scenario = load_scenario_file(repo / TASK).scenario
    return dataclasses.replace(scenario, duration=0.3)


def run_clicked_session(meshcat, short_task, output, clicker):
    """Runs P02's session with the page in `meshcat`, `clicker(pressed, errors)` on a
    thread; returns the labels pressed before each run started, and the clicker's errors."""
    pressed, errors, seen_at_start = [], [], []

    def guarded():
        try:
            clicker(pressed, errors)
        except Exception as error:  # the test's thread waits on the page: wake it
            errors.append(f"{type(error).__name__}: {error}")
        if errors:
            _thread.interrupt_main()

    def run(trial):
        seen_at_start.append((trial.scenario.method, list(pressed)))
        return run_task(trial)

    thread = threading.Thread(target=guarded, daemon=True)
    thread.start()
    try:
        run_session(short_task, "P02", METHODS, output, run, MeshcatSessionPage(meshcat))
    except KeyboardInterrupt:
        pytest.fail(f"the clicker failed: {errors}")
    thread.join(timeout=30)
    assert not errors, errors
    return seen_at_start, pressed


def check_session(output, seen_at_start, pressed):
    assert session_order(METHODS, "P02") == METHODS
    assert pressed == CLICKS
    # Each method ran only after its Start button was clicked, the second only after the
    # first's questions and Next.
    assert seen_at_start == [("pbp_alternated", CLICKS[:1]), ("teleop", CLICKS[:5])]
    saved = json.loads((output / "questionnaire.json").read_text())
    assert saved["answers"] == ANSWERS
    # The file records the questions and what their ends meant, as the buttons said them.
    assert saved["questions"] == {
        "tiredness": {"question": "How tired did you feel?", "0": "very tired",
                      "5": "not tired at all"},
        "ease": {"question": "How easy was it to operate the robot?", "0": "very hard",
                 "5": "very easy"}}
    for method in METHODS:
        assert trial_paths(output, method, 0)[0].is_file()


def test_both_ends_of_each_question_say_what_they_mean():
    assert list(answer_labels("tiredness")) == [
        "0 = very tired: How tired did you feel?", "1: How tired did you feel?",
        "2: How tired did you feel?", "3: How tired did you feel?",
        "4: How tired did you feel?", "5 = not tired at all: How tired did you feel?"]
    ease = answer_labels("ease")
    assert label_of("ease", 0) == "0 = very hard: How easy was it to operate the robot?"
    assert label_of("ease", 5) == "5 = very easy: How easy was it to operate the robot?"
    assert list(ease.values()) == [0, 1, 2, 3, 4, 5]


@pytest.mark.slow
def test_a_session_is_clicked_through_in_the_page(meshcat, short_task, tmp_path):
    port = meshcat.port()

    def click(pressed, errors):
        page = ForeignPage(port, origin=f"http://localhost:{port}")
        try:
            position = 0
            for label in CLICKS:
                # The page learns of a button when Meshcat adds it; search past the last
                # one clicked, as the same labels come again for the second method.
                deadline = time.monotonic() + 60
                while (found := page.received().find(label.encode(), position)) < 0:
                    if time.monotonic() > deadline:
                        errors.append(f"the page never showed {label!r}")
                        return
                    time.sleep(0.02)
                position = found + len(label)
                pressed.append(label)
                page.press(label)
        finally:
            page.close()

    output = tmp_path / "P02"
    check_session(output, *run_clicked_session(meshcat, short_task, output, click))
    # The session's buttons are gone when it ends: nothing is left to click by mistake.
    assert not [name for name in meshcat.GetButtonNames() if "method" in name or ":" in name]


@pytest.mark.slow
@pytest.mark.browser
@pytest.mark.timeout(240)
@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed")
@pytest.mark.skipif(sync_playwright is None, reason="playwright is not installed")
def test_a_session_is_clicked_through_in_chromium(meshcat, short_task, tmp_path):
    url = meshcat.web_url()

    def click(pressed, errors):
        with open_page(url) as page:
            # Meshcat's control panel (dat.gui) starts closed.
            page.get_by_text("Open Controls", exact=True).click(timeout=30_000)
            for label in CLICKS:
                # The button as the person sees it in the control panel, by its text.
                name = page.locator("span.property-name").get_by_text(label, exact=True)
                button = page.locator("li.cr.function", has=name)
                button.wait_for(state="visible", timeout=60_000)
                pressed.append(label)
                button.click(timeout=30_000)

    output = tmp_path / "P02"
    check_session(output, *run_clicked_session(meshcat, short_task, output, click))
