"""The controller of the shared-autonomy baselines (``hop``, ``policy_blending``) in the
position tasks, as one Diagram with the PBP controller's ports: HOP's goal posterior and its
assistance between the hand's sampled state and the station's command. No DMP bank.

    ee_state (sampled) ──> ee_state_split ──[p, v]──> assistance (robot_state)
                       └─> goal_estimator (MaxEntGoalEstimator) ──> assistance
                                                                    (goal_probabilities)
    goals ──> goal_estimator, assistance
    operator_command [vx, vy, vz, yaw_rate] ──> goal_estimator
                                            └─> operator_command_split ──> assistance (v)
                                                                       └─> heading_command
    assistance.command [p, v] ──> hand_over (the hand-over law, as PBP's)
    hand_over.command + heading_command.heading ──> ee_command (the station's input)

The operator's yaw rate turns the hand as under PBP (`HeadingCommand`); HOP assists the
position only, since the reaching tasks' goals are positions.
"""

from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import Demultiplexer

from pbp_drake.builder.pbp_controller import add_hand_over
from pbp_drake.systems import GoalsSource, HeadingCommand, HopAssistance, MaxEntGoalEstimator
from pbp_drake.systems.ports import EeState, OperatorCommand


def make_hop_controller(resolved):
    """The controller of a resolved HSR scenario whose method is ``hop`` or
    ``policy_blending``, a Diagram named `hop_controller`.

    .. pydrake_system::

        name: hop_controller
        input_ports:
        - ee_state
        - operator_command
        output_ports:
        - ee_command
        - selected_goal
        - goal_probabilities
        - posterior_clipped

    `selected_goal` is the most probable goal (no hysteresis: policy blending assists
    toward it), `goal_probabilities` the belief and `posterior_clipped` whether its last
    update was clipped; all three named as the PBP controller's, so the loggers, the task
    monitor, the virtual participant and the scene's drawing read them unchanged.
    """
    scenario = resolved.scenario
    period = scenario.control_period
    goals = resolved.goals
    goal_count = len(goals)
    builder = DiagramBuilder()

    split = builder.AddNamedSystem("ee_state_split", Demultiplexer([6, EeState.size - 6]))
    builder.ExportInput(split.get_input_port(), "ee_state")
    goals_source = builder.AddNamedSystem("goals", GoalsSource(goals))

    posterior = builder.AddNamedSystem("goal_estimator", MaxEntGoalEstimator(
        goal_count, scenario.hop, period))
    builder.ConnectInput("ee_state", posterior.get_ee_state_input_port())
    builder.Connect(goals_source.get_output_port(), posterior.get_goals_input_port())
    builder.ExportInput(posterior.get_operator_command_input_port(), "operator_command")

    command_split = builder.AddNamedSystem("operator_command_split", Demultiplexer(
        [3, OperatorCommand.size - 3]))
    builder.ConnectInput("operator_command", command_split.get_input_port())
    heading = builder.AddNamedSystem("heading_command", HeadingCommand(
        EeState(resolved.initial_ee_state).heading, period,
        scenario.robot.max_hand_yaw_acceleration))
    builder.ConnectInput("operator_command", heading.get_operator_command_input_port())

    assistance = builder.AddNamedSystem("assistance", HopAssistance(
        scenario.method, goal_count, scenario.hop, period))
    builder.Connect(split.get_output_port(0), assistance.get_robot_state_input_port())
    builder.Connect(goals_source.get_output_port(), assistance.get_goals_input_port())
    builder.Connect(command_split.get_output_port(0),
                    assistance.get_operator_command_input_port())
    builder.Connect(posterior.get_goal_probabilities_output_port(),
                    assistance.get_goal_probabilities_input_port())

    add_hand_over(builder, resolved, assistance.get_command_output_port(), heading)
    builder.ExportOutput(posterior.get_selected_goal_output_port(), "selected_goal")
    builder.ExportOutput(posterior.get_goal_probabilities_output_port(), "goal_probabilities")
    builder.ExportOutput(posterior.get_posterior_clipped_output_port(), "posterior_clipped")
    diagram = builder.Build()
    diagram.set_name("hop_controller")
    return diagram
