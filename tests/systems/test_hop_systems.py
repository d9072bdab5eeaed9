"""HOP's systems in small diagrams: the goal posterior (`MaxEntGoalEstimator`,
`PoseMaxEntGoalEstimator`) and the intent filter (`IntentFilterGoalEstimator`,
`PoseIntentFilterGoalEstimator`) keep the
core's recursive belief tick by tick, in the Context alone; the assistance
(`HopAssistance`, `PoseHopAssistance`) sends the operator's command plus HOP's action, and
predict-then-assist the operator's alone until it is confident."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.core import quaternion
from pbp_drake.core.grasp_task import side_grasp_orientation
from pbp_drake.core.hindsight_optimization import (
    HopSettings, assisted_command, hop_targets, uniform_log_belief, update_posterior)
from pbp_drake.core.intent_filter import (
    IntentFilterSettings, filter_step, intent_features, pose_intent_features)
from pbp_drake.systems import (
    HopAssistance, IntentFilterGoalEstimator, MaxEntGoalEstimator, PoseHopAssistance,
    PoseIntentFilterGoalEstimator, PoseMaxEntGoalEstimator)

PERIOD = 0.03
SETTINGS = HopSettings()
GOALS = np.array([[1.5, 0.5, 0.7], [1.5, -0.5, 0.7], [0.2, 1.5, 0.7]])
HAND = np.array([0.0, 0.0, 0.7])
TOWARD_FIRST = 0.12 * (GOALS[0] - HAND) / np.linalg.norm(GOALS[0] - HAND)


def constant(builder, value):
    return builder.AddSystem(ConstantVectorSource(np.asarray(value, float))).get_output_port()


def estimator_diagram(command, settings=SETTINGS, margin=0.0, hold_steps=1):
    """The estimator fed the hand at HAND, the goals and `command` (a vector, or a source
    system for a command that changes)."""
    builder = DiagramBuilder()
    estimator = builder.AddSystem(MaxEntGoalEstimator(len(GOALS), settings, PERIOD, margin,
                                                      hold_steps))
    builder.Connect(constant(builder, np.concatenate([HAND, np.zeros(5)])),
                    estimator.get_ee_state_input_port())
    builder.Connect(constant(builder, GOALS.reshape(-1)), estimator.get_goals_input_port())
    source = (builder.AddSystem(command).get_output_port()
              if hasattr(command, "get_output_port") else constant(builder, command))
    builder.Connect(source, estimator.get_operator_command_input_port())
    return builder.Build(), estimator


def outputs(estimator, simulator):
    context = estimator.GetMyContextFromRoot(simulator.get_context())
    return (int(estimator.get_selected_goal_output_port().Eval(context)[0]),
            estimator.get_goal_probabilities_output_port().Eval(context),
            estimator.get_posterior_clipped_output_port().Eval(context)[0])


def test_the_estimator_keeps_the_cores_recursive_belief_tick_by_tick():
    diagram, estimator = estimator_diagram(np.append(TOWARD_FIRST, 0.0))
    simulator = Simulator(diagram)
    simulator.Initialize()
    selected, probabilities, _ = outputs(estimator, simulator)
    np.testing.assert_array_equal(probabilities, np.full(3, 1.0 / 3.0))  # the prior
    log_belief, targets = uniform_log_belief(3), hop_targets(GOALS)
    for tick in range(40):  # the first update is tick 0's, at its decide stage
        simulator.AdvanceTo(tick * PERIOD + 1e-4)
        log_belief = update_posterior(SETTINGS, targets, log_belief, HAND,
                                      TOWARD_FIRST).log_belief
        np.testing.assert_allclose(outputs(estimator, simulator)[1], np.exp(log_belief),
                                   rtol=0, atol=1e-14)
    assert outputs(estimator, simulator)[0] == 0


@pytest.mark.parametrize("active", [1.0, 0.0])
def test_the_intent_filter_keeps_the_cores_belief_tick_by_tick(active):
    """`IntentFilterGoalEstimator` (the ``intent_filter`` estimator): the core's filter on
    the operator's command and yaw rate while it acts, and on the hand's own velocity (no
    turn) while it is silent, the hand's heading both ways."""
    settings = IntentFilterSettings(silence_rate=100.0)  # a silence read too
    hand_velocity = np.array([0.0, 0.1, 0.0])  # toward the third goal
    heading = 0.3
    builder = DiagramBuilder()
    estimator = builder.AddSystem(IntentFilterGoalEstimator(len(GOALS), settings, PERIOD))
    builder.Connect(constant(builder, np.concatenate([HAND, hand_velocity, [heading, 0.0]])),
                    estimator.get_ee_state_input_port())
    builder.Connect(constant(builder, GOALS.reshape(-1)), estimator.get_goals_input_port())
    builder.Connect(constant(builder, np.append(TOWARD_FIRST, 0.4)),
                    estimator.get_operator_command_input_port())
    builder.Connect(constant(builder, [active]), estimator.get_operator_active_input_port())
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    log_belief = uniform_log_belief(3)
    motion, yaw_rate = (TOWARD_FIRST, 0.4) if active else (hand_velocity, 0.0)
    for tick in range(40):
        simulator.AdvanceTo(tick * PERIOD + 1e-4)
        update = filter_step(settings, log_belief, intent_features(
            GOALS, HAND, motion, heading, yaw_rate, PERIOD, settings.min_speed, bool(active)),
            PERIOD)
        log_belief = update.log_belief
        np.testing.assert_allclose(outputs(estimator, simulator)[1], update.probabilities,
                                   rtol=0, atol=1e-14)
    assert outputs(estimator, simulator)[0] == (0 if active else 2)


