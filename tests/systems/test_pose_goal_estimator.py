"""The ``pose`` goal estimator as a system: what it reads as the operator's intent. With
`operator_twist` connected, a hand carried toward one grasp by the robot's own policy does
not hold the estimate there while the operator pushes toward another."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.core import quaternion
from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.systems.pbp.pose_goal_estimator import PoseGoalEstimator

PERIOD = 0.03
# Two grasps with the hand's own orientation, 0.5 m ahead: one to the left, one to the right.
GOALS = np.array([np.concatenate([[0.5, 0.4, 0.0], quaternion.IDENTITY]),
                  np.concatenate([[0.5, -0.4, 0.0], quaternion.IDENTITY])])
LEFT, RIGHT = np.array([0.0, 0.1, 0.0]), np.array([0.0, -0.1, 0.0])


def selections(hand_velocity, operator_velocity=None, seconds=0.3, hand_position=None,
               operator_until=None):
    """The estimator's selected goal after `seconds`, the hand at `hand_position` (the
    origin) moving at `hand_velocity`, the operator commanding `operator_velocity` (None:
    not connected) until `operator_until` (s; None: throughout), then nothing."""
    settings = GoalEstimatorSettings(method="pose")
    builder = DiagramBuilder()
    estimator = builder.AddSystem(PoseGoalEstimator(len(GOALS), settings, PERIOD))
    position = np.zeros(3) if hand_position is None else hand_position
    hand = np.concatenate([position, quaternion.IDENTITY, hand_velocity, np.zeros(3)])
    builder.Connect(builder.AddSystem(ConstantVectorSource(hand)).get_output_port(),
                    estimator.get_hand_pose_input_port())
    builder.Connect(builder.AddSystem(ConstantVectorSource(GOALS.reshape(-1))).get_output_port(),
                    estimator.get_goal_poses_input_port())
    if operator_velocity is not None:
        twist = np.concatenate([operator_velocity, np.zeros(3)])
        until = seconds + 1.0 if operator_until is None else operator_until
        source = TrajectorySource(PiecewisePolynomial.ZeroOrderHold(
            [0.0, until, seconds + 2.0], np.column_stack([twist, np.zeros(6), np.zeros(6)])))
        builder.Connect(builder.AddSystem(source).get_output_port(),
                        estimator.get_operator_twist_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(seconds)
    context = estimator.GetMyContextFromRoot(simulator.get_context())
    return int(estimator.get_selected_goal_output_port().Eval(context)[0])


def test_unconnected_it_reads_the_hands_own_direction_of_travel():
    assert selections(LEFT) == 0
    assert selections(RIGHT) == 1


@pytest.mark.parametrize("hand, operator, expected", [(LEFT, RIGHT, 1), (RIGHT, LEFT, 0)])
def test_connected_it_reads_the_operators_twist_not_the_hands(hand, operator, expected):
    assert selections(hand, operator) == expected


def test_an_idle_operator_shows_no_direction():
    # The hand moving left is the policy's doing: with the operator idle, the two grasps
    # (equally far, same orientation) stay tied and the first selection holds.
    first = selections(LEFT, np.zeros(3), seconds=0.0)
    assert selections(LEFT, np.zeros(3)) == first
    assert selections(RIGHT, np.zeros(3)) == first


def test_while_the_operator_gives_no_input_the_selection_holds():
    # The operator shows the right-hand grasp, then lets go while the policy carries the
    # hand to the left, nearer the left-hand grasp: no new evidence, no switch.
    near_left = np.array([0.0, 0.3, 0.0])
    assert selections(LEFT, RIGHT, seconds=1.0, hand_position=near_left,
                      operator_until=0.3) == 1
    # Unconnected, the hand's own motion and distance take the selection over.
    assert selections(LEFT, seconds=1.0, hand_position=near_left) == 0


@pytest.mark.parametrize("settings", [GoalEstimatorSettings(method="nearest"), {"method": "pose"}])
def test_it_takes_pose_settings_alone(settings):
    with pytest.raises(ValueError, match="settings must be a GoalEstimatorSettings with method "
                                         "'pose'"):
        PoseGoalEstimator(len(GOALS), settings, PERIOD)
