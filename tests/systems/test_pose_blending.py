"""Six-DoF PBP in a closed loop: the pose bank, the blender and the hand-over drive a hand
that follows its command. A goal switch and the operator's presses and releases keep the
commanded orientation continuous and change the commanded angular velocity by at most
0.3 rad/s per tick; the blender's modes as a user sees them."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.core import quaternion
from pbp_drake.core.dmp import DmpBankModel as PositionModel
from pbp_drake.core.dmp import DmpSettings
from pbp_drake.core.dmp.orientation_bank import OrientationDmpBank
from pbp_drake.core.pose_arbitration import HandOverLimits
from pbp_drake.systems.pbp.goals_source import GoalsSource
from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.systems import PoseBlender, PoseDmpBank, PoseGoalGrouping, PoseHandOver

DT = 0.01
ANGULAR_STEP = 0.3  # rad/s: the most the commanded angular velocity may change per tick
LIMITS = HandOverLimits(max_acceleration=3.0, max_speed=0.6,
                        max_angular_acceleration=ANGULAR_STEP / DT, max_angular_speed=2.0)
START = np.concatenate([[0.0, 0.0, 0.0], quaternion.IDENTITY])
# Two goals far apart in orientation (120 degrees between them).
GOALS = np.array([np.concatenate([[0.5, 0.3, 0.2], quaternion.exp_map([0.0, 0.0, 1.2])]),
                  np.concatenate([[0.5, -0.3, 0.2], quaternion.exp_map([0.0, 0.0, -0.9])])])


def held(times, values, width):
    """A zero-order-hold source of `values` (rows) from `times`, held after the last."""
    times = list(times) + [100.0]
    values = np.vstack([values, values[-1:]]).T.reshape(width, -1)
    return TrajectorySource(PiecewisePolynomial.ZeroOrderHold(times, values))


def closed_loop(mode, seconds, switch_at=None, presses=None, twist=None, alpha=None):
    """The commands `(ticks, 13)` the hand was sent: PoseState rows."""
    settings = DmpSettings(basis_count=20)
    positions = PositionModel.straight(START[:3], 2, 1.0, settings)
    orientations = OrientationDmpBank.straight(START[3:], 2, 1.0, settings)
    builder = DiagramBuilder()
    bank = builder.AddSystem(PoseDmpBank(
        positions, orientations, DT, lock_phase_when_operator_acts=mode == "pbp_alternated",
        max_speed=LIMITS.max_speed, max_angular_speed=LIMITS.max_angular_speed))
    blender = builder.AddSystem(PoseBlender(mode, 2, DT, alpha))
    hand_over = builder.AddSystem(PoseHandOver(START, LIMITS, DT))
    goals = builder.AddSystem(GoalsSource(GOALS))
    # The hand follows its command exactly: its state is the hand-over's output.
    hand = hand_over.get_command_output_port()
    builder.Connect(goals.get_output_port(), bank.get_goal_poses_input_port())
    builder.Connect(hand, bank.get_robot_state_input_port())
    builder.Connect(hand, blender.get_robot_state_input_port())
    builder.Connect(bank.get_selected_reference_output_port(),
                    blender.get_policy_reference_input_port())
    builder.Connect(blender.get_reference_output_port(), hand_over.get_reference_input_port())
    selection = builder.AddSystem(held([0.0, switch_at or 50.0], np.array([[0.0], [1.0]]), 1))
    builder.Connect(selection.get_output_port(), bank.get_followed_goal_input_port())
    builder.Connect(selection.get_output_port(), bank.get_selected_goal_input_port())
    times, values = presses or ([0.0], np.array([[0.0]]))
    active = builder.AddSystem(held(times, np.asarray(values, dtype=float), 1))
    builder.Connect(active.get_output_port(), bank.get_operator_active_input_port())
    builder.Connect(active.get_output_port(), blender.get_operator_active_input_port())
    operator = builder.AddSystem(ConstantVectorSource(np.zeros(6) if twist is None else twist))
    builder.Connect(operator.get_output_port(), blender.get_operator_twist_input_port())
    logger = LogVectorOutput(hand, builder, DT)
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(seconds)
    return logger.FindLog(simulator.get_context()).data().T


def assert_continuous(commands):
    """At most ANGULAR_STEP between two ticks' angular velocities, and orientations that
    turn by about the fastest allowed turn over one tick at most (a jump to the other goal
    would be 2.1 rad). About: the command is the DMP's pose after one step, turned back by
    the velocity not reached times dt; the DMP's step turns by the integral of its velocity,
    which differs from its end velocity times dt by half its angular acceleration times
    dt^2 (as in position). At a goal switch that acceleration is largest: 0.38 rad/s
    above the limit here, for one tick."""
    angular = commands[:, 10:13]
    steps = np.linalg.norm(np.diff(angular, axis=0), axis=1)
    assert steps.max() <= ANGULAR_STEP + 1e-9
    turns = [quaternion.angle_between(p, q) for p, q in zip(commands[1:, 3:7],
                                                            commands[:-1, 3:7])]
    assert max(turns) <= 1.25 * LIMITS.max_angular_speed * DT
    return steps


@pytest.mark.slow
def test_a_goal_switch_keeps_orientation_and_angular_velocity_continuous():
    commands = closed_loop("pbp_continuous", 1.2, switch_at=0.405)
    steps = assert_continuous(commands)
    switch = int(round(0.405 / DT))
    # The switch is felt: the commanded turn reverses over the next ticks, at the limit.
    assert steps[switch - 1:switch + 8].max() == pytest.approx(ANGULAR_STEP, rel=1e-6)
    before, after = commands[switch - 2, 12], commands[switch + 25, 12]
    assert before > 0.3 and after < 0.0
    # And the hand ends turned toward the new goal (-0.9 rad about z), not the first one.
    final = commands[-1, 3:7]
    assert (quaternion.angle_between(final, GOALS[1, 3:])
            < quaternion.angle_between(final, GOALS[0, 3:]))


@pytest.mark.slow
def test_presses_and_releases_keep_the_angular_velocity_continuous():
    presses = ([0.0, 0.3, 0.6], np.array([[0.0], [1.0], [0.0]]))
    twist = np.array([0.0, 0.0, 0.0, 1.5, 0.0, -1.0])  # the operator turns the hand fast
    commands = closed_loop("pbp_alternated", 1.0, presses=presses, twist=twist)
    steps = assert_continuous(commands)
    # Both the press and the release reached the limit: without the law they jump.
    for moment in (0.3, 0.6):
        tick = int(round(moment / DT))
        assert steps[tick - 1:tick + 4].max() == pytest.approx(ANGULAR_STEP, rel=1e-6)
    # While pressed, the hand turned as the operator asked (once the ramp was over).
    np.testing.assert_allclose(commands[int(0.55 / DT), 10:13], twist[3:], atol=1e-9)


def blender_reference(mode, twist, active=1.0, alpha=None, probabilities=None):
    robot = np.concatenate([[0.1, 0.2, 0.3], quaternion.exp_map([0.4, 0.0, 0.0]), np.zeros(6)])
    policy = np.concatenate([[0.2, 0.2, 0.3], quaternion.exp_map([0.0, 0.6, 0.0]),
                             [0.1, 0.0, 0.0], [0.0, 0.5, 0.0]])
    blender = PoseBlender(mode, 2, DT, alpha)
    context = blender.CreateDefaultContext()
    blender.get_robot_state_input_port().FixValue(context, robot)
    blender.get_policy_reference_input_port().FixValue(context, policy)
    blender.get_operator_twist_input_port().FixValue(context, twist)
    blender.get_operator_active_input_port().FixValue(context, [active])
    if probabilities is not None:
        blender.get_goal_probabilities_input_port().FixValue(context, probabilities)
        blender.get_selected_goal_input_port().FixValue(context, [0.0])
    return blender.get_reference_output_port().Eval(context), policy


def test_teleop_passes_the_operator_twist():
    twist = np.array([0.1, -0.2, 0.05, 0.3, 0.0, -0.7])
    reference, _ = blender_reference("teleop", twist)
    np.testing.assert_array_equal(reference[7:], twist)


def test_fixed_alpha_blends_the_twists():
    twist = np.array([0.1, -0.2, 0.05, 0.3, 0.0, -0.7])
    reference, policy = blender_reference("fixed_alpha", twist, alpha=0.25)
    np.testing.assert_allclose(reference[7:], 0.75 * twist + 0.25 * policy[7:])


def test_confidence_alpha_gives_a_sure_policy_the_command():
    twist = np.array([0.1, -0.2, 0.05, 0.3, 0.0, -0.7])
    reference, policy = blender_reference("confidence_alpha", twist,
                                          probabilities=[1.0, 0.0])
    np.testing.assert_allclose(reference[7:], policy[7:])
    unsure, _ = blender_reference("confidence_alpha", twist, probabilities=[0.5, 0.5])
    np.testing.assert_allclose(unsure[7:], twist)


def test_a_nan_operator_twist_is_refused_with_its_field_named():
    with pytest.raises(ValueError, match="operator_twist wz is NaN or infinite"):
        blender_reference("pbp_continuous", np.array([0.0, 0.0, 0.0, 0.0, 0.0, np.nan]))


@pytest.mark.parametrize("pose", [START[:6], np.append(START[:6], np.nan)])
def test_a_hand_over_start_that_is_no_pose_is_refused(pose):
    with pytest.raises(ValueError, match=r"initial_pose must be 7 finite numbers \[x, y, z, "
                                         r"qw, qx, qy, qz\]"):
        PoseHandOver(pose, LIMITS, DT)


def test_its_weight_is_a_context_parameter_as_the_blenders():
    blender = PoseBlender("fixed_alpha", 2, DT, 0.3)
    context, other = blender.CreateDefaultContext(), blender.CreateDefaultContext()
    blender.set_alpha(context, 0.8)
    assert blender.alpha(context) == 0.8 and blender.alpha(other) == 0.3
    with pytest.raises(ValueError, match="alpha must lie in"):
        blender.set_alpha(context, 1.5)
    no_user = PoseBlender("pbp_no_user", 2, DT)
    assert no_user.alpha(no_user.CreateDefaultContext()) is None
    with pytest.raises(ValueError, match="weight of fixed_alpha; this blender is pbp_no_user"):
        no_user.set_alpha(no_user.CreateDefaultContext(), 0.5)
    confident = PoseBlender("confidence_alpha", 2, DT, confidence_range=(0.2, 0.6),
                            alpha_max=0.9)
    assert (confident.confidence_range, confident.alpha_max) == ((0.2, 0.6), 0.9)
    with pytest.raises(RuntimeError, match="PoseBlender in confidence_alpha mode needs its "
                                           "goal_probabilities input port connected"):
        confident.alpha(confident.CreateDefaultContext())


@pytest.mark.parametrize("limits", [None, (1.0, 0.2), 3.0])
def test_the_pose_hand_over_names_limits_that_are_no_hand_over_limits(limits):
    with pytest.raises(ValueError, match=r"^limits must be HandOverLimits \(max_acceleration, "
                                         r"max_speed, max_angular_acceleration, "
                                         r"max_angular_speed\), got "):
        PoseHandOver(START, limits, DT)


@pytest.mark.parametrize("value", [None, "0.1"])
def test_the_pose_grouping_names_a_metres_per_radian_that_is_no_number(value):
    with pytest.raises(ValueError, match="metres_per_radian must be a finite number >= 0, got "):
        PoseGoalGrouping(2, GoalEstimatorSettings(method="pose"), DT, value)
