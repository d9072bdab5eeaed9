"""The 2-D scenes' diagram: the paper's point robot under PBP or explicit arbitration.

    robot.state ──> robot_state_sample (ZeroOrderHold at the control period) ──> blender
    robot.state ──> operator ──> blender, dmp_bank (operator_active: PBP-Alt's phase lock)
    robot.state ──> dmp_bank (or demonstration_player for explicit arbitration) ──> blender
    goals ──> dmp_bank;  blender.command ──> robot.command

The order within a tick is `pbp_drake.systems.tick`'s (the robot steps half a plant step off
the ticks). Loggers named `robot_state_log`, `operator_active_log`, `operator_command_log`,
`command_log` and (PBP) `phase_log` record each tick.
"""

from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, ZeroOrderHold

from pbp_drake.builder.operators import make_operator
from pbp_drake.core.methods import METHODS
from pbp_drake.systems import Blender, DemonstrationPlayer, DmpBank, GoalsSource, PointRobotDynamics
from pbp_drake.systems.visualizers.point_scene_visualizer import PointSceneVisualizer


def build_point_robot_diagram(resolved, meshcat=None, prediction_steps=None):
    """The Diagram of a resolved 2-D scenario; with `meshcat`, also draws it there (the
    DMPs' paths `prediction_steps` ahead, as `build_diagram`'s)."""
    scenario = resolved.scenario
    period = scenario.control_period
    start, goals = resolved.start, resolved.goals
    goal_count, dimension = goals.shape
    builder = DiagramBuilder()

    robot = builder.AddNamedSystem("robot", PointRobotDynamics(start, scenario.robot))
    robot_state = robot.get_state_output_port()
    sample = builder.AddNamedSystem("robot_state_sample", ZeroOrderHold(period, 2 * dimension))
    builder.Connect(robot_state, sample.get_input_port())

    operator = builder.AddNamedSystem("operator", make_operator(scenario, dimension))
    if operator.num_input_ports():
        builder.Connect(robot_state, operator.get_input_port(0))
    operator_active = operator.get_operator_active_output_port()

    blender = builder.AddNamedSystem("blender", Blender(
        resolved.blend_mode, dimension, goal_count, period, scenario.alpha))
    dmp_bank = None
    method = METHODS[scenario.method]
    if method.plays_demonstration:
        times, positions = resolved.demonstration
        policy = builder.AddNamedSystem(
            "demonstration_player", DemonstrationPlayer(times, positions, period))
        prediction_steps = 0
    else:
        if prediction_steps is None:
            prediction_steps = 0 if meshcat is None else int(round(
                resolved.dmp_bank.duration / period))
        dmp_bank = policy = builder.AddNamedSystem("dmp_bank", DmpBank(
            resolved.dmp_bank, period,
            lock_phase_when_operator_acts=method.lock_phase,
            prediction_steps=prediction_steps))
        goals_source = builder.AddNamedSystem("goals", GoalsSource(goals))
        builder.Connect(goals_source.get_output_port(), dmp_bank.get_goals_input_port())
        builder.Connect(robot_state, dmp_bank.get_robot_state_input_port())
        builder.Connect(operator_active, dmp_bank.get_operator_active_input_port())

    builder.Connect(sample.get_output_port(), blender.get_robot_state_input_port())
    builder.Connect(policy.get_references_output_port(), blender.get_references_input_port())
    builder.Connect(operator.get_operator_command_output_port(),
                    blender.get_operator_command_input_port())
    builder.Connect(operator_active, blender.get_operator_active_input_port())
    builder.Connect(blender.get_command_output_port(), robot.get_command_input_port())

    for name, port in [("robot_state_log", robot_state),
                       ("operator_active_log", operator_active),
                       ("operator_command_log", operator.get_operator_command_output_port()),
                       ("command_log", blender.get_command_output_port())]:
        LogVectorOutput(port, builder, period).set_name(name)
    if dmp_bank is not None:
        LogVectorOutput(dmp_bank.get_phase_output_port(), builder, period).set_name("phase_log")

    if meshcat is not None:
        demonstration = None if resolved.demonstration is None else resolved.demonstration[1]
        visualizer = builder.AddNamedSystem("visualizer", PointSceneVisualizer(
            meshcat, start, goals, scenario.obstacles, demonstration, prediction_steps))
        builder.Connect(robot_state, visualizer.get_robot_state_input_port())
        builder.Connect(operator_active, visualizer.get_operator_active_input_port())
        if prediction_steps:
            builder.Connect(dmp_bank.get_predicted_paths_output_port(),
                            visualizer.get_predicted_paths_input_port())

    diagram = builder.Build()
    diagram.set_name(scenario.name)
    return diagram
