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
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, Multiplexer, ZeroOrderHold

from pbp_drake.core.dmp import DmpBank as DmpBankMath
from pbp_drake.scenarios import (
    Gamepad as GamepadConfig, Hsr, Keyboard as KeyboardConfig, NoOperator as NoOperatorConfig,
    ObstacleRepulsion, ScriptedCommands, SinusoidalStep,
    VirtualParticipant as VirtualParticipantConfig, demonstration_samples, dmp_settings,
    goal_estimator_settings, resolved_goals, resolved_start, task_layout, validate_scenario)
from pbp_drake.robots import (
    CylinderObstacle, HsrStationConfig, hsr_initial_ee_state, make_hsr_station)
from pbp_drake.systems import (
    Blender, DemonstrationPlayer, DmpBank, GoalEstimator, GoalsSource, HeadingCommand,
    NoOperator, ObstacleRepulsionOperator, PointRobot, ReachSceneVisualizer, SampleHold,
    ScriptedOperator, TaskMonitor)
from pbp_drake.systems.moving_obstacles import MovingObstacles
from pbp_drake.systems.vector_split import VectorSplit

# How the scenario's method maps onto the blender (PBP-NoUser is PBP-Cont with no operator).
BLEND_MODE_OF_METHOD = {
    "pbp_alternated": "pbp_alternated",
    "pbp_continuous": "pbp_continuous",
    "pbp_no_user": "pbp_continuous",
    "fixed_alpha": "fixed_alpha",
    "confidence_alpha": "confidence_alpha",
    "teleop": "teleop",
}


def build_diagram(scenario, meshcat=None, prediction_steps=None):
    """Builds the scenario's Diagram; with `meshcat`, also draws it there.

    `prediction_steps` (default: the DMP's duration in control periods when drawing) sets how
    far ahead the DMP bank predicts its paths for drawing.
    """
    validate_scenario(scenario)
    if isinstance(scenario.robot, Hsr):
        return _build_hsr_diagram(scenario, meshcat)
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
        goals_source = builder.AddNamedSystem("goals", GoalsSource(goals))
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


# How far ahead the HSR scene draws the DMPs' paths, in samples over the DMP's duration.
HSR_PREDICTION_SAMPLES = 40