@pytest.mark.parametrize("active, forward_key, shown", [(1.0, True, -1), (1.0, False, 0),
                                                       (0.0, False, 0)])
def test_the_pose_intent_filter_keeps_the_cores_belief_tick_by_tick(active, forward_key,
                                                                    shown):
    """`PoseIntentFilterGoalEstimator` (the grasping task's ``intent_filter``): the core's
    pose features on the operator's twist while it acts and the hand's own while it is
    silent, the goal shown overridden while it acts, the forward key as the method has it."""
    settings = IntentFilterSettings(silence_rate=8.0, override_rate=10.0)
    orientations = np.array([side_grasp_orientation(angle) for angle in (0.3, -0.3, 1.2)])
    hand = np.concatenate([HAND, side_grasp_orientation(0.0), [0.0, 0.1, 0.0, 0.0, 0.0, 0.0]])
    twist = np.concatenate([TOWARD_FIRST, [0.0, 0.0, 0.3]])
    builder = DiagramBuilder()
    estimator = builder.AddSystem(PoseIntentFilterGoalEstimator(
        len(GOALS), settings, PERIOD, forward_key=forward_key))
    builder.Connect(constant(builder, hand), estimator.get_hand_pose_input_port())
    builder.Connect(constant(builder, np.hstack([GOALS, orientations]).reshape(-1)),
                    estimator.get_goal_poses_input_port())
    builder.Connect(constant(builder, twist), estimator.get_operator_twist_input_port())
    builder.Connect(constant(builder, [active]), estimator.get_operator_active_input_port())
    builder.Connect(constant(builder, [shown]), estimator.get_shown_goal_input_port())
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    log_belief = uniform_log_belief(3)
    velocity, angular_velocity = (twist[:3], twist[3:]) if active else (hand[7:10],
                                                                        np.zeros(3))
    for tick in range(20):
        simulator.AdvanceTo(tick * PERIOD + 1e-4)
        update = filter_step(settings, log_belief, pose_intent_features(
            GOALS, orientations, HAND, hand[3:7], velocity, angular_velocity, PERIOD,
            settings.min_speed, bool(active), forward_key, shown), PERIOD)
        log_belief = update.log_belief
        np.testing.assert_allclose(outputs(estimator, simulator)[1], update.probabilities,
                                   rtol=0, atol=1e-14)


