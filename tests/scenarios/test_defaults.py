"""One default per knob: a system built from a scenario file that leaves a section out has
the same parameters as the same system constructed in Python with its defaults."""

import dataclasses

import numpy as np
import pytest
from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed

from pbp_drake.builder import build_diagram, find_system
from pbp_drake.core.dmp import DmpSettings
from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.robots import HsrStationConfig
from pbp_drake.scenarios import PointScenario, TaskScenario, resolve
from pbp_drake.systems import (
    GamepadOperator, GoalEstimator, KeyboardOperator, ObstacleRepulsionOperator,
    PointRobotDynamics, VirtualOperator)

PERIOD = 0.03
HSR = "robot: !Hsr {}\ntask: {}\ncontrol_period: 0.03\n"
TOY = "start: [0.0, 0.0]\ngoals: [[1.0, 0.0]]\ndmp_duration: 1.0\n"


def built(yaml_text, meshcat=None):
    """The diagram and resolved scenario of a scenario written in YAML (a robot task's when
    it starts with `HSR`)."""
    schema = TaskScenario if yaml_text.startswith(HSR) else PointScenario
    resolved = resolve(yaml_load_typed(schema=schema, data=yaml_text))
    return build_diagram(resolved, meshcat), resolved


def params_of(system):
    """A system's parameters as plain data (the YAML tag classes add no field)."""
    return dataclasses.asdict(system.params)


def test_virtual_participant_defaults_match(meshcat):
    diagram, resolved = built(HSR + "operator: !VirtualParticipant {}\n")
    from_yaml = diagram.GetSubsystemByName("operator")
    in_python = VirtualOperator(PERIOD, resolved.goals, nominal_speed=0.12)
    assert params_of(from_yaml) == params_of(in_python)


@pytest.mark.parametrize("tag, system", [("Keyboard", KeyboardOperator),
                                         ("Gamepad", GamepadOperator)])
def test_browser_operator_defaults_match(meshcat, tag, system):
    diagram, _ = built(HSR + f"operator: !{tag} {{}}\nmethod: teleop\n", meshcat)
    from_yaml = diagram.GetSubsystemByName("operator")
    in_python = system(meshcat, PERIOD, allow_forward=True, nominal_speed=0.12)
    assert params_of(from_yaml) == params_of(in_python)


def test_goal_estimator_and_dmp_defaults_match():
    diagram, resolved = built(HSR)
    estimator = find_system(diagram, "goal_estimator")
    assert estimator.settings == GoalEstimator(2, GoalEstimatorSettings(), PERIOD).settings
    assert find_system(diagram, "dmp_bank").bank.settings == DmpSettings()


def test_point_robot_and_repulsion_defaults_match():
    diagram, _ = built(TOY + "obstacles: [{center: [0.5, 0.0]}]\n"
                       "operator: !ObstacleRepulsion {}\n")
    robot = diagram.GetSubsystemByName("robot")
    assert params_of(robot) == params_of(PointRobotDynamics(np.zeros(2)))
    operator = diagram.GetSubsystemByName("operator")
    in_python = ObstacleRepulsionOperator([[0.5, 0.0]], [0.1], 2, 0.01)
    assert params_of(operator) == params_of(in_python)


def test_changed_yaml_value_reaches_the_system():
    diagram, _ = built(HSR + "operator: !VirtualParticipant {rotation_speed: 0.5}\n"
                       "goal_estimator: {temperature: 0.3}\n")
    assert diagram.GetSubsystemByName("operator").params.rotation_speed == 0.5
    assert find_system(diagram, "goal_estimator").settings.temperature == 0.3


def test_hsr_station_defaults_match():
    _, resolved = built(HSR)
    # The task sets the hand's start height, the loop's period and the obstacles.
    derived = {"ee_height": 0.7, "control_period": PERIOD, "obstacles": []}
    in_python = dataclasses.replace(HsrStationConfig(), **derived)
    assert yaml_dump_typed(resolved.station) == yaml_dump_typed(in_python)
