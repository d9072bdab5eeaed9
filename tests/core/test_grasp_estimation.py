"""The ``pose`` goal estimator (`pbp_drake.core.grasp_estimation`)."""

import numpy as np
import pytest

from pbp_drake.core.goal_estimation import GoalEstimatorSettings, goal_probabilities
from pbp_drake.core.grasp_estimation import (
    estimate_pose, pose_costs, pose_probabilities, turn_errors)
from pbp_drake.core.grasp_task import side_grasp_orientation, top_grasp_orientation
from pbp_drake.core.quaternion import angle_between, exp_map, multiply

SETTINGS = GoalEstimatorSettings(method="pose")
HAND = np.array([0.5, 0.0, 0.7])
LEVEL = side_grasp_orientation(0.0)
STILL = np.zeros(3)


def run(settings, positions, orientations, hand_states):
    """Selections of successive updates at `hand_states` (p, q, v, omega)."""
    memory, selections = None, []
    for position, orientation, velocity, angular_velocity in hand_states:
        selected, probabilities, memory = estimate_pose(
            settings, positions, orientations, position, orientation, velocity,
            angular_velocity, memory)
        assert probabilities.sum() == pytest.approx(1.0)
        selections.append(selected)
    return selections


def test_it_picks_the_grasp_the_hand_moves_toward():
    positions = np.array([[1.5, 0.8, 0.7], [1.5, -0.8, 0.7]])
    orientations = np.array([LEVEL, LEVEL])
    for target in (0, 1):
        velocity = 0.1 * (positions[target] - HAND) / np.linalg.norm(positions[target] - HAND)
        assert run(SETTINGS, positions, orientations, [(HAND, LEVEL, velocity, STILL)]) == [
            target]


def test_two_grasps_at_one_place_are_told_apart_by_the_turn_alone():
    place = np.array([1.5, 0.0, 0.83])
    positions = np.array([place, place])
    orientations = np.array([top_grasp_orientation(-1.2), top_grasp_orientation(1.2)])
    hand = place + [0.0, 0.0, 0.1]
    start = top_grasp_orientation(0.0)  # halfway between the two rolls
    velocity = np.array([0.0, 0.0, -0.05])  # toward both alike
    for target in (0, 1):
        # Turning at 0.5 rad/s about the vertical, the way that brings the target's roll.
        omega = next(candidate for candidate in ([0.0, 0.0, 0.5], [0.0, 0.0, -0.5])
                     if turn_errors(orientations[target][np.newaxis], start,
                                    np.array(candidate))[1][0] > 0)
        probabilities = pose_probabilities(SETTINGS, positions, orientations, hand, start,
                                           velocity, omega)
        assert int(np.argmax(probabilities)) == target
        assert probabilities[target] > 0.9
    # Not turning, the two are alike.
    probabilities = pose_probabilities(SETTINGS, positions, orientations, hand, start,
                                       velocity, STILL)
    np.testing.assert_allclose(probabilities, [0.5, 0.5])


def test_having_turned_to_a_grasp_orientation_names_it_without_turning():
    place = np.array([1.5, 0.0, 0.7])
    orientations = np.array([side_grasp_orientation(-0.8), side_grasp_orientation(0.8)])
    hand = place - [0.2, 0.0, 0.0]
    selections = run(SETTINGS, np.array([place, place]), orientations,
                     [(hand, orientations[1], STILL, STILL)] * 3)
    assert selections == [1, 1, 1]


def test_the_closing_rate_is_the_angles_rate():
    goal = multiply(exp_map([0.3, -0.7, 0.4]), LEVEL)
    omega = np.array([0.2, 0.5, -0.3])
    step = 1e-6
    angle, closing = turn_errors(goal[np.newaxis], LEVEL, omega)
    later = multiply(exp_map(omega * step), LEVEL)
    assert (angle[0] - angle_between(later, goal)) / step == pytest.approx(closing[0],
                                                                           rel=1e-4)