def test_the_intent_filter_takes_its_own_settings():
    with pytest.raises(ValueError, match="settings must be IntentFilterSettings, got "
                                         "HopSettings"):
        IntentFilterGoalEstimator(len(GOALS), SETTINGS, PERIOD)


def test_the_intent_filter_refuses_a_nan_goal_at_its_first_update():
    goals = GOALS.copy()
    goals[1, 0] = np.nan
    builder = DiagramBuilder()
    estimator = builder.AddSystem(IntentFilterGoalEstimator(
        len(GOALS), IntentFilterSettings(), PERIOD))
    builder.Connect(constant(builder, np.concatenate([HAND, np.zeros(5)])),
                    estimator.get_ee_state_input_port())
    builder.Connect(constant(builder, goals.reshape(-1)), estimator.get_goals_input_port())
    builder.Connect(constant(builder, np.zeros(4)), estimator.get_operator_command_input_port())
    builder.Connect(constant(builder, [1.0]), estimator.get_operator_active_input_port())
    simulator = Simulator(builder.Build())
    with pytest.raises(ValueError, match="goals contain NaN or infinite values"):
        simulator.AdvanceTo(PERIOD)


@pytest.mark.parametrize("estimator", [
    lambda: IntentFilterGoalEstimator(len(GOALS), IntentFilterSettings(), PERIOD),
    lambda: MaxEntGoalEstimator(len(GOALS), SETTINGS, PERIOD),
])
@pytest.mark.parametrize("port, field, message", [
    ("ee_state", 1, r"ee_state y is NaN or infinite: \[0.0, nan"),
    ("operator_command", 3, r"operator_command yaw_rate is NaN or infinite: \[0.0, 0.0, 0.0"),
])
def test_the_estimators_refuse_a_nan_hand_or_command_naming_the_field(estimator, port, field,
                                                                      message):
    values = {"ee_state": np.concatenate([HAND, np.zeros(5)]), "operator_command": np.zeros(4)}
    values[port][field] = np.nan
    builder = DiagramBuilder()
    estimator = builder.AddSystem(estimator())
    builder.Connect(constant(builder, values["ee_state"]), estimator.get_ee_state_input_port())
    builder.Connect(constant(builder, GOALS.reshape(-1)), estimator.get_goals_input_port())
    builder.Connect(constant(builder, values["operator_command"]),
                    estimator.get_operator_command_input_port())
    builder.Connect(constant(builder, [1.0]), estimator.get_operator_active_input_port())
    simulator = Simulator(builder.Build())
    with pytest.raises(ValueError, match=message):
        simulator.AdvanceTo(PERIOD)


@pytest.mark.parametrize("estimator", [
    lambda: PoseIntentFilterGoalEstimator(len(GOALS), IntentFilterSettings(), PERIOD),
    lambda: PoseMaxEntGoalEstimator(len(GOALS), SETTINGS, PERIOD),
])
@pytest.mark.parametrize("port, field, message", [
    ("hand_pose", 1, r"hand_pose y is NaN or infinite: \[0.0, nan"),
    ("hand_pose", 12, r"hand_pose wz is NaN or infinite"),
    ("operator_twist", 5, r"operator_twist wz is NaN or infinite: \[0.0, 0.0, 0.0"),
])
def test_the_pose_estimators_refuse_a_nan_hand_or_twist_naming_the_field(estimator, port, field,
                                                                         message):
    # Silent or acting (`operator_active` 0 and 1) the intent filter read a NaN into finite
    # probabilities.
    orientation = side_grasp_orientation(0.0)
    values = {"hand_pose": np.concatenate([HAND, orientation, np.zeros(6)]),
              "operator_twist": np.zeros(6)}
    values[port][field] = np.nan
    for active in (0.0, 1.0):
        builder = DiagramBuilder()
        system = builder.AddSystem(estimator())
        builder.Connect(constant(builder, values["hand_pose"]), system.get_hand_pose_input_port())
        builder.Connect(constant(builder, np.hstack([GOALS, np.tile(orientation, (3, 1))])
                                 .reshape(-1)), system.get_goal_poses_input_port())
        builder.Connect(constant(builder, values["operator_twist"]),
                        system.get_operator_twist_input_port())
        builder.Connect(constant(builder, [active]), system.get_operator_active_input_port())
        simulator = Simulator(builder.Build())
        with pytest.raises(ValueError, match=message):
            simulator.AdvanceTo(PERIOD)


