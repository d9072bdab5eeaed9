"""A scene's objects are checked in O(K log K): the overlapping pair found is the closest
pair, as measuring all K^2 gaps finds it, ten thousand objects are checked at once, and
objects that are no points are refused; and the reach's progress toward its object."""

import numpy as np
import pytest

from pbp_drake.core.reach_task import closest_pair_within, reach_progress, validate_objects


@pytest.mark.slow
@pytest.mark.parametrize("count, distance", [(2, 0.9), (5, 0.4), (60, 0.05), (400, 0.01)])
def test_the_closest_pair_is_the_one_all_gaps_give(count, distance):
    rng = np.random.default_rng(count)
    for _ in range(20):
        points = rng.uniform(0.0, 1.0, (count, 3))
        gaps = np.linalg.norm(points[:, None] - points[None], axis=-1)
        gaps[np.diag_indices(count)] = np.inf
        found = closest_pair_within(points, distance)
        if gaps.min() >= distance:
            assert found is None
            continue
        first, second = np.unravel_index(np.argmin(gaps), gaps.shape)
        assert found == (min(first, second), max(first, second), gaps.min())


def test_ten_thousand_objects_are_checked_and_an_overlap_among_them_named():
    rng = np.random.default_rng(0)
    grid = np.stack(np.meshgrid(np.linspace(1.3, 2.4, 100), np.linspace(-1, 1, 100)), -1)
    objects = np.column_stack([grid.reshape(-1, 2) + rng.uniform(-1e-3, 1e-3, (10000, 2)),
                               np.full(10000, 0.7)])
    validate_objects(objects, 0.005)
    objects[7345, :2] = objects[12, :2] + [0.001, 0.0]
    with pytest.raises(ValueError, match="objects 12 and 7345 overlap: 0.001 m apart"):
        validate_objects(objects, 0.005)


@pytest.mark.parametrize("objects, message", [
    (np.zeros((0, 3)), r"objects must be \(M, 3\) with M >= 1, got shape \(0, 3\)"),
    (np.zeros((2, 2)), r"objects must be \(M, 3\) with M >= 1, got shape \(2, 2\)"),
    ([[1.5, 0.0, 0.7], [2.0, np.nan, 0.7]], "objects contain NaN or infinite values"),
])
def test_objects_that_are_no_points_are_refused(objects, message):
    with pytest.raises(ValueError, match=message):
        validate_objects(objects, 0.005)


def test_reach_progress_is_the_distance_covered_and_1_from_the_target_itself():
    start, target = np.array([0.0, 0.0, 0.7]), np.array([2.0, 0.0, 0.7])
    assert reach_progress([1.5, 0.0, 0.7], start, target) == pytest.approx(0.75)
    assert reach_progress([-1.0, 0.0, 0.7], start, target) == 0.0
    assert reach_progress([-1.0, 0.0, 0.7], target, target) == 1.0