def test_costs_are_the_documented_formula():
    positions = np.array([[1.5, 0.5, 0.7], [1.0, -0.5, 0.9]])
    orientations = np.array([side_grasp_orientation(0.3), top_grasp_orientation(0.2)])
    velocity, omega = np.array([0.1, 0.05, 0.0]), np.array([0.0, 0.1, 0.2])
    settings = GoalEstimatorSettings(method="pose", distance_weight=0.7,
                                     orientation_weight=1.3, turn_horizon=0.5)
    costs = pose_costs(settings, positions, orientations, HAND, LEVEL, velocity, omega)
    for index in range(2):
        offset = positions[index] - HAND
        alpha = np.arccos(offset @ velocity / (np.linalg.norm(offset)
                                               * np.linalg.norm(velocity)))
        angle, closing = turn_errors(orientations[index][np.newaxis], LEVEL, omega)
        expected = (alpha + 0.7 * np.linalg.norm(offset)
                    + 1.3 * max(0.0, angle[0] - 0.5 * closing[0]))
        assert costs[index] == pytest.approx(expected)
    # Slower than min_speed, the direction of travel says nothing.
    slow = pose_costs(settings, positions, orientations, HAND, LEVEL, 0.001 * velocity, omega)
    np.testing.assert_allclose(
        slow, costs - [np.arccos((positions[i] - HAND) @ velocity / np.linalg.norm(
            positions[i] - HAND) / np.linalg.norm(velocity)) for i in range(2)])


def test_the_sign_of_a_quaternion_changes_nothing():
    positions = np.array([[1.5, 0.5, 0.7], [1.5, -0.5, 0.7], [2.0, 0.0, 0.83]])
    orientations = np.array([side_grasp_orientation(0.3), side_grasp_orientation(-0.6),
                             top_grasp_orientation(0.9)])
    arguments = (HAND, LEVEL, np.array([0.1, 0.0, 0.0]), np.array([0.0, 0.0, 0.3]))
    first = pose_probabilities(SETTINGS, positions, orientations, *arguments)
    flipped = pose_probabilities(SETTINGS, positions, -orientations, HAND, -LEVEL,
                                 *arguments[2:])
    np.testing.assert_allclose(first, flipped, atol=1e-12)


def test_a_cold_estimator_is_one_hot_not_nan():
    cold = GoalEstimatorSettings(method="pose", temperature=1e-6)
    probabilities = pose_probabilities(
        cold, [[1.5, 0.5, 0.7], [1.5, -0.5, 0.7]], [LEVEL, LEVEL], HAND, LEVEL,
        [0.0, 0.1, 0.0], STILL)
    np.testing.assert_array_equal(probabilities, [1.0, 0.0])


def test_the_hysteresis_is_the_shipped_one():
    positions = np.array([[1.5, 0.8, 0.7], [1.5, -0.8, 0.7]])
    orientations = np.array([LEVEL, LEVEL])
    left, right = [np.array([0.1, 0.1, 0.0]), np.array([0.1, -0.1, 0.0])]
    states = [(HAND, LEVEL, left, STILL)] + [(HAND, LEVEL, right, STILL)] * 2
    assert run(SETTINGS, positions, orientations, states) == [0, 0, 1]


@pytest.mark.parametrize("arguments, message", [
    (dict(grasp_orientations=[[1.0, 0, 0, 0]]), r"grasp orientations must be \(K, 4\)"),
    (dict(grasp_orientations=[[1.0, 1.0, 0, 0]] * 2), "grasp orientations is not a unit"),
    (dict(orientation=[0.5, 0, 0, 0]), "orientation is not a unit quaternion"),
    (dict(orientation=[[1.0, 0, 0, 0]] * 2), r"orientation must be one quaternion"),
    (dict(velocity=[0.0, np.nan, 0.0]), "velocity is NaN"),
    (dict(angular_velocity=[0.0, 0.0]), "angular_velocity must have 3 entries"),
    (dict(grasp_positions=[[1.0, 0.0]]), r"goals must be \(K, 3\)"),
])
def test_bad_input_says_what_is_wrong(arguments, message):
    values = dict(grasp_positions=[[1.5, 0.5, 0.7], [1.5, -0.5, 0.7]],
                  grasp_orientations=[LEVEL, LEVEL], position=HAND, orientation=LEVEL,
                  velocity=STILL, angular_velocity=STILL)
    values.update(arguments)
    with pytest.raises(ValueError, match=message):
        pose_probabilities(SETTINGS, **values)


def test_the_settings_know_the_pose_method_and_its_weights():
    with pytest.raises(ValueError, match="turn_horizon must be a finite number >= 0"):
        GoalEstimatorSettings(method="pose", turn_horizon=-1.0)
    with pytest.raises(ValueError, match="call pbp_drake.core.grasp_estimation"):
        goal_probabilities(SETTINGS, [[1.0, 0.0, 0.7]], HAND, 0.0)
    with pytest.raises(ValueError, match="settings.method is 'angle'"):
        estimate_pose(GoalEstimatorSettings(), [[1.0, 0.0, 0.7]], [LEVEL], HAND, LEVEL,
                      STILL, STILL)
