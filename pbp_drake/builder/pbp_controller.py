"""The shared-control controller of a task-space robot as one Diagram, built from
parameters alone (`PbpControllerConfig`): nothing in it knows which robot it drives.
Its wiring under the PBP methods and explicit arbitration (`pbp_controller`) and under
``hop`` and ``predict_then_assist`` (`hop_controller`): docs/design.md. With
`goal_estimator: {group_mass: M}` (M > 0) a `GoalGrouping` stands between the goals and
the DMP bank (`followed_goals` into the bank's `goals`), and the controller's
`selected_goal` is its `shown_goal`. A station is wired as `build_reach_diagram` does:
`station.ee_state` through a `SampleHold` into `ee_state`, and `ee_command` back.
"""

import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import Demultiplexer, Multiplexer

from pbp_drake.core.arbitration import BLEND_LAWS
from pbp_drake.core.coordinates import check_positions
from pbp_drake.core.controller_config import PbpControllerConfig
from pbp_drake.core.goal_estimation import READS_COMMAND, READS_INTENT, estimator_entry
from pbp_drake.core.methods import ASSISTED, BLENDED, METHODS
from pbp_drake.systems import (
    Blender, DmpBank, GoalEstimator, GoalGrouping, HandOver, HeadingCommand, HopAssistance,
    IntentFilterGoalEstimator, LikelyGoals, MaxEntGoalEstimator, PoseGoalEstimator,
    PoseIntentFilterGoalEstimator, PoseMaxEntGoalEstimator)
from pbp_drake.systems.pbp.dmp_bank import checked_prediction
from pbp_drake.systems.ports import EeState, OperatorCommand, checked_count

# How far ahead the task scenes draw the DMPs' paths, in samples over the DMP's duration.
TASK_PREDICTION_SAMPLES = 40
# How many goals' paths `predicted_paths` holds by default: the selected goal's and the
# three next most probable goals'. A drawing of them costs the same whatever K.
PREDICTED_GOALS = 4


def make_pbp_controller(config: PbpControllerConfig, initial_ee_state, goals,
                        prediction_steps=0, predicted_goal_count=PREDICTED_GOALS):
    """The controller of `config.method`, a Diagram named `pbp_controller` (or
    `hop_controller` under ``hop`` and ``predict_then_assist``).

    Args:
        config: the controller's parameters (validated here; ValueError names the field).
        initial_ee_state: the hand's `EeState` (8,) where the station starts (e.g.
            `hsr_initial_ee_state(station)`): the DMPs, the hand-over and the heading
            start there.
        goals: (K, 3) the candidate goals at the start, one DMP each (of
            `config.duration_for(start, goals)`); the `goals` port brings them as they move.
        prediction_steps: > 0 adds `predicted_paths` and `predicted_goals` (PBP methods):
            the paths of `predicted_goal_count` goals (at most K), the selected goal's
            first and then the most probable others', over the DMPs' duration in that many
            samples, for drawing; `predicted_goals` is their indices.

    .. pydrake_system::

        name: pbp_controller
        input_ports:
        - ee_state
        - goals
        - operator_command
        - operator_active (not under hop and predict_then_assist)
        output_ports:
        - ee_command
        - selected_goal
        - goal_probabilities
        - phase (with DMPs)
        - predicted_paths (with prediction_steps > 0)
        - predicted_goals (with prediction_steps > 0)
        - posterior_clipped (with HOP's posterior)

    `ee_state` is an `EeState`, `operator_command` an `OperatorCommand`, `operator_active`
    1 while the operator acts, `ee_command` the `EeCommand` of the next tick.
    `selected_goal` is the followed goal's index (with goal groups, -1 until the robot
    commits to one), `goal_probabilities` the estimator's K probabilities.
    """
    if not isinstance(config, PbpControllerConfig):
        raise ValueError(f"config must be PbpControllerConfig, got {type(config).__name__}")
    config.validate()
    given = initial_ee_state
    initial_ee_state = _floats(initial_ee_state).reshape(-1)
    if initial_ee_state.size != EeState.size or not np.isfinite(initial_ee_state).all():
        shown = initial_ee_state.tolist() if initial_ee_state.size else repr(given)
        raise ValueError(f"initial_ee_state must be {EeState.size} finite numbers (an "
                         f"EeState), got {shown}")
    goals = _floats(goals)
    if goals.ndim != 2 or goals.shape[1] != 3 or len(goals) == 0:
        raise ValueError(f"goals must be a non-empty (K, 3) array, got shape {goals.shape}")
    check_positions(goals, "goals")
    prediction_steps = checked_prediction(prediction_steps, None)
    predicted_goal_count = checked_count(predicted_goal_count, "predicted_goal_count")
    builder = DiagramBuilder()
    # Drake's (C++) Demultiplexers: no Python call is spent on splitting.
    split = builder.AddNamedSystem("ee_state_split", Demultiplexer([6, EeState.size - 6]))
    builder.ExportInput(split.get_input_port(), "ee_state")
    command_split = builder.AddNamedSystem("operator_command_split", Demultiplexer(
        [3, OperatorCommand.size - 3]))
    builder.ExportInput(command_split.get_input_port(), "operator_command")
    start = initial_ee_state[:3]
    name, add_policy = _POLICIES[METHODS[config.method].policy]
    estimator, reference, shown = add_policy(
        builder, config, start, goals, split, command_split, prediction_steps,
        min(predicted_goal_count, len(goals)))
    heading = builder.AddNamedSystem("heading_command", HeadingCommand(
        EeState(initial_ee_state).heading, config.control_period,
        config.hand_over.max_hand_yaw_acceleration,
        max_turn=config.hand_over.max_heading_turn))
    builder.ConnectInput("operator_command", heading.get_operator_command_input_port())
    hand_over = builder.AddNamedSystem("hand_over", HandOver(
        start, config.hand_over.max_hand_acceleration, config.hand_over.max_hand_speed,
        config.control_period))
    builder.Connect(reference, hand_over.get_reference_input_port())
    ee_command = builder.AddNamedSystem("ee_command", Multiplexer([6, 1]))
    builder.Connect(hand_over.get_command_output_port(), ee_command.get_input_port(0))
    builder.Connect(heading.get_heading_output_port(), ee_command.get_input_port(1))
    builder.ExportOutput(ee_command.get_output_port(), "ee_command")
    builder.ExportOutput(shown, "selected_goal")
    builder.ExportOutput(estimator.get_goal_probabilities_output_port(), "goal_probabilities")
    if estimator.HasOutputPort("posterior_clipped"):
        builder.ExportOutput(estimator.get_posterior_clipped_output_port(), "posterior_clipped")
    diagram = builder.Build()
    diagram.set_name(name)
    return diagram


