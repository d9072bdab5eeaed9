"""The robot camera as a person sees it: `pbp-drake run diagrams/hsr_reach.yaml --camera
robot` with the virtual participant (no keys to press), its page opened in headless
Chromium, shows both the hand and the yellow target marker. The hand's own black (the
model's material) is also the neck's, the motors' and the floor's shadows: the test paints
the hand magenta in the page and counts the magenta pixels, which only the hand can make.

Slowed to a twentieth of real time, so that the scene is still near its start while the
page renders in software. (tests/console/test_camera.py checks the view through a whole
task, and that the old one hid the hand, with a pinhole model instead of a browser.)

Needs Debian's `chromium` and Playwright from PyPI (the `test` extra; never
`playwright install`). Skipped where either is missing.
"""

import io
import sys
import time

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest
from browser_page import NEEDS_BROWSER, free_port, open_page, running
from test_browser_end_to_end import yellow_pixel_count

pytestmark = NEEDS_BROWSER

REALTIME_RATE = 0.05
MIN_YELLOW = 30  # as the keyboard test's: the target ball shows ~170 such pixels here
# The fingers show ~90 to 150 pixels at 1280 x 720 (from above, the wrist hides the palm).
MIN_HAND = 40
# The hand's geometry in the page (MeshcatVisualizer's path of the link hand_palm_link),
# and the colour it is painted: a hue nothing else in the scene has. Magenta (300 degrees)
# and up to red: the operator's translucent orange ring, shown around the hand while the
# operator acts, tints it towards 357 degrees.
HAND_PATH = ["drake", "visualizer", "hsrb", "hand_palm_link"]
HAND_PAINT = [1.0, 0.0, 1.0, 1.0]
HAND_HUES = (285 / 360, 1.0)


def screenshot(page):
    """The page, its own yellows (the "No connection" banner, the realtime-rate plot) under
    grey boxes: Playwright's default magenta would pass for the hand."""
    return page.screenshot(type="png", mask_color="#808080",
                           mask=[page.locator("#status-message"), page.locator("#stats-plot")])


def hand_pixel_count(png):
    """Saturated, lit pixels of the hand's paint (HAND_HUES)."""
    image = matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3]
    hue, saturation, value = np.moveaxis(matplotlib.colors.rgb_to_hsv(image), -1, 0)
    return int(np.count_nonzero((hue >= HAND_HUES[0]) & (hue <= HAND_HUES[1])
                                & (saturation > 0.5) & (value > 0.3)))


@pytest.mark.timeout(150)
def test_the_robot_camera_shows_the_hand_and_the_target_in_the_browser(repo, tmp_path):
    command = [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml",
               "--operator", "virtual", "--camera", "robot", "--port", str(free_port()),
               "--realtime-rate", str(REALTIME_RATE)]
    with running(command, cwd=repo) as (process, output):
        url = output.wait_for(r"^Meshcat: (https?://\S+)", timeout=60)
        assert url, f"no Meshcat URL from pbp-drake:\n{output.text()}"
        with open_page(url.group(1)) as page:
            # The robot's geometry arrives after the page loads: paint the hand once it has.
            page.wait_for_function(f"() => viewer.scene_tree.find({HAND_PATH})"
                                   ".object.children.length > 0")
            page.evaluate(f"() => viewer.set_property({HAND_PATH}, 'color', {HAND_PAINT})")
            # Screenshots take seconds in software rendering; retry until the scene (its
            # target marker) is drawn and the robot camera has been set, for a few seconds.
            deadline = time.monotonic() + 20.0
            while ((yellow_pixel_count(png := screenshot(page)) < MIN_YELLOW
                    or hand_pixel_count(png) < MIN_HAND) and time.monotonic() < deadline):
                time.sleep(0.5)
        still_running = process.poll() is None
    (tmp_path / "robot_camera.png").write_bytes(png)

    assert still_running, f"the run ended before the screenshot:\n{output.text()}"
    yellow = yellow_pixel_count(png)
    assert yellow >= MIN_YELLOW, (f"only {yellow} yellow pixels of the target marker in "
                                  f"{tmp_path / 'robot_camera.png'}")
    hand = hand_pixel_count(png)
    assert hand >= MIN_HAND, (f"only {hand} pixels of the hand (painted magenta) in "
                              f"{tmp_path / 'robot_camera.png'}: the head hides it?")
