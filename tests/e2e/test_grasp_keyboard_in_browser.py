"""A person at the browser drives the grasping task, end to end: `pbp-drake run` the grasp
task with the keyboard, open its Meshcat page in headless Chromium, see the six-DoF keys'
mode, hold the Left arrow, and check that the hand went left; then R switches the page's
mode label to turning.

Needs Debian's `chromium` and Playwright from PyPI (skipped where either is missing).
"""

import re
import sys
import time

import numpy as np
import pytest
from browser_page import NEEDS_BROWSER, click, free_port, open_page, running

from pbp_drake.systems.operators.pose_keyboard_operator import MODE_LABELS, ROTATE, TRANSLATE

pytestmark = NEEDS_BROWSER

DURATION = 10.0  # the task's time limit: the run ends by itself after it
START_Y = 0.078  # the palm starts at about (0.45, 0.08, 0.70), approach along world +x
RESULT = re.compile(r"^hsr_grasp \[teleop, seed 0\]: .*, hand at \[(\S+), (\S+), (\S+)\]$")


def hold(page, key, seconds):
    """Presses `key` as a browser's auto-repeat would, every ~50 ms (a key counts as held
    for hold_time, 0.6 s, after its last click)."""
    end = time.monotonic() + seconds
    while (now := time.monotonic()) < end:
        page.keyboard.press(key)
        time.sleep(max(0.0, 0.05 - (time.monotonic() - now)))


@pytest.mark.timeout(120)
def test_the_keyboard_moves_the_grasping_hand_from_the_page(repo):
    port = free_port()
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_grasp.yaml",
               "--method", "teleop", "--operator", "keyboard",
               "--duration", str(DURATION), "--port", str(port)]
    with running(command, cwd=repo) as (process, output):
        url = output.wait_for(r"^Meshcat: (http://\S+)", timeout=60)
        assert url, f"no Meshcat URL from pbp-drake:\n{output.text()}"
        assert output.wait_for(r"^Keys: arrows move the hand\b.*R switches to turning",
                               timeout=10), output.text()
        with open_page(url.group(1)) as page:
            page.wait_for_selector(f"text={MODE_LABELS[TRANSLATE]}", state="attached")
            click(page, "Start")
            time.sleep(1.0)
            hold(page, "ArrowLeft", 2.0)
            pressed_while_running = process.poll() is None
            page.keyboard.press("KeyR")
            page.wait_for_selector(f"text={MODE_LABELS[ROTATE]}", state="attached",
                                   timeout=5_000)
            # The page stays to the end: a person's run without its page stands still.
            result = output.wait_for(RESULT.pattern, timeout=DURATION + 30)
            assert result, f"no result line from pbp-drake:\n{output.text()}"
        process.wait(timeout=10)

    hand = np.array([float(value) for value in result.groups()])
    assert hand[1] > START_Y + 0.1, (
        f"the hand did not go left: it ended at {hand} (the keys were pressed "
        f"{'during' if pressed_while_running else 'after'} the run)\n{output.text()}")
