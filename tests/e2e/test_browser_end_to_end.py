"""A person at the browser, end to end: `pbp-drake run` the HSR reaching task with the
keyboard operator, open its Meshcat page in headless Chromium, hold the Left arrow, and
check that the hand went left and that the page shows the yellow target marker.

Needs Debian's `chromium` (`make test` installs it where it can) and Playwright from PyPI
(the `test` extra; never `playwright install`). Skipped where either is missing.
"""

import io
import re
import sys
import time

import matplotlib.image
import numpy as np
import pytest
from browser_page import NEEDS_BROWSER, click, free_port, open_page, running

pytestmark = NEEDS_BROWSER

# The task's time limit: long enough for the keys to land on a busy machine (a page
# rendered in software showed its buttons 10 s late); the test then ends the run from the
# page's Stop button rather than wait for it.
DURATION = 40.0
START_Y = 0.08  # the hand starts at about (0.53, 0.08, 0.70), pointing along world +x
MIN_YELLOW = 30  # the target ball shows ~70-80 such pixels at 1280 x 720
RESULT = re.compile(r"^hsr_reach \[teleop, seed 0\]: .*, hand at \[(\S+), (\S+), (\S+)\]$")


def yellow_pixel_count(png):
    """Pixels of the lit yellow target ball (Rgba 1.0, 0.9, 0.0): bright, and saturated
    towards yellow; its highlights keep some blue, so `B < 80` alone would miss most of it."""
    image = matplotlib.image.imread(io.BytesIO(png), format="png")  # floats in [0, 1]
    rgb = np.round(image[..., :3] * 255).astype(int)
    red, green, blue = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(np.count_nonzero((red > 200) & (green > 170)
                                & (np.minimum(red, green) - blue > 90)))


def screenshot(page):
    # Masked: the page's own yellows, the "No connection" banner and the realtime-rate plot.
    return page.screenshot(type="png", mask=[page.locator("#status-message"),
                                             page.locator("#stats-plot")])


@pytest.mark.timeout(120)
def test_holding_the_left_arrow_in_the_browser_moves_the_hand_left(repo, tmp_path):
    port = free_port()
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--method", "teleop", "--operator", "keyboard",
               "--duration", str(DURATION), "--port", str(port)]
    with running(command, cwd=repo) as (process, output):
        url = output.wait_for(r"^Meshcat: (http://\S+)", timeout=60)
        assert url, f"no Meshcat URL from pbp-drake:\n{output.text()}"
        with open_page(url.group(1)) as page:
            # The task starts at the page's Start; the keys work once the page has the
            # keyboard operator's buttons.
            page.wait_for_selector("text=Left (←)", state="attached")
            click(page, "Start")
            time.sleep(1.0)
            # Meshcat clicks a key's button on every keydown on `window`, and a key
            # counts as held for hold_time (0.6 s) after its last click: press it as a
            # browser's key auto-repeat would, every ~50 ms, for 2 s. (Each press waits
            # for the page, which renders in software: fewer presses get in.)
            end = time.monotonic() + 2.0
            while (now := time.monotonic()) < end:
                page.keyboard.press("ArrowLeft")
                time.sleep(max(0.0, 0.05 - (time.monotonic() - now)))
            pressed_while_running = process.poll() is None
            # Screenshots take seconds in software rendering; retry until the scene
            # (its target marker) is drawn, for a few seconds.
            deadline = time.monotonic() + 10.0
            while (yellow_pixel_count(png := screenshot(page)) < MIN_YELLOW
                   and time.monotonic() < deadline):
                time.sleep(0.5)
            if process.poll() is None:  # ends the run at once, as a person would
                click(page, "Stop")
        (tmp_path / "meshcat.png").write_bytes(png)
        result = output.wait_for(RESULT.pattern, timeout=DURATION + 30)
        assert result, f"no result line from pbp-drake:\n{output.text()}"
        process.wait(timeout=10)

    hand = np.array([float(value) for value in result.groups()])
    assert hand[1] > START_Y + 0.1, (
        f"the hand did not go left: it ended at {hand} (the keys were pressed "
        f"{'during' if pressed_while_running else 'after'} the run)\n{output.text()}")
    yellow = yellow_pixel_count(png)
    assert yellow >= MIN_YELLOW, (f"only {yellow} yellow pixels of the target marker in the "
                          f"screenshot {tmp_path / 'meshcat.png'}")
