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
from pydrake.systems.primitives import LogVectorOutput, Multiplexer, ZeroOrderHold

from pbp_drake.scenarios import (
    Gamepad as GamepadConfig, Keyboard as KeyboardConfig, NoOperator as NoOperatorConfig,
    ObstacleRepulsion, ResolvedScenario, ScriptedCommands, SinusoidalStep,
    VirtualParticipant as VirtualParticipantConfig, resolve)
from pbp_drake.systems import (
    Blender, DemonstrationPlayer, DmpBank, GoalsSource, NoOperator, ObstacleRepulsionOperator,
    PointRobot, ScriptedOperator)


def build_diagram(scenario, meshcat=None, prediction_steps=None):
    """Builds the Diagram of a `ResolvedScenario` (or of a `Scenario`, resolved here once);
    with `meshcat`, also draws it there.

    `prediction_steps` (default: the DMP's duration in control periods when drawing) sets how
    far ahead the DMP bank predicts its paths for drawing.
    """
    resolved = scenario if isinstance(scenario, ResolvedScenario) else resolve(scenario)
    if resolved.is_hsr:
        return _build_hsr_diagram(resolved, meshcat)
    scenario = resolved.scenario
    period = scenario.control_period
    start, goals = resolved.start, resolved.goals
    goal_count, dimension = goals.shape
    builder = DiagramBuilder()

    robot = builder.AddNamedSystem("robot", PointRobot(start, scenario.robot))
    robot_state = robot.get_state_output_port()
    sample = builder.AddNamedSystem("robot_state_sample", ZeroOrderHold(period, 2 * dimension))
    builder.Connect(robot_state, sample.get_input_port())

    operator = builder.AddNamedSystem("operator", make_operator(scenario, dimension))
    if operator.num_input_ports():
        builder.Connect(robot_state, operator.get_input_port(0))

    blender = builder.AddNamedSystem("blender", Blender(
        resolved.blend_mode, dimension, goal_count, period, scenario.alpha))
    dmp_bank = None
    if scenario.method == "fixed_alpha":
        times, positions = resolved.demonstration
        policy = builder.AddNamedSystem(
            "demonstration_player", DemonstrationPlayer(times, positions, period))
    else:
        if prediction_steps is None:
            prediction_steps = 0 if meshcat is None else int(round(
                resolved.dmp_bank.duration / period))
        dmp_bank = policy = builder.AddNamedSystem("dmp_bank", DmpBank(
            resolved.dmp_bank, period,
            lock_phase_when_operator_acts=scenario.method == "pbp_alternated",
            prediction_steps=prediction_steps))
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
        if resolved.demonstration is not None:
            demonstration = resolved.demonstration[1]
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


def make_operator(scenario, dimension):
    """The operator system the scenario asks for (none at all for PBP-NoUser)."""
    config = scenario.operator
    period = scenario.control_period
    if scenario.method == "pbp_no_user" or isinstance(config, NoOperatorConfig):
        return NoOperator(dimension, period)
    if isinstance(config, ObstacleRepulsion):
        return ObstacleRepulsionOperator(
            [o.center for o in scenario.obstacles], [o.radius for o in scenario.obstacles],
            dimension, period, config)
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


def _build_hsr_diagram(resolved, meshcat):
    """The HSR reaching task (section IV-B.1 of the paper):

        station.ee_state ──> ee_state_sample (SampleHold) ──> dmp_bank, goal_estimator,
                                                              task_monitor, blender
        station.ee_state, task_monitor.target, goal_estimator ──> operator
        operator.operator_command [vx, vy, vz, yaw_rate] ──> blender (v), heading_command
        blender.command [p, v] + heading ──> station.ee_command (whole-body differential IK)

    The operator samples at the control ticks; a quarter plant step later the DMP bank, the
    goal estimator, the heading and the task monitor update from the same sampled state and
    the operator's decision of that tick, before the plant moves.
    """
    from pbp_drake.robots.hsr_station import add_hsr_station
    from pbp_drake.systems.goal_estimator import GoalEstimator
    from pbp_drake.systems.heading_command import HeadingCommand
    from pbp_drake.systems.sample_hold import SampleHold
    from pbp_drake.systems.task_monitor import TaskMonitor
    from pbp_drake.systems.vector_split import VectorSplit

    scenario = resolved.scenario
    period = scenario.control_period
    task = scenario.task
    layout = resolved.layout
    goals = layout.objects
    goal_count = len(goals)
    offset = resolved.station.plant.time_step / 4
    builder = DiagramBuilder()

    station = add_hsr_station(builder, time_step=resolved.station.plant.time_step,
                              meshcat=meshcat, ee_height=task.height, command_period=period,
                              diff_ik_time_step=resolved.station.diff_ik_time_step)
    start = station.initial_ee_state[:3]
    ee_state = station.ee_state
    sample = builder.AddNamedSystem("ee_state_sample",
                                    SampleHold(period, station.initial_ee_state))
    builder.Connect(ee_state, sample.get_input_port())
    ee_split = builder.AddNamedSystem("ee_state_split", VectorSplit([6, 2]))
    builder.Connect(sample.get_output_port(), ee_split.get_input_port())
    ee_position_velocity = ee_split.get_output_port(0)

    goals_source = builder.AddNamedSystem("goals", GoalsSource(goals))
    estimator = builder.AddNamedSystem("goal_estimator", GoalEstimator(
        goal_count, scenario.goal_estimator, period,
        update_offset=offset))
    builder.Connect(sample.get_output_port(), estimator.get_ee_state_input_port())
    builder.Connect(goals_source.get_output_port(), estimator.get_goals_input_port())

    monitor = builder.AddNamedSystem("task_monitor", TaskMonitor(
        goals, layout.targets, layout.switch_schedule, start, task.success_distance, period,
        update_offset=offset))
    builder.Connect(sample.get_output_port(), monitor.get_ee_state_input_port())
    obstacles = None
    if layout.obstacles is not None:
        obstacles = _add_obstacles(builder, scenario, station, layout.obstacles, sample,
                                   monitor, offset)

    operator = builder.AddNamedSystem("operator", make_hsr_operator(
        resolved, meshcat, obstacles is not None))
    for port_name, source in [("ee_state", ee_state),
                              ("target", monitor.get_target_output_port()),
                              ("selected_goal", estimator.get_selected_goal_output_port()),
                              ("obstacle_positions", obstacles and
                               obstacles.get_obstacle_positions_output_port())]:
        if operator.HasInputPort(port_name) and source is not None:
            builder.Connect(source, operator.GetInputPort(port_name))
    operator_active = operator.get_operator_active_output_port()
    operator_command = operator.get_operator_command_output_port()
    builder.Connect(operator_active, monitor.get_operator_active_input_port())

    bank = resolved.dmp_bank
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
        station.initial_ee_state[6], period, update_offset=offset))
    builder.Connect(operator_command, heading.get_operator_command_input_port())

    blender = builder.AddNamedSystem("blender", Blender(
        resolved.blend_mode, 3, goal_count, period, scenario.alpha))
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
    builder.Connect(ee_command.get_output_port(), station.ee_command)

    for name, port in [("ee_state_log", ee_state),
                       ("operator_active_log", operator_active),
                       ("operator_command_log", operator_command),
                       ("command_log", ee_command.get_output_port()),
                       ("selected_goal_log", estimator.get_selected_goal_output_port()),
                       ("target_log", monitor.get_target_output_port()),
                       ("phase_log", dmp_bank.get_phase_output_port())]:
        LogVectorOutput(port, builder, period).set_name(name)

    if meshcat is not None:
        from pbp_drake.systems.reach_scene_visualizer import ReachSceneVisualizer

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