def test_the_assistance_systems_keep_their_method():
    assert HopAssistance("predict_then_assist", 3, SETTINGS, PERIOD).method == (
        "predict_then_assist")
    assert PoseHopAssistance("hop", 3, SETTINGS, PERIOD).method == "hop"


@pytest.mark.slow
def test_commanding_a_goal_long_enough_sits_at_the_clip():
    diagram, estimator = estimator_diagram(np.append(TOWARD_FIRST, 0.0))
    simulator = Simulator(diagram)
    simulator.AdvanceTo(3.0)
    assert outputs(estimator, simulator)[2] == 0.0
    simulator.AdvanceTo(60.0)
    selected, probabilities, clipped = outputs(estimator, simulator)
    assert (selected, clipped) == (0, 1.0)
    assert probabilities[0] == pytest.approx(0.99, abs=1e-12)


def test_two_contexts_and_a_restart_give_the_same_belief():
    diagram, estimator = estimator_diagram(np.append(TOWARD_FIRST, 0.0))
    first = Simulator(diagram)
    first.AdvanceTo(1.0)
    beliefs = outputs(estimator, first)[1].copy()
    second = Simulator(diagram)
    second.AdvanceTo(1.0)
    np.testing.assert_array_equal(outputs(estimator, second)[1], beliefs)
    first.get_mutable_context().SetTimeStateAndParametersFrom(diagram.CreateDefaultContext())
    first.Initialize()
    first.AdvanceTo(1.0)
    np.testing.assert_array_equal(outputs(estimator, first)[1], beliefs)


@pytest.mark.slow
def test_the_selection_moves_only_after_the_hysteresis():
    """The operator turns from the first goal to the second after 3 s: with margin 0.1 and
    10 held updates the selection moves later than with none."""
    toward_second = 0.12 * (GOALS[1] - HAND) / np.linalg.norm(GOALS[1] - HAND)
    commands = np.column_stack([np.append(TOWARD_FIRST, 0.0), np.append(toward_second, 0.0),
                                np.append(toward_second, 0.0)])

    def switch_time(margin, hold_steps):
        source = TrajectorySource(PiecewisePolynomial.ZeroOrderHold([0.0, 3.0, 100.0],
                                                                    commands))
        diagram, estimator = estimator_diagram(source, margin=margin, hold_steps=hold_steps)
        simulator = Simulator(diagram)
        for tick in range(1, 600):
            simulator.AdvanceTo(tick * PERIOD + 1e-4)
            if outputs(estimator, simulator)[0] == 1:
                return tick * PERIOD
        return None

    at_once, held = switch_time(0.0, 1), switch_time(0.1, 10)
    assert 3.0 < at_once < held


def assistance_output(method, probabilities, command):
    builder = DiagramBuilder()
    assistance = builder.AddSystem(HopAssistance(method, len(GOALS), SETTINGS, PERIOD))
    builder.Connect(constant(builder, np.concatenate([HAND, np.zeros(3)])),
                    assistance.get_robot_state_input_port())
    builder.Connect(constant(builder, GOALS.reshape(-1)), assistance.get_goals_input_port())
    builder.Connect(constant(builder, command), assistance.get_operator_command_input_port())
    builder.Connect(constant(builder, probabilities),
                    assistance.get_goal_probabilities_input_port())
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    return assistance.get_command_output_port().Eval(
        assistance.GetMyContextFromRoot(context))


