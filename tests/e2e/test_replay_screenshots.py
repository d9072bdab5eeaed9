"""A 2-D replay as a user sees it: `pbp-drake run diagrams/toy_alpha_study.yaml --headless
--record FILE.html`, opened in headless Chromium, shows the start (magenta disc), the goal
(green) and the robot (blue) inside the page, seen from above, at the start of the
animation and later on, where the robot has moved towards the goal and the DMP's path (teal
dots) has changed. An HSR replay's DMP paths (blue dots) move with the hand likewise.

Needs Debian's `chromium` and Playwright from PyPI (the `test` extra; never
`playwright install`). Skipped where either is missing.
"""

import io
import subprocess
import sys

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest
from browser_page import NEEDS_BROWSER, open_page
from replay_tracks import animation_tracks
from scipy import ndimage

pytestmark = NEEDS_BROWSER

WIDTH, HEIGHT = 1280, 720
DURATION = 1.0
LATER = 0.6  # seconds into the replay: the robot is half way, the path bent by the push
# Hues (0..1) of the markers as rendered (point_scene_visualizer's colours, lit: the goal's
# green, 130 degrees, shows at 110 to 135), at least 45 degrees apart.
HUES = {"start": 300 / 360, "goal": 120 / 360, "robot": 225 / 360, "path": 180 / 360}
HUE_TOLERANCE = 20 / 360
BORDER = 8  # pixels: a marker touching the page's edge would be clipped
MIN_MARKER_PIXELS = 300  # the goal, the smallest marker, covers ~500 at this size


def colour_mask(png, hue):
    """Saturated, lit pixels of `hue` (within HUE_TOLERANCE) in the screenshot `png`."""
    image = matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3]
    hsv = matplotlib.colors.rgb_to_hsv(image)
    distance = np.abs((hsv[..., 0] - hue + 0.5) % 1.0 - 0.5)
    return (distance < HUE_TOLERANCE) & (hsv[..., 1] > 0.4) & (hsv[..., 2] > 0.3)


def marker(png, name):
    """The largest blob of the marker's colour: `(centre (x, y), pixel count, box)`. An
    opening first removes 1-pixel lines (the executed path is drawn in the robot's blue)."""
    mask = ndimage.binary_opening(colour_mask(png, HUES[name]), np.ones((3, 3)))
    labels, count = ndimage.label(mask)
    assert count, f"no {name} marker in the screenshot"
    sizes = ndimage.sum(mask, labels, range(1, count + 1))
    largest = int(np.argmax(sizes)) + 1
    rows, columns = np.nonzero(labels == largest)
    box = (columns.min(), rows.min(), columns.max(), rows.max())
    return np.array([columns.mean(), rows.mean()]), int(sizes[largest - 1]), box


def assert_inside(png, name):
    centre, pixels, (left, top, right, bottom) = marker(png, name)
    assert pixels >= MIN_MARKER_PIXELS, f"the {name} marker shows {pixels} pixels only"
    assert (left >= BORDER and top >= BORDER and right < WIDTH - BORDER
            and bottom < HEIGHT - BORDER), (
        f"the {name} marker {(left, top, right, bottom)} touches the edge of the page")
    return centre


def seek(page, time):
    """Shows the replay at `time` s: Meshcat's page plays its animation through
    `viewer.animator` (the controls' play/pause/time), so pause it there and seek."""
    page.evaluate(f"() => {{ viewer.animator.pause(); viewer.animator.seek({time}); "
                  "viewer.render(); }")
    page.wait_for_timeout(300)
    return page.screenshot(type="png")


def record(repo, scenario, replay, duration, *options, exit_code=0):
    """Runs `pbp-drake run SCENARIO --headless --record REPLAY`; returns the replay's text."""
    run = subprocess.run(
        [sys.executable, "-m", "pbp_drake", "run", scenario, "--headless", "--record",
         str(replay), "--duration", str(duration), *options],
        cwd=repo, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=120)
    assert run.returncode == exit_code, run.stdout + run.stderr
    return replay.read_text()


def screenshots(replay, times):
    """Screenshots of the replay file at each of `times` (seconds into its animation)."""
    with open_page(replay.as_uri(), (WIDTH, HEIGHT), timeout_ms=30_000) as page:
        # The page decodes its commands asynchronously; the animation comes last.
        page.wait_for_function("() => viewer.animator.duration > 0")
        shots = [seek(page, time) for time in times]
    for time, png in zip(times, shots):
        (replay.parent / f"{replay.stem}_{time:g}s.png").write_bytes(png)
    return shots


def assert_moved(first, later, hue, what):
    masks = [colour_mask(png, hue) for png in (first, later)]
    changed = np.count_nonzero(masks[0] ^ masks[1])
    assert changed > 0.5 * np.count_nonzero(masks[0]), (
        f"{what} barely moved ({changed} pixels changed) between the two screenshots")


@pytest.mark.timeout(180)
def test_a_2d_replay_shows_start_goal_and_robot_inside_the_page_and_paths_that_move(
        repo, tmp_path):
    replay = tmp_path / "toy.html"
    html = record(repo, "diagrams/toy_alpha_study.yaml", replay, DURATION)
    # The recording itself holds the path's motion, not only its last frame.
    times, first_dot = animation_tracks(html)["/pbp/predictions/0/0", ".position"]
    assert times[-1] >= DURATION - 0.05 and np.ptp(first_dot[:, 0]) > 0.3
    first, later = screenshots(replay, [0.0, LATER])

    start, goal, robot = (assert_inside(first, name) for name in ["start", "goal", "robot"])
    assert np.linalg.norm(robot - start) < 10, "at 0 s the robot is not on the start"
    # Seen from above, +x to the right: the goal (1, 0) right of the start (0, 0), level.
    assert goal[0] - start[0] > 300 and abs(goal[1] - start[1]) < 10
    assert_inside(later, "start"), assert_inside(later, "goal")
    moved = assert_inside(later, "robot")
    assert start[0] + 100 < moved[0] < goal[0], f"at {LATER} s the robot is at {moved}"
    assert_moved(first, later, HUES["path"], "the DMP path's dots")


@pytest.mark.timeout(180)
def test_an_hsr_replay_moves_the_dmp_paths_with_the_hand(repo, tmp_path):
    # The hand moves about 0.1 m in 4 s; the paths start from it (blue dots, the estimate's
    # bold, the others faint).
    replay = tmp_path / "hsr.html"
    # (Exit code 1: the task stops at its 4 s time limit, short of the target.)
    html = record(repo, "diagrams/hsr_reach.yaml", replay, 4.0, "--operator", "virtual",
                  exit_code=1)
    _, first_dot = animation_tracks(html)["/task/predictions/selected/0", ".position"]
    assert np.linalg.norm(first_dot[-1] - first_dot[0]) > 0.05
    first, later = screenshots(replay, [0.3, 3.7])
    assert_moved(first, later, HUES["robot"], "the blue DMP paths")
