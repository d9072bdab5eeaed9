"""The blending laws and the systems that carry them."""

import dataclasses

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.core.arbitration import BLEND_MODES, blend
from pbp_drake.scenarios import ScriptedCommands, load_scenario_file
from pbp_drake.simulation import simulate
from pbp_drake.systems import Blender, PointRobot


@pytest.mark.parametrize("mode", ["pbp_continuous", "pbp_alternated", "fixed_alpha"])
def test_blending_with_no_input_is_the_bare_policy(mode):
    rng = np.random.default_rng(0)
    for _ in range(10):
        robot, policy, policy_velocity = rng.normal(size=(3, 2))
        position, velocity = blend(mode, robot, policy, policy_velocity, np.zeros(2), False,
                                   0.01, alpha=0.3)
        np.testing.assert_array_equal(position, policy)
        np.testing.assert_array_equal(velocity, policy_velocity)


def test_pbp_with_a_silent_operator_runs_the_bare_dmp(repo):
    """Closed loop: an operator that never acts leaves PBP-Alt and PBP-Cont equal to the DMP
    alone (PBP-NoUser)."""
    scenario = load_scenario_file(repo / "diagrams/toy_alpha_study.yaml").scenario
    silent = ScriptedCommands(times=[0.0], commands=[[0.0, 0.0]])
    bare = simulate(dataclasses.replace(scenario, method="pbp_no_user")).positions
    for method in ("pbp_alternated", "pbp_continuous"):
        run = simulate(dataclasses.replace(scenario, method=method, operator=silent))
        np.testing.assert_array_equal(run.positions, bare)
        assert not run.operator_active.any()


def test_each_mode_moves_the_reference_as_documented():
    robot, policy, policy_velocity = np.zeros(2), np.array([1.0, 0.0]), np.array([2.0, 0.0])
    push = np.array([0.0, 1.0])
    dt = 0.1
    expected = {
        "pbp_continuous": ([1.0, 0.1], [2.0, 1.0]),
        "pbp_alternated": ([0.0, 0.1], [0.0, 1.0]),
        "fixed_alpha": ([0.25, 0.075], [0.5, 0.75]),
        "teleop": ([0.0, 0.1], [0.0, 1.0]),
    }
    for mode in BLEND_MODES:
        position, velocity = blend(mode, robot, policy, policy_velocity, push, True, dt, 0.25)
        np.testing.assert_allclose(position, expected[mode][0], err_msg=mode)
        np.testing.assert_allclose(velocity, expected[mode][1], err_msg=mode)


@pytest.mark.parametrize("alpha", [-0.1, 1.5, float("nan")])
def test_alpha_outside_unit_interval_is_refused(alpha):
    with pytest.raises(ValueError, match="alpha must lie in \\[0, 1\\]"):
        Blender("fixed_alpha", 2, 1, 0.01, alpha=alpha)


def test_unknown_blending_mode_is_refused():
    with pytest.raises(ValueError, match="'pbp_alternate' is unknown"):
        Blender("pbp_alternate", 2, 1, 0.01)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nan_or_infinite_operator_command_stops_the_simulation(bad):
    builder = DiagramBuilder()
    blender = builder.AddSystem(Blender("pbp_continuous", 2, 1, 0.01))
    robot = builder.AddSystem(PointRobot([0.0, 0.0]))
    for port, value in [(blender.get_references_input_port(), [1.0, 0.0, 0.0, 0.0]),
                        (blender.get_operator_command_input_port(), [bad, 0.0]),
                        (blender.get_operator_active_input_port(), [1.0])]:
        source = builder.AddSystem(ConstantVectorSource(value))
        builder.Connect(source.get_output_port(), port)
    builder.Connect(robot.get_state_output_port(), blender.get_robot_state_input_port())
    builder.Connect(blender.get_command_output_port(), robot.get_command_input_port())
    simulator = Simulator(builder.Build())
    with pytest.raises(ValueError, match="operator_command is NaN or infinite"):
        simulator.AdvanceTo(0.01)


def test_point_robot_settles_on_a_constant_reference():
    builder = DiagramBuilder()
    robot = builder.AddSystem(PointRobot([0.0, 0.0], time_step=0.001))
    source = builder.AddSystem(ConstantVectorSource([0.5, -0.2, 0.0, 0.0]))
    builder.Connect(source.get_output_port(), robot.get_command_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(1.0)
    state = robot.get_state_output_port().Eval(
        robot.GetMyContextFromRoot(simulator.get_context()))
    np.testing.assert_allclose(state, [0.5, -0.2, 0.0, 0.0], atol=1e-4)


def test_simulations_are_restartable_and_contexts_independent(repo):
    from pbp_drake.builder import build_diagram
    from pbp_drake.simulation import read_trajectory

    scenario = load_scenario_file(repo / "diagrams/toy_alpha_study.yaml").scenario
    diagram = build_diagram(scenario)
    runs = []
    for _ in range(2):
        simulator = Simulator(diagram)
        simulator.AdvanceTo(scenario.duration)
        runs.append(read_trajectory(diagram, simulator.get_context(), 100))
    np.testing.assert_array_equal(runs[0].positions, runs[1].positions)
    np.testing.assert_array_equal(runs[0].phase, runs[1].phase)