def _add_obstacles(builder, scenario, station, obstacle_scene, sample, monitor, offset):
    """The moving cylinders, measured against the robot's collision geometry."""
    from pydrake.geometry import CollisionFilterDeclaration, GeometrySet

    from pbp_drake.systems.collision_monitor import CollisionMonitor
    from pbp_drake.systems.moving_obstacles import MovingObstacles

    task = scenario.task
    plant, scene_graph = station.plant, station.scene_graph
    obstacles = builder.AddNamedSystem("obstacles", MovingObstacles(
        scene_graph, obstacle_scene, station.initial_ee_state[:3], task.obstacle_radius,
        task.obstacle_height, task.obstacle_speed, scenario.control_period,
        update_offset=offset))
    builder.Connect(sample.get_output_port(), obstacles.get_ee_state_input_port())
    builder.Connect(obstacles.get_geometry_pose_output_port(),
                    scene_graph.get_source_pose_port(obstacles.source_id))
    robot_geometries = [geometry for body in plant.GetBodyIndices(station.model)
                        for geometry in plant.GetCollisionGeometriesForBody(plant.get_body(body))]
    # The obstacles are measured, not felt: keep them out of the plant's contact (which
    # also refuses pairs of geometries it does not own, such as two obstacles meeting).
    scene_graph.collision_filter_manager().Apply(
        CollisionFilterDeclaration()
        .ExcludeBetween(GeometrySet(robot_geometries), GeometrySet(obstacles.geometry_ids))
        .ExcludeWithin(GeometrySet(obstacles.geometry_ids)))
    collisions = builder.AddNamedSystem(
        "collision_monitor", CollisionMonitor(robot_geometries, obstacles.geometry_ids))
    builder.Connect(scene_graph.get_query_output_port(),
                    collisions.get_query_object_input_port())
    builder.Connect(collisions.get_in_collision_output_port(),
                    monitor.get_in_collision_input_port())
    LogVectorOutput(collisions.get_in_collision_output_port(), builder,
                    scenario.control_period).set_name("in_collision_log")
    return obstacles


def make_hsr_operator(resolved, meshcat, with_obstacles=False):
    """The HSR task's operator: a person at the keyboard or gamepad, or the virtual one
    (which, `with_obstacles`, watches the task's obstacles)."""
    scenario = resolved.scenario
    config = scenario.operator
    period = scenario.control_period
    allow_forward = scenario.method == "teleop"
    speed = resolved.nominal_speed
    if scenario.method == "pbp_no_user" or isinstance(config, NoOperatorConfig):
        return NoOperator(4, period)
    if isinstance(config, VirtualParticipantConfig):
        from pbp_drake.systems.virtual_participant import VirtualParticipant

        return VirtualParticipant(
            period, resolved.layout.objects, mode="drive" if allow_forward else "assist",
            params=config, nominal_speed=speed, seed=scenario.seed,
            obstacle_count=scenario.task.obstacle_count if with_obstacles else 0,
            obstacle_radius=scenario.task.obstacle_radius if with_obstacles else 0.0,
            policy_adds=scenario.method == "pbp_continuous")
    if meshcat is None:
        raise ValueError(f"operator !{type(config).__name__} reads the browser: it needs "
                         "Meshcat (pbp-drake run without --headless)")
    if isinstance(config, KeyboardConfig):
        from pbp_drake.systems.keyboard_operator import KeyboardOperator

        return KeyboardOperator(meshcat, period, allow_forward, config, nominal_speed=speed)
    if isinstance(config, GamepadConfig):
        from pbp_drake.systems.gamepad_operator import GamepadOperator

        return GamepadOperator(meshcat, period, allow_forward, config, nominal_speed=speed)
    raise TypeError(f"unknown operator config {type(config).__name__}")
