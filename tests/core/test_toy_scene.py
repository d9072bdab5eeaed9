"""The paper's virtual human of the 2-D toy scenes (`repulsion_command`, Eq. 5): pushed away
from the nearest obstacle within its threshold, radially unless given an axis."""

import numpy as np
import pytest

from pbp_drake.core.toy_scene import repulsion_command

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