def make_goal_estimator(config: PbpControllerConfig, goal_count, pose=False, forward_key=True):
    """The PBP methods' goal estimator of `config.goal_estimator.method` for `goal_count`
    goals: a `GoalEstimator`, an `IntentFilterGoalEstimator` (``intent_filter``) or a
    `MaxEntGoalEstimator` (``maxent_command``: HOP's posterior with the likelihood of PBP's
    operator, at the operators' speed `config.nominal_speed`); with `pose`, for grasp
    poses, the `Pose` form of each (the intent filter's operator pushing along the
    approach axis as `forward_key` says)."""
    settings, period = config.goal_estimator, config.control_period
    reads = estimator_entry(settings.method).reads
    if reads == READS_INTENT:
        if pose:
            return PoseIntentFilterGoalEstimator(goal_count, settings.intent_filter, period,
                                                 settings.margin, settings.hold_steps,
                                                 forward_key)
        return IntentFilterGoalEstimator(goal_count, settings.intent_filter, period,
                                         settings.margin, settings.hold_steps)
    if reads == READS_COMMAND:
        posterior = PoseMaxEntGoalEstimator if pose else MaxEntGoalEstimator
        return posterior(goal_count, config.hop, period, settings.margin, settings.hold_steps,
                         operator_speed=config.nominal_speed)
    return (PoseGoalEstimator if pose else GoalEstimator)(goal_count, settings, period)


def _floats(values):
    """`values` as a float array; an empty one when they are not numbers (a string)."""
    try:
        return np.asarray(values, float)
    except (TypeError, ValueError):
        return np.zeros(0)