def _build_hsr_diagram(scenario, meshcat):
    """The HSR reaching task (section IV-B.1 of the paper):

        station.ee_state ──> ee_state_sample (SampleHold) ──> dmp_bank, goal_estimator,
                                                              task_monitor, blender
        station.ee_state, task_monitor.target, goal_estimator ──> operator
        operator.operator_command [vx, vy, vz, yaw_rate] ──> blender (v), heading_command
        blender.command [p, v] + heading ──> station.ee_command (whole-body differential IK)
        obstacles.obstacle_positions ──> station.obstacle_positions (obstacle task)
        station.in_collision ──> task_monitor

    The station (`make_hsr_station`: plant, diff IK, PD, obstacle geometry, collision
    monitor, Meshcat visualizer) is one block named `hsr_station`.

    The operator samples at the control ticks; a quarter plant step later the DMP bank, the
    goal estimator, the heading and the task monitor update from the same sampled state and
    the operator's decision of that tick, before the plant moves.
    """
    period = scenario.control_period
    task = scenario.task
    layout = task_layout(scenario)
    goals = layout.objects
    goal_count = len(goals)
    offset = scenario.robot.time_step / 4
    builder = DiagramBuilder()

    station = builder.AddNamedSystem("hsr_station", make_hsr_station(
        hsr_station_config(scenario, layout), meshcat))
    initial_ee_state = hsr_initial_ee_state(station)
    start = initial_ee_state[:3]
    ee_state = station.GetOutputPort("ee_state")
    sample = builder.AddNamedSystem("ee_state_sample", SampleHold(period, initial_ee_state))
    builder.Connect(ee_state, sample.get_input_port())
    ee_split = builder.AddNamedSystem("ee_state_split", VectorSplit([6, 2]))
    builder.Connect(sample.get_output_port(), ee_split.get_input_port())
    ee_position_velocity = ee_split.get_output_port(0)

    goals_source = builder.AddNamedSystem("goals", GoalsSource(goals))
    estimator = builder.AddNamedSystem("goal_estimator", GoalEstimator(
        goal_count, goal_estimator_settings(scenario.goal_estimator), period,
        update_offset=offset))
    builder.Connect(sample.get_output_port(), estimator.get_ee_state_input_port())
    builder.Connect(goals_source.get_output_port(), estimator.get_goals_input_port())

    monitor = builder.AddNamedSystem("task_monitor", TaskMonitor(
        goals, layout.targets, layout.switch_schedule, start, task.success_distance, period,
        update_offset=offset))
    builder.Connect(sample.get_output_port(), monitor.get_ee_state_input_port())
    obstacles = None
    if layout.obstacles is not None:
        obstacles = _add_obstacles(builder, scenario, station, layout.obstacles, start, sample,
                                   monitor, offset)

    operator = builder.AddNamedSystem("operator", make_hsr_operator(
        scenario, meshcat, layout.objects, obstacles is not None))
    for port_name, source in [("ee_state", ee_state),
                              ("target", monitor.get_target_output_port()),
                              ("selected_goal", estimator.get_selected_goal_output_port()),
                              ("obstacle_positions", obstacles and
                               obstacles.get_floor_positions_output_port())]:
        if operator.HasInputPort(port_name) and source is not None:
            builder.Connect(source, operator.GetInputPort(port_name))
    operator_active = operator.get_operator_active_output_port()
    operator_command = operator.get_operator_command_output_port()
    builder.Connect(operator_active, monitor.get_operator_active_input_port())

    bank = make_hsr_dmp_bank(scenario, start, goals)
    prediction_steps = HSR_PREDICTION_SAMPLES if meshcat is not None else 0
    dmp_bank = builder.AddNamedSystem("dmp_bank", DmpBank(
        bank, period, lock_phase_when_operator_acts=scenario.method == "pbp_alternated",
        prediction_steps=prediction_steps, update_offset=offset,
        prediction_period=bank.duration / HSR_PREDICTION_SAMPLES))
    builder.Connect(goals_source.get_output_port(), dmp_bank.get_goals_input_port())
    builder.Connect(ee_position_velocity, dmp_bank.get_robot_state_input_port())
    builder.Connect(operator_active, dmp_bank.get_operator_active_input_port())

    command_split = builder.AddNamedSystem("operator_command_split", VectorSplit([3, 1]))
    builder.Connect(operator_command, command_split.get_input_port())
    heading = builder.AddNamedSystem("heading_command", HeadingCommand(
        initial_ee_state[6], period, update_offset=offset))
    builder.Connect(operator_command, heading.get_operator_command_input_port())

    blender = builder.AddNamedSystem("blender", Blender(
        BLEND_MODE_OF_METHOD[scenario.method], 3, goal_count, period, scenario.alpha))
    builder.Connect(ee_position_velocity, blender.get_robot_state_input_port())
    builder.Connect(dmp_bank.get_references_output_port(), blender.get_references_input_port())
    builder.Connect(estimator.get_selected_goal_output_port(),
                    blender.get_selected_goal_input_port())
    builder.Connect(estimator.get_goal_probabilities_output_port(),
                    blender.get_goal_probabilities_input_port())
    builder.Connect(command_split.get_output_port(0), blender.get_operator_command_input_port())
    builder.Connect(operator_active, blender.get_operator_active_input_port())
    ee_command = builder.AddNamedSystem("ee_command", Multiplexer([6, 1]))
    builder.Connect(blender.get_command_output_port(), ee_command.get_input_port(0))
    builder.Connect(heading.get_heading_output_port(), ee_command.get_input_port(1))
    builder.Connect(ee_command.get_output_port(), station.GetInputPort("ee_command"))

    for name, port in [("ee_state_log", ee_state),
                       ("operator_active_log", operator_active),
                       ("operator_command_log", operator_command),
                       ("command_log", ee_command.get_output_port()),
                       ("selected_goal_log", estimator.get_selected_goal_output_port()),
                       ("target_log", monitor.get_target_output_port()),
                       ("phase_log", dmp_bank.get_phase_output_port())]:
        LogVectorOutput(port, builder, period).set_name(name)

    if meshcat is not None:
        visualizer = builder.AddNamedSystem("task_visualizer", ReachSceneVisualizer(
            meshcat, goals, prediction_steps))
        builder.Connect(monitor.get_target_output_port(), visualizer.get_target_input_port())
        builder.Connect(estimator.get_selected_goal_output_port(),
                        visualizer.get_selected_goal_input_port())
        builder.Connect(operator_active, visualizer.get_operator_active_input_port())
        builder.Connect(ee_state, visualizer.get_ee_state_input_port())
        builder.Connect(dmp_bank.get_predicted_paths_output_port(),
                        visualizer.get_predicted_paths_input_port())

    diagram = builder.Build()
    diagram.set_name(scenario.name)
    return diagram


