"""`make_pbp_controller` built from dataclasses alone, on an arm of our own: no scenario,
no HSR. The PBP loop takes the hand to a goal, follows a goal that moves, lets a teleop
operator drive, and refuses a config that cannot work by its field (and a start or goals
of the wrong shape)."""

import dataclasses
import pathlib

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

from pbp_drake import (
    GoalEstimatorSettings, GoalsSource, HandOverSettings, IdleOperator, PbpControllerConfig,
    SampleHold, arm_initial_ee_state, make_arm_station, make_pbp_controller)
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.systems.ports import OperatorCommand

REPO = pathlib.Path(__file__).resolve().parents[2]
PERIOD = 0.03


def arm_config():
    robot = load_scenario_file(REPO / "diagrams" / "arm_reach.yaml").scenario.robot
    return dataclasses.replace(robot.station_config(), control_period=PERIOD)


def closed_loop(config, goals, operator=None):
    """The arm station, `config`'s controller and an operator (idle by default), wired as
    a user would; returns the diagram, the goals source and the hand's log."""
    station = make_arm_station(arm_config())
    start = arm_initial_ee_state(station)
    builder = DiagramBuilder()
    builder.AddNamedSystem("arm_station", station)
    controller = builder.AddNamedSystem("pbp_controller",
                                        make_pbp_controller(config, start, goals))
    sample = builder.AddNamedSystem("ee_state_sample", SampleHold(PERIOD, start))
    source = builder.AddNamedSystem("goals", GoalsSource(goals))
    operator = builder.AddNamedSystem("operator", operator or IdleOperator(
        OperatorCommand.size, PERIOD))
    builder.Connect(station.GetOutputPort("ee_state"), sample.get_input_port())
    builder.Connect(sample.get_output_port(), controller.GetInputPort("ee_state"))
    builder.Connect(source.get_output_port(), controller.GetInputPort("goals"))
    builder.Connect(operator.GetOutputPort("operator_command"),
                    controller.GetInputPort("operator_command"))
    if controller.HasInputPort("operator_active"):
        builder.Connect(operator.GetOutputPort("operator_active"),
                        controller.GetInputPort("operator_active"))
    builder.Connect(controller.GetOutputPort("ee_command"), station.GetInputPort("ee_command"))
    log = LogVectorOutput(station.GetOutputPort("ee_state"), builder, PERIOD)
    return builder.Build(), source, log, start


@pytest.mark.slow
def test_pbp_takes_the_hand_to_the_goal_the_estimator_picks():
    goals = np.array([[0.55, 0.15, 0.30], [0.55, -0.25, 0.45]])
    config = PbpControllerConfig(method="pbp_no_user", control_period=PERIOD)
    diagram, _, log, start = closed_loop(config, goals)
    simulator = Simulator(diagram)
    simulator.AdvanceTo(6.0)
    hands = log.FindLog(simulator.get_context()).data()
    # With the hand pointing along +x, the angle estimator picks the nearer direction.
    ends = np.linalg.norm(goals - hands[:3, -1], axis=1)
    assert ends.min() < 0.01
    speeds = np.linalg.norm(np.diff(hands[:3], axis=1), axis=0) / PERIOD
    assert speeds.max() <= config.hand_over.max_hand_speed + 0.01


@pytest.mark.slow
def test_a_goal_that_moves_on_the_goals_port_is_followed():
    goals = np.array([[0.55, 0.0, 0.35]])
    config = PbpControllerConfig(method="pbp_no_user", control_period=PERIOD,
                                 hand_over=HandOverSettings(max_hand_speed=0.25))
    diagram, source, log, _ = closed_loop(config, goals)
    simulator = Simulator(diagram)
    simulator.AdvanceTo(1.5)
    moved = np.array([[0.5, 0.2, 0.45]])
    source.set_goals(source.GetMyMutableContextFromRoot(simulator.get_mutable_context()), moved)
    simulator.AdvanceTo(8.0)
    hand = log.FindLog(simulator.get_context()).data()[:3, -1]
    assert np.linalg.norm(hand - moved[0]) < 0.01


@pytest.mark.slow
def test_teleop_moves_the_hand_at_the_operators_command():
    goals = np.array([[0.55, 0.0, 0.35]])
    config = PbpControllerConfig(method="teleop", control_period=PERIOD)
    command = ConstantVectorSource([0.0, 0.1, 0.0, 0.0])
    active = ConstantVectorSource([1.0])

    operator = _ConstantOperator(command, active)
    diagram, _, log, start = closed_loop(config, goals, operator.diagram)
    simulator = Simulator(diagram)
    simulator.AdvanceTo(2.0)
    hands = log.FindLog(simulator.get_context()).data()
    assert abs((hands[1, -1] - hands[1, -11]) / (10 * PERIOD) - 0.1) < 0.002
    assert abs(hands[0, -1] - start[0]) < 0.002


