"""The PBP controller of the HSR tasks as one Diagram: goals, goal estimator, DMP bank,
blender and the heading, between the hand's sampled state and the station's command.

    ee_state (sampled) ──> ee_state_split ──[p, v]──> dmp_bank, blender
                       └─> goal_estimator ──> blender (selected_goal, goal_probabilities),
                                              dmp_bank (followed_goal, selected_goal)
    operator_command ──> goal_estimator (the maxent_command estimator only)
    dmp_bank.selected_reference ──> blender (policy_reference: the selected goal's alone)
    goals ──> dmp_bank, goal_estimator
    operator_command [vx, vy, vz, yaw_rate] ──> operator_command_split ──> blender (v)
                                            └─> heading_command
    operator_active ──> dmp_bank (PBP-Alt's phase lock), blender
    blender.command [p, v] ──> hand_over (the hand-over law: bounded acceleration)
    hand_over.command + heading_command.heading ──> ee_command (the station's input)

The goal estimator is a `GoalEstimator`, or with `goal_estimator: {method: maxent_command}`
a `MaxEntGoalEstimator` (HOP's posterior on the operator's command, with the scenario's
`hop` settings and the `goal_estimator` section's hysteresis), which adds the output
`posterior_clipped`. The methods ``hop`` and ``policy_blending`` have a controller of their
own, without DMPs (`pbp_drake.builder.hop_controller`).

A user with a station of their own (`pbp_drake.robots.make_hsr_station`) wires it as the
builder does: `station.ee_state` through a `SampleHold` into `ee_state`, the operator's
outputs into `operator_command` and `operator_active`, and `ee_command` back into the
station.
"""

from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import Demultiplexer, Multiplexer

from pbp_drake.systems import (
    Blender, DmpBank, GoalEstimator, GoalsSource, HandOver, HeadingCommand, MaxEntGoalEstimator)
from pbp_drake.systems.ports import EeState, OperatorCommand

# How far ahead the HSR scene draws the DMPs' paths, in samples over the DMP's duration.
HSR_PREDICTION_SAMPLES = 40