def test_hop_sends_the_operator_plus_the_assistance_as_a_one_tick_reference():
    belief = np.array([0.6, 0.3, 0.1])
    command = assistance_output("hop", belief, TOWARD_FIRST)
    expected = assisted_command("hop", SETTINGS, hop_targets(GOALS), belief, HAND,
                                TOWARD_FIRST).velocity
    np.testing.assert_array_equal(command[3:], expected)
    np.testing.assert_allclose(command[:3], HAND + expected * PERIOD, rtol=0, atol=1e-15)
    # Faster toward the goals than the operator alone: the assistance adds to the command.
    assert np.linalg.norm(command[3:]) > np.linalg.norm(TOWARD_FIRST)


def test_predict_then_assist_is_the_operator_until_confident():
    unsure = assistance_output("predict_then_assist", [0.5, 0.3, 0.2], TOWARD_FIRST)
    np.testing.assert_array_equal(unsure[3:], TOWARD_FIRST)
    sure = assistance_output("predict_then_assist", [0.9, 0.05, 0.05], TOWARD_FIRST)
    certain = assistance_output("hop", [1.0, 0.0, 0.0], TOWARD_FIRST)
    np.testing.assert_array_equal(sure, certain)


def test_a_nan_command_raises():
    with pytest.raises(ValueError, match="velocity is NaN"):
        assistance_output("hop", [0.4, 0.3, 0.3], [np.nan, 0.0, 0.0])


def test_the_pose_systems_turn_the_hand_toward_the_grasp_it_turns_toward():
    """Two grasps at the same place, turned either way: the operator's turn names one, and
    HOP's assistance turns the hand further toward it."""
    orientations = np.array([side_grasp_orientation(0.6), side_grasp_orientation(-0.6)])
    hand_orientation = side_grasp_orientation(0.0)
    goal_poses = np.hstack([np.tile([1.0, 0.0, 0.7], (2, 1)), orientations]).reshape(-1)
    hand = np.concatenate([HAND, hand_orientation, np.zeros(6)])
    twist = np.array([0.1, 0.0, 0.0, 0.0, 0.0, 0.3])  # forward, turning left
    builder = DiagramBuilder()
    estimator = builder.AddSystem(PoseMaxEntGoalEstimator(2, SETTINGS, PERIOD))
    assistance = builder.AddSystem(PoseHopAssistance("hop", 2, SETTINGS, PERIOD))
    for port in (estimator.get_hand_pose_input_port(), assistance.get_robot_state_input_port()):
        builder.Connect(constant(builder, hand), port)
    for port in (estimator.get_goal_poses_input_port(), assistance.get_goal_poses_input_port()):
        builder.Connect(constant(builder, goal_poses), port)
    for port in (estimator.get_operator_twist_input_port(),
                 assistance.get_operator_twist_input_port()):
        builder.Connect(constant(builder, twist), port)
    builder.Connect(estimator.get_goal_probabilities_output_port(),
                    assistance.get_goal_probabilities_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(2.0)
    context = simulator.get_context()
    probabilities = estimator.get_goal_probabilities_output_port().Eval(
        estimator.GetMyContextFromRoot(context))
    assert probabilities[0] > 0.5 > probabilities[1]
    reference = assistance.get_reference_output_port().Eval(
        assistance.GetMyContextFromRoot(context))
    # More left turn than the operator's own, and the pose is the twist applied for a tick.
    assert reference[12] > twist[5]
    turned = quaternion.multiply(quaternion.exp_map(reference[10:13] * PERIOD),
                                 hand_orientation)
    np.testing.assert_allclose(reference[3:7], quaternion.aligned(turned, hand_orientation),
                               atol=1e-12)
