"""The one builder: a scenario in, a Drake Diagram out.

    robot.state ──> robot_state_sample (ZeroOrderHold at the control period) ──> blender
    robot.state ──> operator ──> blender, dmp_bank (operator_active: PBP-Alt's phase lock)
    robot.state ──> dmp_bank (or demonstration_player for explicit arbitration) ──> blender
    goals ──> dmp_bank;  blender.command ──> robot.command

Every control tick `t_k` the operator and the sample of the robot state update from the
robot's state at `t_k`; a quarter plant step later (before the plant, which steps half a
step off the ticks, moves) the DMP bank steps from the same state, seeing the operator's
decision of this tick; the blender combines them into the command the robot tracks until
the next tick. Logs are taken at the ticks: the phase logged at `t_k` is the phase with
which tick k steps. Loggers named `robot_state_log`, `operator_active_log`,
`operator_command_log`, `command_log` and (PBP) `phase_log` record each tick.
"""

import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput, ZeroOrderHold

from pbp_drake.core.dmp import DmpBank as DmpBankMath
from pbp_drake.scenarios import (
    NoOperator as NoOperatorConfig, ObstacleRepulsion, ScriptedCommands, SinusoidalStep,
    demonstration_samples, dmp_settings, resolved_goals, resolved_start, validate_scenario)
from pbp_drake.systems import (
    Blender, DemonstrationPlayer, DmpBank, NoOperator, ObstacleRepulsionOperator, PointRobot,
    ScriptedOperator)

# How the scenario's method maps onto the blender (PBP-NoUser is PBP-Cont with no operator).
BLEND_MODE_OF_METHOD = {
    "pbp_alternated": "pbp_alternated",
    "pbp_continuous": "pbp_continuous",
    "pbp_no_user": "pbp_continuous",
    "fixed_alpha": "fixed_alpha",
    "teleop": "teleop",
}


def build_diagram(scenario, meshcat=None, prediction_steps=None):
    """Builds the scenario's Diagram; with `meshcat`, also draws it there.

    `prediction_steps` (default: the DMP's duration in control periods when drawing) sets how
    far ahead the DMP bank predicts its paths for drawing.
    """
    validate_scenario(scenario)
    period = scenario.control_period
    start = resolved_start(scenario)
    goals = resolved_goals(scenario)
    goal_count, dimension = goals.shape
    builder = DiagramBuilder()

    robot = builder.AddNamedSystem("robot", PointRobot(
        start, scenario.robot.mass, scenario.robot.stiffness, scenario.robot.damping,
        scenario.robot.time_step))
    robot_state = robot.get_state_output_port()
    sample = builder.AddNamedSystem("robot_state_sample", ZeroOrderHold(period, 2 * dimension))
    builder.Connect(robot_state, sample.get_input_port())

    operator = builder.AddNamedSystem("operator", make_operator(scenario, dimension))
    if operator.num_input_ports():
        builder.Connect(robot_state, operator.get_input_port(0))

    blender = builder.AddNamedSystem("blender", Blender(
        BLEND_MODE_OF_METHOD[scenario.method], dimension, goal_count, period, scenario.alpha))
    dmp_bank = None
    if scenario.method == "fixed_alpha":
        times, positions = demonstration_samples(scenario.demonstration)
        policy = builder.AddNamedSystem(
            "demonstration_player", DemonstrationPlayer(times, positions, period))
    else:
        if prediction_steps is None:
            prediction_steps = 0 if meshcat is None else int(round(
                make_dmp_bank(scenario).duration / period))
        dmp_bank = policy = builder.AddNamedSystem("dmp_bank", DmpBank(
            make_dmp_bank(scenario), period,
            lock_phase_when_operator_acts=scenario.method == "pbp_alternated",
            prediction_steps=prediction_steps, update_offset=scenario.robot.time_step / 4))
        goals_source = builder.AddNamedSystem("goals", ConstantVectorSource(goals.reshape(-1)))
        builder.Connect(goals_source.get_output_port(), dmp_bank.get_goals_input_port())
        builder.Connect(robot_state, dmp_bank.get_robot_state_input_port())
        builder.Connect(operator.get_operator_active_output_port(),
                        dmp_bank.get_operator_active_input_port())

    builder.Connect(sample.get_output_port(), blender.get_robot_state_input_port())
    builder.Connect(policy.get_references_output_port(), blender.get_references_input_port())
    builder.Connect(operator.get_operator_command_output_port(),
                    blender.get_operator_command_input_port())
    builder.Connect(operator.get_operator_active_output_port(),
                    blender.get_operator_active_input_port())
    builder.Connect(blender.get_command_output_port(), robot.get_command_input_port())

    for name, port in [("robot_state_log", robot_state),
                       ("operator_active_log", operator.get_operator_active_output_port()),
                       ("operator_command_log", operator.get_operator_command_output_port()),
                       ("command_log", blender.get_command_output_port())]:
        LogVectorOutput(port, builder, period).set_name(name)
    if dmp_bank is not None:
        LogVectorOutput(dmp_bank.get_phase_output_port(), builder, period).set_name("phase_log")

    if meshcat is not None:
        from pbp_drake.systems.point_scene_visualizer import PointSceneVisualizer

        demonstration = None
        if scenario.demonstration is not None:
            demonstration = demonstration_samples(scenario.demonstration)[1]
        visualizer = builder.AddNamedSystem("visualizer", PointSceneVisualizer(
            meshcat, start, goals, scenario.obstacles, demonstration,
            prediction_steps if dmp_bank is not None else 0))
        builder.Connect(robot_state, visualizer.get_robot_state_input_port())
        builder.Connect(operator.get_operator_active_output_port(),
                        visualizer.get_operator_active_input_port())
        if dmp_bank is not None and prediction_steps:
            builder.Connect(dmp_bank.get_predicted_paths_output_port(),
                            visualizer.get_predicted_paths_input_port())

    diagram = builder.Build()
    diagram.set_name(scenario.name)
    return diagram