def make_pbp_controller(resolved, prediction_steps=0):
    """The PBP controller of a resolved HSR scenario, a Diagram named `pbp_controller`.

    .. pydrake_system::

        name: pbp_controller
        input_ports:
        - ee_state
        - operator_command
        - operator_active
        output_ports:
        - ee_command
        - selected_goal
        - goal_probabilities
        - phase
        - predicted_paths (with prediction_steps > 0)
        - posterior_clipped (with the maxent_command estimator)

    `prediction_steps` > 0 adds `predicted_paths` (each DMP's path over its duration in
    that many samples, for drawing).
    """
    scenario = resolved.scenario
    period = scenario.control_period
    goals = resolved.goals
    goal_count = len(goals)
    bank = resolved.dmp_bank
    builder = DiagramBuilder()

    # Drake's (C++) Demultiplexers: their outputs depend on every source, time included,
    # but everything downstream reads them once a tick (the DMP bank's and the estimator's
    # updates, and the blender only through the hand-over's update), so nothing recomputes
    # between ticks, and no Python call is spent on splitting.
    split = builder.AddNamedSystem("ee_state_split", Demultiplexer([6, EeState.size - 6]))
    builder.ExportInput(split.get_input_port(), "ee_state")
    position_velocity = split.get_output_port(0)
    goals_source = builder.AddNamedSystem("goals", GoalsSource(goals))

    reads_command = scenario.goal_estimator.method == "maxent_command"
    estimator = builder.AddNamedSystem("goal_estimator", MaxEntGoalEstimator(
        goal_count, scenario.hop, period, scenario.goal_estimator.margin,
        scenario.goal_estimator.hold_steps) if reads_command else GoalEstimator(
        goal_count, scenario.goal_estimator, period))
    builder.ConnectInput("ee_state", estimator.get_ee_state_input_port())
    builder.Connect(goals_source.get_output_port(), estimator.get_goals_input_port())

    dmp_bank = builder.AddNamedSystem("dmp_bank", DmpBank(
        bank, period, lock_phase_when_operator_acts=scenario.method == "pbp_alternated",
        prediction_steps=prediction_steps,
        prediction_period=bank.duration / max(prediction_steps, 1),
        # PBP-Cont adds the operator to a DMP that keeps running: without the limit, an
        # operator holding the hand off the DMP's path winds the DMP's velocity up past the
        # hand's speed limit until it overrides them (the other modes never hold it so).
        max_speed=(scenario.robot.max_hand_speed if resolved.blend_mode == "pbp_continuous"
                   else None),
        # Every DMP steps from the followed one's velocity (connected below): the state is
        # then O(D) whatever K (with shared weights and start, every scenario's bank, the
        # outputs are O(D) too).
        compact_state=True))
    builder.Connect(goals_source.get_output_port(), dmp_bank.get_goals_input_port())
    builder.Connect(position_velocity, dmp_bank.get_robot_state_input_port())
    builder.ExportInput(dmp_bank.get_operator_active_input_port(), "operator_active")

    command_split = builder.AddNamedSystem("operator_command_split", Demultiplexer(
        [3, OperatorCommand.size - 3]))
    builder.ExportInput(command_split.get_input_port(), "operator_command")
    heading = builder.AddNamedSystem("heading_command", HeadingCommand(
        EeState(resolved.initial_ee_state).heading, period,
        scenario.robot.max_hand_yaw_acceleration))
    builder.ConnectInput("operator_command", heading.get_operator_command_input_port())
    if reads_command:
        builder.ConnectInput("operator_command", estimator.get_operator_command_input_port())

    blender = builder.AddNamedSystem("blender", Blender(
        resolved.blend_mode, 3, goal_count, period, scenario.alpha))
    builder.Connect(position_velocity, blender.get_robot_state_input_port())
    # The blender follows the selected goal's reference alone (O(D), not all K).
    builder.Connect(dmp_bank.get_selected_reference_output_port(),
                    blender.get_policy_reference_input_port())
    builder.Connect(estimator.get_selected_goal_output_port(),
                    dmp_bank.get_selected_goal_input_port())
    builder.Connect(estimator.get_selected_goal_output_port(),
                    blender.get_selected_goal_input_port())
    # Read at the decide stage before the estimator updates: the goal followed last tick.
    builder.Connect(estimator.get_selected_goal_output_port(),
                    dmp_bank.get_followed_goal_input_port())
    builder.Connect(estimator.get_goal_probabilities_output_port(),
                    blender.get_goal_probabilities_input_port())
    builder.Connect(command_split.get_output_port(0), blender.get_operator_command_input_port())
    builder.ConnectInput("operator_active", blender.get_operator_active_input_port())

    add_hand_over(builder, resolved, blender.get_command_output_port(), heading)
    builder.ExportOutput(estimator.get_selected_goal_output_port(), "selected_goal")
    builder.ExportOutput(estimator.get_goal_probabilities_output_port(), "goal_probabilities")
    builder.ExportOutput(dmp_bank.get_phase_output_port(), "phase")
    if prediction_steps:
        builder.ExportOutput(dmp_bank.get_predicted_paths_output_port(), "predicted_paths")
    if reads_command:
        builder.ExportOutput(estimator.get_posterior_clipped_output_port(), "posterior_clipped")
    diagram = builder.Build()
    diagram.set_name("pbp_controller")
    return diagram


def add_hand_over(builder, resolved, reference, heading):
    """Adds to `builder` the hand-over every method's command goes through (`HandOver`,
    from the `reference` [p, v] output port, within the robot's limits) and the station's
    command, its output with `heading`'s (a `HeadingCommand`), exported as `ee_command`."""
    scenario = resolved.scenario
    hand_over = builder.AddNamedSystem("hand_over", HandOver(
        resolved.start, scenario.robot.max_hand_acceleration, scenario.robot.max_hand_speed,
        scenario.control_period))
    builder.Connect(reference, hand_over.get_reference_input_port())
    ee_command = builder.AddNamedSystem("ee_command", Multiplexer([6, 1]))
    builder.Connect(hand_over.get_command_output_port(), ee_command.get_input_port(0))
    builder.Connect(heading.get_heading_output_port(), ee_command.get_input_port(1))
    builder.ExportOutput(ee_command.get_output_port(), "ee_command")