def make_hsr_dmp_bank(scenario, start, goals):
    """One straight-path DMP per object from the end effector's start; the duration gives
    the farthest object the nominal speed `scenario.robot.speed`."""
    distance = np.max(np.linalg.norm(np.asarray(goals) - start, axis=1))
    duration = scenario.dmp.duration if scenario.dmp.duration > 0 else (
        distance / scenario.robot.speed)
    return DmpBankMath.straight(start, len(goals), duration, dmp_settings(scenario.dmp))


def hsr_station_config(scenario, layout):
    """The HSR station of the scenario: its robot's rates, the task's height, the control
    loop's period (the station ramps between ticks) and the task's cylinders, if any."""
    task = scenario.task
    obstacles = []
    if layout.obstacles is not None:
        obstacles = [CylinderObstacle(radius=task.obstacle_radius, height=task.obstacle_height)
                     for _ in layout.obstacles.obstacle_starts]
    return HsrStationConfig(
        plant=MultibodyPlantConfig(time_step=scenario.robot.time_step,
                                   discrete_contact_approximation="sap"),
        diff_ik_time_step=scenario.robot.diff_ik_time_step,
        command_period=scenario.control_period, ee_height=task.height, obstacles=obstacles)


def _add_obstacles(builder, scenario, station, obstacle_scene, start, sample, monitor, offset):
    """The moving cylinders' behaviour; the station holds their geometry and measures them
    against the robot."""
    task = scenario.task
    obstacles = builder.AddNamedSystem("obstacles", MovingObstacles(
        obstacle_scene, start, task.obstacle_height, task.obstacle_speed,
        scenario.control_period, update_offset=offset))
    builder.Connect(sample.get_output_port(), obstacles.get_ee_state_input_port())
    builder.Connect(obstacles.get_obstacle_positions_output_port(),
                    station.GetInputPort("obstacle_positions"))
    in_collision = station.GetOutputPort("in_collision")
    builder.Connect(in_collision, monitor.get_in_collision_input_port())
    LogVectorOutput(in_collision, builder, scenario.control_period).set_name("in_collision_log")
    return obstacles


def make_hsr_operator(scenario, meshcat, objects, with_obstacles=False):
    """The HSR task's operator: a person at the keyboard or gamepad, or the virtual one
    (which, `with_obstacles`, watches the task's obstacles)."""
    config = scenario.operator
    period = scenario.control_period
    allow_forward = scenario.method == "teleop"
    speed = getattr(config, "speed", 0.0) or scenario.robot.speed
    if scenario.method == "pbp_no_user" or isinstance(config, NoOperatorConfig):
        return NoOperator(4, period)
    if isinstance(config, VirtualParticipantConfig):
        from pbp_drake.systems.virtual_participant import VirtualParticipant

        return VirtualParticipant(
            period, objects, mode="drive" if allow_forward else "assist", speed=speed,
            rotation_speed=config.rotation_speed, reaction_delay=config.reaction_delay,
            direction_noise=config.direction_noise, speed_noise=config.speed_noise,
            seed=scenario.seed,
            obstacle_count=scenario.task.obstacle_count if with_obstacles else 0,
            obstacle_radius=scenario.task.obstacle_radius if with_obstacles else 0.0,
            policy_adds=scenario.method == "pbp_continuous")
    if meshcat is None:
        raise ValueError(f"operator !{type(config).__name__} reads the browser: it needs "
                         "Meshcat (pbp-drake run without --headless)")
    if isinstance(config, KeyboardConfig):
        from pbp_drake.systems.keyboard_operator import KeyboardOperator

        return KeyboardOperator(meshcat, period, allow_forward, speed=speed,
                                rotation_speed=config.rotation_speed,
                                hold_time=config.hold_time)
    if isinstance(config, GamepadConfig):
        from pbp_drake.systems.gamepad_operator import GamepadOperator

        return GamepadOperator(meshcat, period, allow_forward, speed=speed,
                               rotation_speed=config.rotation_speed,
                               dead_zone=config.dead_zone)
    raise TypeError(f"unknown operator config {type(config).__name__}")
