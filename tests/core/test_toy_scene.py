"""The paper's virtual human of the 2-D toy scenes (`repulsion_command`, Eq. 5): pushed away
from the nearest obstacle within its threshold, radially unless given an axis."""

import numpy as np
import pytest

from pbp_drake.core.toy_scene import bent_path, collision_ratio, repulsion_command

CENTRES, RADII = [[0.0, 0.0], [1.0, 0.0]], [0.1, 0.1]


def test_without_an_axis_it_pushes_straight_away_from_the_nearest_obstacle():
    command, active = repulsion_command([0.75, 0.15], CENTRES, RADII, speed=2.0)
    assert active
    np.testing.assert_allclose(command, 2.0 * np.array([-0.25, 0.15]) / np.hypot(0.25, 0.15))


def test_on_an_obstacles_centre_it_pushes_along_the_last_axis():
    command, active = repulsion_command([1.0, 0.0], CENTRES, RADII)
    assert active
    np.testing.assert_array_equal(command, [0.0, 1.0])


@pytest.mark.parametrize("centres, radii", [(CENTRES, RADII), (np.zeros((0, 2)), [])])
def test_beyond_the_threshold_or_with_no_obstacle_it_rests(centres, radii):
    command, active = repulsion_command([0.5, 0.6], centres, radii, distance_threshold=0.2)
    assert not active
    np.testing.assert_array_equal(command, [0.0, 0.0])


@pytest.mark.parametrize("centres, radii", [([[1.0, 1.0]], [0.1, 0.2]),
                                            ([[1.0, 1.0], [0.0, 0.0]], [0.1])])
def test_a_radius_count_other_than_the_obstacles_is_refused(centres, radii):
    # NumPy broadcast [[1, 1]] with two radii into two obstacles: a ratio of another scene.
    with pytest.raises(ValueError, match=rf"^radii has {len(radii)} values for {len(centres)} "
                                         r"centres; expected one radius an obstacle$"):
        collision_ratio(np.zeros((5, 2)), centres, radii)
    assert collision_ratio(np.zeros((4, 2)), [[0.0, 0.0], [5.0, 5.0]], [0.1, 0.2]) == 1.0


@pytest.mark.parametrize("start, goal, duration, message", [
    ([0.0, 0.0], [1.0, 0.0], 0.0, r"duration must be positive and finite, got 0.0"),
    ([0.0, 0.0], [1.0, 0.0], float("nan"), r"duration must be positive and finite, got nan"),
    ([0.5, 0.5], [0.5, 0.5], 1.0, r"goal \[0.5, 0.5\] is where start is"),
    ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 1.0,
     r"start must be two finite numbers \(x, y\), got \[0.0, 0.0, 0.0\]"),
    ([0.0, 0.0], [1.0, np.nan], 1.0, r"goal must be two finite numbers \(x, y\), got \[1.0, nan\]"),
])
def test_a_bent_path_that_has_no_shape_is_refused_by_name(start, goal, duration, message):
    # Each gave NaN positions without a word, or NumPy's broadcast error.
    with pytest.raises(ValueError, match=f"^{message}"):
        bent_path(start, goal, 0.2, duration)
