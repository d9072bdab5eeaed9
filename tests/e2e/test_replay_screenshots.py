"""A 2-D replay as a user sees it: `pbp-drake run diagrams/toy_alpha_study.yaml --headless
--record FILE.html`, opened in headless Chromium, shows the start (magenta disc), the goal
(green) and the robot (blue) inside the page, seen from above, at the start of the
animation and later on, where the robot has moved towards the goal and the DMP's path (teal
dots) has changed. It opens paused at 0 s, with a key of its colours and no executed path
yet; played, it draws the executed path (the robot's blue trail) behind the robot, from the
start to the goal. An HSR replay's DMP paths (blue dots) move with the hand likewise; it too
opens paused, without the 2-D key.

Needs Debian's `chromium` and Playwright from PyPI (the `test` extra; never
`playwright install`). Skipped where either is missing.
"""

import contextlib
import io
import re
import subprocess
import sys

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest
from browser_page import NEEDS_BROWSER, open_page
from replay_tracks import animation_tracks, commands
from scipy import ndimage

from pbp_drake.output_paths import LEGEND_ID, REPLAY_HINT_ID
from pbp_drake.systems.visualizers.point_scene_visualizer import LEGEND

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
# The executed path's dots (0.003 m) make a line ~3 pixels wide: ~2000 pixels, whole.
MIN_TRAIL_PIXELS = 400


def colour_mask(png, hue):
    """Saturated, lit pixels of `hue` (within HUE_TOLERANCE) in the screenshot `png`."""
    image = matplotlib.image.imread(io.BytesIO(png), format="png")[..., :3]
    hsv = matplotlib.colors.rgb_to_hsv(image)
    distance = np.abs((hsv[..., 0] - hue + 0.5) % 1.0 - 0.5)
    return (distance < HUE_TOLERANCE) & (hsv[..., 1] > 0.4) & (hsv[..., 2] > 0.3)


def marker(png, name):
    """The largest blob of the marker's colour: `(centre (x, y), pixel count, box)`. An
    opening first removes lines up to 4 pixels wide (the executed path, a trail of small
    dots in the robot's blue)."""
    mask = ndimage.binary_opening(colour_mask(png, HUES[name]), np.ones((5, 5)))
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


def trail_pixels(png):
    """The robot's blue outside the robot's own disc (`marker`'s blob, which leaves out the
    thin trail touching it, widened by its rim): the executed path's pixels, as a mask."""
    mask = colour_mask(png, HUES["robot"])
    disc = ndimage.binary_opening(mask, np.ones((5, 5)))
    labels, count = ndimage.label(disc)
    if count:
        sizes = ndimage.sum(disc, labels, range(1, count + 1))
        robot = ndimage.binary_dilation(labels == int(np.argmax(sizes)) + 1, iterations=3)
        mask &= ~robot
    return mask


def screenshot(page):
    """The page, its key and play hint under grey boxes (their swatches would pass for
    markers)."""
    return page.screenshot(type="png", mask_color="#808080",
                           mask=[page.locator(f"#{LEGEND_ID}"),
                                 page.locator(f"#{REPLAY_HINT_ID}")])


def seek(page, time):
    """Shows the replay at `time` s: Meshcat's page plays its animation through
    `viewer.animator` (the controls' play/pause/time), so pause it there and seek."""
    page.evaluate(f"() => {{ viewer.animator.pause(); viewer.animator.seek({time}); "
                  "viewer.render(); }")
    page.wait_for_timeout(300)
    return screenshot(page)


def opening(page):
    """How the replay opened, ten frames after its animation loaded (one that played on
    its own would have moved): `{"playing", "time", "clips", "legend", "hint"}`, `clips`
    the largest time of its clips, `legend` its key's text (None without one) and `hint`
    whether it says how to play it."""
    state = page.evaluate("""() => new Promise(done => {
        let frames = 10;
        const next = () => --frames ? requestAnimationFrame(next) : done({
            playing: viewer.animator.playing, time: viewer.animator.time,
            clips: Math.max(...viewer.animator.actions.map(action => action.time))});
        requestAnimationFrame(next);
    })""")
    legend = page.locator(f"#{LEGEND_ID}")
    state["legend"] = legend.inner_text() if legend.is_visible() else None
    state["hint"] = page.locator(f"#{REPLAY_HINT_ID}").is_visible()
    return state


def press_play(page):
    """Clicks the replay's play button (Meshcat's controls: Animations, default, play)."""
    page.locator(".dg li.cr.function").filter(has=page.locator(
        ".property-name", has_text=re.compile("^play$"))).dispatch_event("click")


