"""The grasping task's scene and rules (`pbp_drake.core.grasp_task`)."""

import numpy as np
import pytest

from pbp_drake.core.grasp_task import (
    approach_direction, grasp_errors, grasp_pose, grasp_progress, grasp_success,
    sample_grasp_scene, side_grasp_orientation, top_grasp_orientation)
from pbp_drake.core.quaternion import exp_map, multiply

SEEDS = range(40)
SUCCESS_DISTANCE, SUCCESS_ANGLE = 0.03, np.radians(10.0)


def rotation_matrix(q):
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def test_the_same_seed_draws_the_same_scene_and_another_seed_another():
    first, again, other = sample_grasp_scene(3), sample_grasp_scene(3), sample_grasp_scene(4)
    for name in ("objects", "tables", "approach_angles", "grasp_positions",
                 "grasp_orientations"):
        np.testing.assert_array_equal(getattr(first, name), getattr(again, name))
    assert first.approaches == again.approaches and first.targets == again.targets
    assert not np.array_equal(first.objects[:2], other.objects[:2])


@pytest.mark.parametrize("seed", SEEDS)
def test_a_scene_keeps_its_ranges_separations_and_switches(seed):
    scene = sample_grasp_scene(seed)
    count = len(scene.objects)
    assert 2 <= count <= 4
    assert np.all((1.25 <= scene.tables[:, 0]) & (scene.tables[:, 0] <= 2.5))
    assert np.all((-1.05 <= scene.tables[:, 1]) & (scene.tables[:, 1] <= 1.05))
    np.testing.assert_allclose(scene.tables[:, 2], 0.6)
    np.testing.assert_allclose(scene.objects, scene.tables + [0.0, 0.0, 0.075])
    gaps = np.linalg.norm(scene.tables[:, None, :2] - scene.tables[None, :, :2], axis=-1)
    assert gaps[~np.eye(count, dtype=bool)].min() >= 0.45
    for approach, angle in zip(scene.approaches, scene.approach_angles):
        limit = np.pi / 2 if approach == "top" else np.pi / 3
        assert approach in ("side", "top") and -limit <= angle <= limit
    np.testing.assert_allclose(np.linalg.norm(scene.grasp_orientations, axis=1), 1.0,
                               atol=1e-12)
    assert len(scene.targets) == 3 and all(0 <= t < count for t in scene.targets)
    assert all(a != b for a, b in zip(scene.targets, scene.targets[1:]))