def make_dmp_bank(scenario):
    """The DMP math of the scenario: learned from its demonstration, else straight paths."""
    settings = dmp_settings(scenario.dmp)
    start = resolved_start(scenario)
    goal_count = resolved_goals(scenario).shape[0]
    duration = scenario.dmp.duration if scenario.dmp.duration > 0 else None
    if scenario.demonstration is None:
        return DmpBankMath.straight(start, goal_count, duration, settings)
    times, positions = demonstration_samples(scenario.demonstration)
    return DmpBankMath.from_demonstration(times, positions, goal_count, settings, start,
                                          duration)


def make_operator(scenario, dimension):
    """The operator system the scenario asks for (none at all for PBP-NoUser)."""
    config = scenario.operator
    period = scenario.control_period
    if scenario.method == "pbp_no_user" or isinstance(config, NoOperatorConfig):
        return NoOperator(dimension, period)
    if isinstance(config, ObstacleRepulsion):
        return ObstacleRepulsionOperator(
            [o.center for o in scenario.obstacles], [o.radius for o in scenario.obstacles],
            dimension, period, config.distance_threshold, config.speed,
            config.axis if config.axis else None)
    if isinstance(config, SinusoidalStep):
        times, commands = sinusoidal_step_commands(config, period, scenario.duration)
        return ScriptedOperator(times, commands, period)
    if isinstance(config, ScriptedCommands):
        return ScriptedOperator(config.times, config.commands, period)
    raise TypeError(f"unknown operator config {type(config).__name__}")


def sinusoidal_step_commands(config, control_period, duration):
    """Samples a SinusoidalStep at the control ticks: times `(T,)`, commands `(T, D)`."""
    times = np.arange(0.0, duration + control_period / 2, control_period)
    elapsed = times - config.start_time
    on = (elapsed >= -1e-12) & (elapsed < config.duration - 1e-12)
    magnitude = np.where(on, config.amplitude * np.sin(2 * np.pi * elapsed / config.period), 0.0)
    axis = np.asarray(config.axis, float)
    return times, np.outer(magnitude, axis / np.linalg.norm(axis))