def record(repo, scenario, replay, duration, *options, exit_code=0):
    """Runs `pbp-drake run SCENARIO --headless --record REPLAY`; returns the replay's text."""
    run = subprocess.run(
        [sys.executable, "-m", "pbp_drake", "run", scenario, "--headless", "--record",
         str(replay), "--duration", str(duration), *options],
        cwd=repo, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=120)
    assert run.returncode == exit_code, run.stdout + run.stderr
    return replay.read_text()


@contextlib.contextmanager
def replay_page(replay):
    """The replay file opened in headless Chromium, once its animation has loaded."""
    with open_page(replay.as_uri(), (WIDTH, HEIGHT), timeout_ms=30_000) as page:
        # The page decodes its commands asynchronously; the animation comes last.
        page.wait_for_function("() => viewer.animator.duration > 0")
        yield page


def screenshots(replay, times):
    """How the replay opened (`opening`), and screenshots of it at each of `times`
    (seconds into its animation)."""
    with replay_page(replay) as page:
        opened = opening(page)
        shots = [seek(page, time) for time in times]
    for time, png in zip(times, shots):
        save(replay, f"{time:g}s", png)
    return opened, shots


def save(replay, name, png):
    (replay.parent / f"{replay.stem}_{name}.png").write_bytes(png)


def assert_opened_paused_at_its_start(opened):
    assert not opened["playing"] and opened["time"] == 0 and opened["clips"] == 0, (
        f"the replay did not open paused at 0 s: {opened}")
    assert opened["hint"], "the replay does not say how to play it"


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
    opened, (first, later) = screenshots(replay, [0.0, LATER])
    assert_opened_paused_at_its_start(opened)

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
    opened, (first, later) = screenshots(replay, [0.3, 3.7])
    assert_opened_paused_at_its_start(opened)
    assert opened["legend"] is None, "an HSR replay shows the 2-D scene's key"
    assert_moved(first, later, HUES["robot"], "the blue DMP paths")


@pytest.mark.timeout(180)
def test_a_2d_replay_opens_paused_with_its_key_and_draws_the_executed_path_as_it_plays(
        repo, tmp_path):
    replay = tmp_path / "toy_scene_1.html"
    html = record(repo, "diagrams/toy_alpha_study.yaml", replay, 2.0, "--scene", "scene_1",
                  "--method", "pbp_alternated")
    # No line at /pbp/executed itself (the trail's dots are under it): one would show whole
    # from 0 s.
    assert not any(command["type"] == "set_object" and command["path"] == "/pbp/executed"
                   for command in commands(html))
    with replay_page(replay) as page:
        opened = opening(page)
        # As it opened, without a seek: the robot on the start, no executed path yet.
        at_start = screenshot(page)
        press_play(page)
        page.wait_for_function("() => !viewer.animator.playing && "
                               "viewer.animator.time > viewer.animator.duration - 0.05",
                               timeout=60_000)
        page.wait_for_timeout(300)  # the last frame drawn
        played = screenshot(page)
        half_way = seek(page, LATER)
    for name, png in [("start", at_start), ("played", played), (f"{LATER:g}s", half_way)]:
        save(replay, name, png)

    assert_opened_paused_at_its_start(opened)
    key = opened["legend"]
    assert key is not None, "the replay has no key"
    assert [name for name, _ in LEGEND if name not in key] == [], f"the key reads {key!r}"
    start, goal = assert_inside(at_start, "start"), assert_inside(at_start, "goal")
    robot = assert_inside(at_start, "robot")
    assert np.linalg.norm(robot - start) < 10, "as it opens, the robot is not on the start"
    # Played to the end: the path runs from the start to the goal, where the robot is.
    columns = np.nonzero(trail_pixels(played))[1]
    assert len(columns) >= MIN_TRAIL_PIXELS, f"only {len(columns)} pixels of executed path"
    assert columns.min() < start[0] + 40 and columns.max() > goal[0] - 40, (
        f"the executed path spans columns {columns.min()} to {columns.max()}, not the "
        f"start's {start[0]:.0f} to the goal's {goal[0]:.0f}")
    trail = np.count_nonzero(trail_pixels(at_start))
    assert trail < 20, f"{trail} pixels of executed path before the robot has moved"
    # Half way: drawn behind the robot only, not yet where it goes next.
    robot = assert_inside(half_way, "robot")
    columns = np.nonzero(trail_pixels(half_way))[1]
    assert len(columns) > 100 and columns.max() < robot[0] + 25, (
        f"at {LATER} s the executed path reaches column {columns.max()}, the robot is at "
        f"{robot[0]:.0f}")