def _add_pbp_policy(builder, config, start, goals, split, command_split, prediction_steps,
                    predicted_goal_count):
    """The goal estimator, the DMP bank and the blender; returns the estimator, the
    blender's command [p, v] and the goal shown."""
    period = config.control_period
    goal_count = len(goals)
    position_velocity = split.get_output_port(0)
    settings = config.goal_estimator
    estimator = builder.AddNamedSystem("goal_estimator", make_goal_estimator(config,
                                                                             goal_count))
    builder.ConnectInput("ee_state", estimator.get_ee_state_input_port())
    builder.ExportInput(estimator.get_goals_input_port(), "goals")
    selected = estimator.get_selected_goal_output_port()
    probabilities = estimator.get_goal_probabilities_output_port()
    # The recursive estimators (maxent_command, intent_filter) read the operator too.
    reads_operator = estimator.HasInputPort("operator_command")
    if reads_operator:
        builder.ConnectInput("operator_command", estimator.get_operator_command_input_port())

    bank = config.dmp_bank(start, goals)
    dmp_bank = builder.AddNamedSystem("dmp_bank", DmpBank(
        bank, period, lock_phase_when_operator_acts=METHODS[config.method].lock_phase,
        prediction_steps=prediction_steps,
        prediction_period=bank.duration / max(prediction_steps, 1),
        # The anti-windup of a law that adds the operator to a running DMP (PBP-Cont).
        max_speed=(config.hand_over.max_hand_speed
                   if BLEND_LAWS[config.blend_mode].adds_to_policy else None),
        # Every DMP steps from the followed one's velocity (connected below): the state is
        # then O(D) whatever K.
        compact_state=True, predicted_goal_count=predicted_goal_count))
    shown = selected
    if settings.group_mass > 0.0:
        grouping = builder.AddNamedSystem("goal_grouping", GoalGrouping(goal_count, settings,
                                                                        period))
        builder.ConnectInput("goals", grouping.get_goals_input_port())
        builder.ConnectInput("ee_state", grouping.get_ee_state_input_port())
        builder.Connect(probabilities, grouping.get_goal_probabilities_input_port())
        builder.Connect(selected, grouping.get_selected_goal_input_port())
        builder.Connect(grouping.get_followed_goals_output_port(),
                        dmp_bank.get_goals_input_port())
        shown = grouping.get_shown_goal_output_port()
    else:
        builder.ConnectInput("goals", dmp_bank.get_goals_input_port())
    builder.Connect(position_velocity, dmp_bank.get_robot_state_input_port())
    builder.ExportInput(dmp_bank.get_operator_active_input_port(), "operator_active")
    if reads_operator:
        builder.ConnectInput("operator_active", estimator.get_operator_active_input_port())

    blender = builder.AddNamedSystem("blender", Blender(
        config.blend_mode, 3, goal_count, period, config.alpha))
    builder.Connect(position_velocity, blender.get_robot_state_input_port())
    # The blender follows the selected goal's reference alone (O(D), not all K).
    builder.Connect(dmp_bank.get_selected_reference_output_port(),
                    blender.get_policy_reference_input_port())
    builder.Connect(selected, dmp_bank.get_selected_goal_input_port())
    builder.Connect(selected, blender.get_selected_goal_input_port())
    # Read at the decide stage before the estimator updates: the goal followed last tick.
    builder.Connect(selected, dmp_bank.get_followed_goal_input_port())
    builder.Connect(probabilities, blender.get_goal_probabilities_input_port())
    builder.Connect(command_split.get_output_port(0), blender.get_operator_command_input_port())
    builder.ConnectInput("operator_active", blender.get_operator_active_input_port())
    builder.ExportOutput(dmp_bank.get_phase_output_port(), "phase")
    if prediction_steps:
        likely = builder.AddNamedSystem("likely_goals", LikelyGoals(
            goal_count, predicted_goal_count))
        builder.Connect(selected, likely.get_selected_goal_input_port())
        builder.Connect(probabilities, likely.get_goal_probabilities_input_port())
        builder.Connect(likely.get_goal_indices_output_port(),
                        dmp_bank.get_predicted_goals_input_port())
        builder.ExportOutput(dmp_bank.get_predicted_paths_output_port(), "predicted_paths")
        builder.ExportOutput(likely.get_goal_indices_output_port(), "predicted_goals")
    return estimator, blender.get_command_output_port(), shown


def _add_hop_policy(builder, config, start, goals, split, command_split, prediction_steps,
                    predicted_goal_count):
    """HOP's posterior and assistance (no DMPs, nothing predicted), which assists the
    position only (the goals are positions); returns as `_add_pbp_policy`, the goal shown
    the most probable one (no hysteresis: predict-then-assist assists toward it)."""
    period = config.control_period
    goal_count = len(goals)
    posterior = builder.AddNamedSystem("goal_estimator", MaxEntGoalEstimator(
        goal_count, config.hop, period))
    builder.ConnectInput("ee_state", posterior.get_ee_state_input_port())
    builder.ExportInput(posterior.get_goals_input_port(), "goals")
    builder.ConnectInput("operator_command", posterior.get_operator_command_input_port())
    assistance = builder.AddNamedSystem("assistance", HopAssistance(
        METHODS[config.method].assistance, goal_count, config.hop, period))
    builder.Connect(split.get_output_port(0), assistance.get_robot_state_input_port())
    builder.ConnectInput("goals", assistance.get_goals_input_port())
    builder.Connect(command_split.get_output_port(0),
                    assistance.get_operator_command_input_port())
    builder.Connect(posterior.get_goal_probabilities_output_port(),
                    assistance.get_goal_probabilities_input_port())
    return posterior, assistance.get_command_output_port(), \
        posterior.get_selected_goal_output_port()


#: The Diagram's name and what adds its policy, by `Method.policy`.
_POLICIES = {BLENDED: ("pbp_controller", _add_pbp_policy),
             ASSISTED: ("hop_controller", _add_hop_policy)}
