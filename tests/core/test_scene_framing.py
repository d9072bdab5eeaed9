"""The framing of a 2-D scene: what a user sees on the page holds the whole scene, with a
margin, on pages from 4:3 to wider than 16:9, centred on a 16:9 page."""

import numpy as np
import pytest

from pbp_drake.core.scene_framing import page_view, resample_by_arc_length, scene_bounds

START, GOALS = np.array([0.0, 0.0]), np.array([[1.0, 0.0], [1.0, 0.5]])
OBSTACLE = ([0.5, -0.1], 0.2)  # reaches y = -0.3, below every point


def visible(view, aspect):
    """What a page of `aspect` shows of `view`: Meshcat keeps xmin, ymin and ymax and sets
    xmax = xmin + aspect * (ymax - ymin)."""
    xmin, _, ymin, ymax = view
    return xmin, xmin + aspect * (ymax - ymin), ymin, ymax


def test_the_bounds_hold_every_point_and_circle_with_a_margin():
    low, high = scene_bounds(np.vstack([START, GOALS]), [OBSTACLE])
    assert np.all(low <= [0.0 - 0.1, -0.3 - 0.1]) and np.all(high >= [1.0 + 0.1, 0.5 + 0.1])
    # The margin is a tenth of the larger side, and at least 0.1.
    low, high = scene_bounds([[0.0, 0.0], [10.0, 1.0]])
    np.testing.assert_allclose([low, high], [[-1.0, -1.0], [11.0, 2.0]])


@pytest.mark.parametrize("aspect", [4 / 3, 3 / 2, 16 / 10, 16 / 9, 21 / 9])
@pytest.mark.parametrize("points", [
    [[0.0, 0.0], [1.0, 0.0]],        # wide: the toy reach
    [[0.0, 0.0], [0.1, 2.0]],        # tall
    [[-3.0, 5.0], [-2.0, 5.5]],      # far from the origin
])
def test_a_page_shows_the_whole_scene(points, aspect):
    low, high = scene_bounds(points)
    xmin, xmax, ymin, ymax = visible(page_view(low, high), aspect)
    assert xmin <= low[0] and high[0] <= xmax + 1e-12
    assert ymin <= low[1] and high[1] <= ymax


def test_the_scene_is_centred_on_a_16_by_9_page_and_fills_it_when_wide():
    low, high = scene_bounds([[0.0, 0.0], [1.0, 0.0]])
    xmin, xmax, ymin, ymax = visible(page_view(low, high), 16 / 9)
    np.testing.assert_allclose([(xmin + xmax) / 2, (ymin + ymax) / 2], (low + high) / 2)
    # Half of the page's width at least (it must still fit a 4:3 page).
    assert (high[0] - low[0]) / (xmax - xmin) >= 0.5 - 1e-12


def test_a_path_resampled_by_arc_length_keeps_its_ends_and_spaces_points_evenly():
    # Slow at the ends, fast in the middle, as a DMP's path.
    path = np.column_stack([np.linspace(0.0, 1.0, 101) ** 3, np.zeros(101)])
    points = resample_by_arc_length(path, 11)
    np.testing.assert_allclose(points[[0, -1]], path[[0, -1]])
    np.testing.assert_allclose(np.diff(points[:, 0]), 0.1)
    np.testing.assert_allclose(resample_by_arc_length([[2.0, 3.0]] * 5, 4), [[2.0, 3.0]] * 4)