class _ConstantOperator:
    """An operator Diagram that holds one command and `operator_active`."""

    def __init__(self, command, active):
        builder = DiagramBuilder()
        builder.AddSystem(command)
        builder.AddSystem(active)
        builder.ExportOutput(command.get_output_port(), "operator_command")
        builder.ExportOutput(active.get_output_port(), "operator_active")
        self.diagram = builder.Build()


@pytest.mark.parametrize("change, message", [
    ({"method": "driving"}, "method 'driving' is unknown; choose one of pbp_alternated, "),
    ({"control_period": 0.0}, "control_period must be finite and positive"),
    ({"hand_over": HandOverSettings(max_hand_speed=-1.0)},
     "hand_over.max_hand_speed must be finite and positive"),
    ({"alpha": 2.0}, "alpha must lie in [0, 1]"),
    ({"dmp_duration": -1.0}, "dmp_duration must be finite and not negative (0: derived)"),
    ({"goal_estimator": GoalEstimatorSettings(method="pose")},
     "goal_estimator.method pose reads grasp orientations, which a position controller has"),
])
def test_a_config_that_cannot_work_names_its_field(change, message):
    config = dataclasses.replace(PbpControllerConfig(), **change)
    with pytest.raises(ValueError) as error:
        make_pbp_controller(config, np.zeros(8), [[0.5, 0.0, 0.3]])
    assert message in str(error.value)



@pytest.mark.parametrize("start, goals, message", [
    (np.zeros(7), [[0.5, 0.0, 0.3]],
     "initial_ee_state must be 8 finite numbers (an EeState), got [0.0, 0.0, 0.0, 0.0"),
    (np.full(8, np.nan), [[0.5, 0.0, 0.3]], "initial_ee_state must be 8 finite numbers"),
    (np.zeros(8), [[0.5, 0.0]], "goals must be a non-empty (K, 3) array, got shape (1, 2)"),
    (np.zeros(8), np.zeros((0, 3)), "goals must be a non-empty (K, 3) array, got shape (0, 3)"),
])
def test_a_start_or_goals_of_the_wrong_shape_are_refused(start, goals, message):
    with pytest.raises(ValueError) as error:
        make_pbp_controller(PbpControllerConfig(), start, goals)
    assert message in str(error.value)


@pytest.mark.parametrize("change, message", [
    ({"alpha": "half"}, "alpha must lie in [0, 1], got 'half'"),
    ({"dmp_duration": None}, "dmp_duration must be finite and not negative (0: derived), got None"),
    ({"dmp": None}, "dmp must be DmpSettings, got NoneType"),
    ({"goal_estimator": "angle"}, "goal_estimator must be GoalEstimatorSettings, got str"),
    ({"hop": None}, "hop must be HopSettings, got NoneType"),
    ({"hand_over": None}, "hand_over must be HandOverSettings, got NoneType"),
    ({"hand_over": HandOverSettings(max_heading_turn="wide")},
     "hand_over.max_heading_turn must be finite and positive (rad; .inf for no bound), got 'wide'"),
])
def test_a_field_of_the_wrong_type_is_named(change, message):
    config = dataclasses.replace(PbpControllerConfig(), **change)
    with pytest.raises(ValueError) as error:
        make_pbp_controller(config, np.zeros(8), [[0.5, 0.0, 0.3]])
    assert message in str(error.value)


@pytest.mark.parametrize("arguments, message", [
    ({"config": None}, "config must be PbpControllerConfig, got NoneType"),
    ({"goals": [[np.nan, 0.0, 0.3]]}, "goals 0 is [nan, 0.0, 0.3]: positions must be finite"),
    ({"goals": [[0.5, 0.0, 0.3], [np.inf, 0.0, 0.3]]}, "goals 1 is [inf, 0.0, 0.3]"),
    ({"goals": "0.5 0 0.3"}, "goals must be a non-empty (K, 3) array, got shape (0,)"),
    ({"initial_ee_state": "home"}, "initial_ee_state must be 8 finite numbers (an EeState), "
                                   "got 'home'"),
    ({"prediction_steps": None}, "prediction_steps must be a whole number >= 0, got None"),
    ({"prediction_steps": -1}, "prediction_steps must be a whole number >= 0, got -1"),
    ({"prediction_steps": 5, "predicted_goal_count": np.nan},
     "predicted_goal_count must be an integer >= 1, got nan"),
    ({"prediction_steps": 5, "predicted_goal_count": 1.5},
     "predicted_goal_count must be an integer >= 1, got 1.5"),
])
def test_a_bad_argument_of_the_controller_is_named(arguments, message):
    arguments = {"config": PbpControllerConfig(), "initial_ee_state": np.zeros(8),
                 "goals": [[0.5, 0.0, 0.3]], **arguments}
    with pytest.raises(ValueError) as error:
        make_pbp_controller(**arguments)
    assert message in str(error.value)
