"""The reaching and obstacle tasks' diagram (sections IV-B.1 and IV-B.2 of the paper) on
the HSR or an arm, a handful of blocks:

    station.ee_state ──> ee_state_sample (SampleHold) ──> pbp_controller, task_monitor,
                                                          obstacles
    goals (GoalsSource, the task's objects) ──> pbp_controller
    station.ee_state, task_monitor.target, pbp_controller.selected_goal ──> operator
    operator ──> pbp_controller (operator_command, operator_active), task_monitor
    pbp_controller.ee_command ──> station.ee_command (differential IK)
    obstacles.obstacle_positions ──> station;  station.in_collision ──> task_monitor

The station is the HSR's, an arm's or the HSR's over LCM (`_station`); the controller is
`make_pbp_controller`'s Diagram; a tick's order is `pbp_drake.systems.tick`'s. Loggers (the
`*_log` systems `pbp_drake.builder.run` reads back) record each tick; the task monitor ends
the simulation at success.
"""

import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from pbp_drake.builder.operators import make_hsr_operator, shown_intent_and_keys
from pbp_drake.builder.pbp_controller import TASK_PREDICTION_SAMPLES, make_pbp_controller
from pbp_drake.robots import ArmStationConfig, make_arm_station, make_hsr_station
from pbp_drake.robots.task_space_bridge import make_bridged_station
from pbp_drake.systems import GoalsSource, ReachSceneVisualizer, SampleHold, TaskMonitor
from pbp_drake.systems.tasks.moving_obstacles import MovingObstacles


def _station(resolved, meshcat):
    """(name, station): the arm's, the HSR's, or the HSR's through the task-space bridge
    (`robot.hardware.connect`; with `driver_sim` the simulated HSR on its far side)."""
    if isinstance(resolved.station, ArmStationConfig):
        station = make_arm_station(resolved.station, meshcat)
        return station.get_name(), station
    hardware = resolved.scenario.robot.hardware
    if hardware is None or not hardware.connect:
        return "hsr_station", make_hsr_station(resolved.station, meshcat)
    robot_side = make_hsr_station(resolved.station, meshcat) if hardware.driver_sim else None
    return "bridged_station", make_bridged_station(
        hardware, resolved.initial_ee_state, resolved.scenario.control_period, robot_side)


def build_reach_diagram(resolved, meshcat=None, hand_trail=False):
    """The Diagram of a resolved reaching or obstacle task (HSR or arm); with `meshcat`,
    drawn there too (with `hand_trail`, the hand's path as it grows)."""
    scenario = resolved.scenario
    period = scenario.control_period
    task = scenario.task
    scene = resolved.scene
    start = resolved.start
    builder = DiagramBuilder()

    station = builder.AddNamedSystem(*_station(resolved, meshcat))
    ee_state = station.GetOutputPort("ee_state")
    sample = builder.AddNamedSystem("ee_state_sample",
                                    SampleHold(period, resolved.initial_ee_state))
    builder.Connect(ee_state, sample.get_input_port())
    sampled = sample.get_output_port()

    monitor = builder.AddNamedSystem("task_monitor", TaskMonitor(
        scene.objects, scene.targets, scene.switch_schedule, start, task.success_distance,
        period))
    builder.Connect(sampled, monitor.get_ee_state_input_port())

    prediction_steps = TASK_PREDICTION_SAMPLES if meshcat is not None else 0
    # The selected goal's path and the next most probable goals'.
    path_count = min(1 + scenario.likely_paths, len(resolved.goals))
    controller = make_pbp_controller(resolved.controller, resolved.initial_ee_state,
                                     resolved.goals, prediction_steps, path_count)
    controller = builder.AddNamedSystem(controller.get_name(), controller)
    goals = builder.AddNamedSystem("goals", GoalsSource(resolved.goals))
    builder.Connect(goals.get_output_port(), controller.GetInputPort("goals"))
    builder.Connect(sampled, controller.GetInputPort("ee_state"))
    builder.Connect(controller.GetOutputPort("ee_command"), station.GetInputPort("ee_command"))

    obstacles = None
    if scene.obstacles is not None:
        obstacles = builder.AddNamedSystem("obstacles", MovingObstacles(
            scene.obstacles, start, task.obstacle_height, task.obstacle_speed, period))
        builder.Connect(sampled, obstacles.get_ee_state_input_port())
        builder.Connect(obstacles.get_obstacle_positions_output_port(),
                        station.GetInputPort("obstacle_positions"))
        builder.Connect(station.GetOutputPort("in_collision"),
                        monitor.get_in_collision_input_port())

    operator = builder.AddNamedSystem("operator", make_hsr_operator(resolved, meshcat))
    selected_goal, keys = shown_intent_and_keys(
        builder, scenario, controller.GetOutputPort("selected_goal"))
    for port_name, source in [("ee_state", ee_state),
                              ("target", monitor.get_target_output_port()),
                              ("selected_goal", selected_goal),
                              ("forward_key", keys),
                              ("obstacle_positions", obstacles and
                               obstacles.get_floor_positions_output_port())]:
        if operator.HasInputPort(port_name) and source is not None:
            builder.Connect(source, operator.GetInputPort(port_name))
    operator_active = operator.get_operator_active_output_port()
    operator_command = operator.get_operator_command_output_port()
    builder.Connect(operator_active, monitor.get_operator_active_input_port())
    if controller.HasInputPort("operator_active"):
        builder.Connect(operator_active, controller.GetInputPort("operator_active"))
    builder.Connect(operator_command, controller.GetInputPort("operator_command"))

    logged = [("ee_state_log", ee_state),
              ("operator_active_log", operator_active),
              ("operator_command_log", operator_command),
              ("command_log", controller.GetOutputPort("ee_command")),
              ("selected_goal_log", selected_goal),
              ("target_log", monitor.get_target_output_port())]
    for name in ("phase", "posterior_clipped"):
        if controller.HasOutputPort(name):
            logged.append((f"{name}_log", controller.GetOutputPort(name)))
    if obstacles is not None:
        logged.append(("in_collision_log", station.GetOutputPort("in_collision")))
    for name, port in logged:
        LogVectorOutput(port, builder, period).set_name(name)

    if meshcat is not None:
        # An arm's workspace is a fraction of the HSR's: the camera frames it.
        workspace = (np.vstack([resolved.station.base_pose[:3], scene.objects, start])
                     if isinstance(resolved.station, ArmStationConfig) else None)
        visualizer = builder.AddNamedSystem("task_visualizer", ReachSceneVisualizer(
            meshcat, scene.objects, prediction_steps, path_count, workspace=workspace,
            hand_trail=hand_trail))
        builder.Connect(monitor.get_target_output_port(), visualizer.get_target_input_port())
        builder.Connect(selected_goal, visualizer.get_selected_goal_input_port())
        builder.Connect(operator_active, visualizer.get_operator_active_input_port())
        builder.Connect(ee_state, visualizer.get_ee_state_input_port())
        if controller.HasOutputPort("predicted_paths"):
            builder.Connect(controller.GetOutputPort("predicted_paths"),
                            visualizer.get_predicted_paths_input_port())
        builder.Connect(controller.GetOutputPort("goal_probabilities"),
                        visualizer.get_goal_probabilities_input_port())

    diagram = builder.Build()
    diagram.set_name(scenario.name)
    return diagram