def test_many_grasps_an_object_keep_the_one_grasp_scene_and_add_its_objects_grasps():
    one, many = sample_grasp_scene(5, object_count=(10, 10)), sample_grasp_scene(
        5, object_count=(10, 10), grasps_per_object=30)
    assert len(many.grasp_positions) == len(many.approaches) == 300
    # Grasp i is of object i // 30, whose centre and table repeat; its first grasp is the
    # one-grasp scene's.
    np.testing.assert_array_equal(many.objects, np.repeat(one.objects, 30, axis=0))
    np.testing.assert_array_equal(many.tables, np.repeat(one.tables, 30, axis=0))
    np.testing.assert_array_equal(many.grasp_positions[::30], one.grasp_positions)
    assert [target // 30 for target in many.targets] == list(one.targets)
    for index, (approach, angle) in enumerate(zip(many.approaches, many.approach_angles)):
        position, orientation = grasp_pose(many.objects[index], approach, angle, 0.15, 0.08)
        np.testing.assert_allclose(many.grasp_positions[index], position)
        np.testing.assert_allclose(many.grasp_orientations[index], orientation)
    # An object's grasps differ (its top grasps in the roll alone): 300 distinct poses.
    poses = np.hstack([many.grasp_positions, many.grasp_orientations]).round(9)
    assert len(np.unique(poses, axis=0)) == 300


def test_each_grasp_pose_is_the_drawn_one():
    scene = sample_grasp_scene(11, top_probability=0.5)
    for index, (approach, angle) in enumerate(zip(scene.approaches, scene.approach_angles)):
        position, orientation = grasp_pose(scene.objects[index], approach, angle, 0.15, 0.08)
        np.testing.assert_allclose(scene.grasp_positions[index], position)
        np.testing.assert_allclose(scene.grasp_orientations[index], orientation)


def test_both_approaches_and_only_one_when_asked():
    approaches = {a for seed in SEEDS for a in sample_grasp_scene(seed).approaches}
    assert approaches == {"side", "top"}
    assert {a for seed in range(10) for a in
            sample_grasp_scene(seed, top_probability=0.0).approaches} == {"side"}
    assert {a for seed in range(10) for a in
            sample_grasp_scene(seed, top_probability=1.0).approaches} == {"top"}


@pytest.mark.parametrize("yaw", [-np.pi / 3, -0.4, 0.0, 0.7, np.pi / 3])
def test_a_side_grasp_approaches_level_at_its_yaw_with_the_fingers_level(yaw):
    frame = rotation_matrix(side_grasp_orientation(yaw))
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(frame[:, 2], [np.cos(yaw), np.sin(yaw), 0.0], atol=1e-12)
    # As the HSR's hand at the start (x_H up): a grasp ahead needs no wrist roll.
    np.testing.assert_allclose(frame[:, 0], [0.0, 0.0, 1.0], atol=1e-12)
    assert abs(frame[2, 1]) < 1e-12  # the fingers close in a level line
    np.testing.assert_allclose(approach_direction(side_grasp_orientation(yaw)), frame[:, 2],
                               atol=1e-12)


@pytest.mark.parametrize("roll", [-np.pi / 2, -0.3, 0.0, 1.0, np.pi / 2])
def test_a_top_grasp_approaches_down_turned_by_its_roll(roll):
    frame = rotation_matrix(top_grasp_orientation(roll))
    np.testing.assert_allclose(frame[:, 2], [0.0, 0.0, -1.0], atol=1e-12)
    # Roll 0: the start hand pitched down, the fingers closing along -y (y_H of the start
    # hand); right-handed about the approach axis (down), i.e. clockwise seen from above.
    np.testing.assert_allclose(frame[:, 1], [-np.sin(roll), -np.cos(roll), 0.0], atol=1e-12)


def test_the_grasp_position_stands_back_from_the_grasp_point_along_the_approach():
    center = np.array([2.0, 0.5, 0.675])
    side, _ = grasp_pose(center, "side", 0.0, 0.15, 0.08)
    np.testing.assert_allclose(side, center - [0.08, 0.0, 0.0], atol=1e-12)
    top, _ = grasp_pose(center, "top", 0.3, 0.15, 0.08)
    np.testing.assert_allclose(top, center + [0.0, 0.0, 0.075 + 0.08], atol=1e-12)
    with pytest.raises(ValueError, match="approach 'under' is unknown"):
        grasp_pose(center, "under", 0.0, 0.15, 0.08)


def turned(orientation, angle, axis=(0.3, -0.5, 0.8)):
    axis = np.asarray(axis) / np.linalg.norm(axis)
    return multiply(exp_map(angle * axis), orientation)


@pytest.mark.parametrize("distance, angle, expected", [
    (0.0, 0.0, True), (0.0299, np.radians(9.9), True), (0.0301, 0.0, False),
    (0.0, np.radians(10.1), False), (0.0301, np.radians(10.1), False),
    (0.0299, np.radians(10.1), False), (0.0301, np.radians(9.9), False)])
def test_success_needs_both_3_cm_and_10_degrees(distance, angle, expected):
    goal_position, goal_orientation = np.array([2.0, 0.0, 0.7]), side_grasp_orientation(0.4)
    position = goal_position + distance * np.array([0.0, 0.6, 0.8])
    orientation = turned(goal_orientation, angle)
    assert grasp_success(position, orientation, goal_position, goal_orientation,
                         SUCCESS_DISTANCE, SUCCESS_ANGLE) is expected
    # q and -q are one orientation: the check does not depend on the sign.
    assert grasp_success(position, -orientation, goal_position, goal_orientation,
                         SUCCESS_DISTANCE, SUCCESS_ANGLE) is expected
    assert grasp_success(position, orientation, goal_position, -goal_orientation,
                         SUCCESS_DISTANCE, SUCCESS_ANGLE) is expected


def test_errors_are_vectorised_and_antipodal_safe():
    goals = np.array([side_grasp_orientation(0.2), -top_grasp_orientation(0.5)])
    distances, angles = grasp_errors([1.0, 0.0, 0.7], -goals[1],
                                     [[1.0, 0.0, 0.7], [1.0, 0.3, 0.3]], goals)
    np.testing.assert_allclose(distances, [0.0, 0.5])
    assert angles[1] == pytest.approx(0.0, abs=1e-7)
    assert 0.0 < angles[0] <= np.pi


def test_success_refuses_a_vector_that_is_no_quaternion():
    with pytest.raises(ValueError, match="orientation is not a unit quaternion"):
        grasp_success([0, 0, 0], [1.0, 1.0, 0.0, 0.0], [0, 0, 0], [1, 0, 0, 0], 0.03, 0.1)


def test_progress_mixes_distance_and_angle():
    start_p, start_q = np.array([0.5, 0.0, 0.7]), side_grasp_orientation(0.0)
    goal_p, goal_q = np.array([1.5, 0.0, 0.7]), side_grasp_orientation(0.5)
    length = SUCCESS_DISTANCE / SUCCESS_ANGLE
    assert grasp_progress(start_p, start_q, start_p, start_q, goal_p, goal_q, length) == 0.0
    assert grasp_progress(goal_p, goal_q, start_p, start_q, goal_p, goal_q, length) == 1.0
    halfway = grasp_progress(0.5 * (start_p + goal_p), side_grasp_orientation(0.25), start_p,
                             start_q, goal_p, goal_q, length)
    assert halfway == pytest.approx(0.5)
    # Turning alone counts: half the turn is worth its share of the pose error.
    turned_only = grasp_progress(start_p, side_grasp_orientation(0.25), start_p, start_q,
                                 goal_p, goal_q, length)
    assert turned_only == pytest.approx(0.5 * 0.5 * length / (1.0 + 0.5 * length))
    # Moving away clips at 0.
    assert grasp_progress(start_p - [1.0, 0, 0], start_q, start_p, start_q, goal_p, goal_q,
                          length) == 0.0
    # Started on the grasp pose itself: done, wherever the hand goes.
    assert grasp_progress(start_p, start_q, goal_p, goal_q, goal_p, goal_q, length) == 1.0


@pytest.mark.parametrize("arguments, message", [
    (dict(object_count=(0, 3)), r"object_count must be \[min, max\]"),
    (dict(object_count=(1, 1)), "target switching needs at least 2 objects"),
    (dict(min_separation=0.3), "less than the tables' diagonal"),
    (dict(object_radius=0.2), "do not fit on tables"),
    (dict(object_count=(4, 4), x_range=(1.25, 1.3), y_range=(0.0, 0.1)),
     "cannot place 4 tables"),
    (dict(table_height=1.0, top_probability=1.0), "out of the HSR's reach"),
])
def test_bad_arguments_say_what_is_wrong(arguments, message):
    with pytest.raises(ValueError, match=message):
        sample_grasp_scene(0, **arguments)
