"""The ``pose`` goal estimator of the grasping task: which of K grasp poses the operator
means, read from the hand's position, orientation and their rates, in pure NumPy
(`pose_costs`; why: docs/tasks/grasp.md, "The `pose` goal estimator"). The settings are
the scenario's `goal_estimator` section (`GoalEstimatorSettings` with `method: pose`)."""

import numpy as np

from pbp_drake.core.goal_estimation import (
    GoalEstimate, softmax_of_costs, update_selection, validate_goals, validate_point)
from pbp_drake.core.quaternion import conjugate, log_map, multiply, unit_quaternions

# Below this distance (m) the hand is at a grasp position: no direction to it.
AT_GOAL = 1e-9
# Below this angle (rad) the hand has the grasp orientation: no axis to turn about.
AT_ORIENTATION = 1e-9


def travel_angles(grasp_positions, position, velocity, min_speed):
    """`alpha_k` (K,): the angle between `velocity` and the direction to each grasp
    position; all 0 below `min_speed`."""
    offsets = grasp_positions - position
    distances = np.linalg.norm(offsets, axis=1)
    speed = np.linalg.norm(velocity)
    if speed < max(min_speed, 1e-12):
        return np.zeros(len(grasp_positions))
    cosines = offsets @ velocity / (np.maximum(distances, AT_GOAL) * speed)
    return np.where(distances <= AT_GOAL, 0.0, np.arccos(np.clip(cosines, -1.0, 1.0)))


def turn_errors(grasp_orientations, orientation, angular_velocity):
    """`(theta (K,), closing (K,))`: the angle from the hand's orientation to each grasp
    orientation and the rate (rad/s) at which turning at `angular_velocity` shrinks it."""
    rotations = log_map(multiply(grasp_orientations.T, conjugate(orientation)[:, np.newaxis]))
    angles = np.linalg.norm(rotations, axis=0)
    axes = rotations / np.maximum(angles, AT_ORIENTATION)
    closing = np.where(angles <= AT_ORIENTATION, 0.0, angular_velocity @ axes)
    return angles, closing


def pose_costs(settings, grasp_positions, grasp_orientations, position, orientation,
               velocity, angular_velocity):
    """`cost_k = alpha_k + distance_weight |g_k - p| + orientation_weight max(0, theta_k -
    turn_horizon closing_k)` (K,) (`travel_angles`, `turn_errors`; arrays already checked)."""
    angles, closing = turn_errors(grasp_orientations, orientation, angular_velocity)
    left_to_turn = np.maximum(angles - settings.turn_horizon * closing, 0.0)
    return (travel_angles(grasp_positions, position, velocity, settings.min_speed)
            + settings.distance_weight * np.linalg.norm(grasp_positions - position, axis=1)
            + settings.orientation_weight * left_to_turn)


def pose_probabilities(settings, grasp_positions, grasp_orientations, position, orientation,
                       velocity, angular_velocity):
    """The K probabilities of the ``pose`` estimator: `softmax(-cost / temperature)`."""
    grasp_positions = validate_goals(grasp_positions)
    grasp_orientations = unit_quaternions(grasp_orientations, "grasp orientations")
    if grasp_orientations.shape != (len(grasp_positions), 4):
        raise ValueError(f"grasp orientations must be (K, 4) with K = {len(grasp_positions)} "
                         f"(one per grasp position), got shape {grasp_orientations.shape}")
    position = validate_point(position, "position")
    orientation = unit_quaternions(orientation, "orientation")
    if orientation.shape != (4,):
        raise ValueError(f"orientation must be one quaternion (4,), got shape "
                         f"{orientation.shape}")
    velocity = validate_point(velocity, "velocity")
    angular_velocity = validate_point(angular_velocity, "angular_velocity")
    costs = pose_costs(settings, grasp_positions, grasp_orientations, position, orientation,
                       velocity, angular_velocity)
    return softmax_of_costs(costs, settings.temperature)


def estimate_pose(settings, grasp_positions, grasp_orientations, position, orientation,
                  velocity, angular_velocity, memory=None):
    """One ``pose`` estimator update: `GoalEstimate(selected, probabilities, memory)`, with
    the hysteresis of `goal_estimation.estimate` (pass `memory` back in; None first)."""
    if settings.method != "pose":
        raise ValueError(f"estimate_pose computes the pose estimator; settings.method is "
                         f"{settings.method!r}")
    probabilities = pose_probabilities(settings, grasp_positions, grasp_orientations,
                                       position, orientation, velocity, angular_velocity)
    memory = update_selection(probabilities, memory, settings.margin, settings.hold_steps)
    return GoalEstimate(memory.selected, probabilities, memory)
