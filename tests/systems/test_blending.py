"""The blending laws and the systems that carry them."""

import dataclasses

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.core.arbitration import (
    BLEND_MODES, blend, confidence_alpha, goal_confidence, validate_mode)
from pbp_drake.scenarios import ScriptedCommands, load_scenario_file
from pbp_drake.builder.run import simulate
from pbp_drake.systems import Blender, PointRobotDynamics
from pbp_drake.systems.tasks.point_robot_dynamics import PointRobotParams


@pytest.mark.parametrize("mode", ["pbp_continuous", "pbp_alternated", "fixed_alpha",
                                  "confidence_alpha"])
def test_blending_with_no_input_is_the_bare_policy(mode):
    rng = np.random.default_rng(0)
    for _ in range(10):
        robot, policy, policy_velocity = rng.normal(size=(3, 2))
        position, velocity = blend(mode, robot, policy, policy_velocity, np.zeros(2), False,
                                   0.01, alpha=0.3)
        np.testing.assert_array_equal(position, policy)
        np.testing.assert_array_equal(velocity, policy_velocity)


@pytest.mark.slow
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
        "confidence_alpha": ([0.25, 0.075], [0.5, 0.75]),
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
    robot = builder.AddSystem(PointRobotDynamics([0.0, 0.0]))
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
    robot = builder.AddSystem(PointRobotDynamics([0.0, 0.0], PointRobotParams(time_step=0.001)))
    source = builder.AddSystem(ConstantVectorSource([0.5, -0.2, 0.0, 0.0]))
    builder.Connect(source.get_output_port(), robot.get_command_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(1.0)
    state = robot.get_state_output_port().Eval(
        robot.GetMyContextFromRoot(simulator.get_context()))
    np.testing.assert_allclose(state, [0.5, -0.2, 0.0, 0.0], atol=1e-4)


@pytest.mark.parametrize("field, value, message", [
    ("mass", 0.0, "robot.mass must be positive, got 0.0"),
    ("time_step", np.inf, "robot.time_step must be positive, got inf"),
    ("damping", -1.0, "robot.damping must be non-negative, got -1.0"),
])
def test_a_point_robot_that_cannot_move_is_refused_by_field(field, value, message):
    with pytest.raises(ValueError, match=message):
        PointRobotDynamics([0.0, 0.0], PointRobotParams(**{field: value}))


@pytest.mark.slow
def test_simulations_are_restartable_and_contexts_independent(repo):
    from pbp_drake.builder import build_diagram
    from pbp_drake.builder.run import read_trajectory

    scenario = load_scenario_file(repo / "diagrams/toy_alpha_study.yaml").scenario
    diagram = build_diagram(scenario)
    runs = []
    for _ in range(2):
        simulator = Simulator(diagram)
        simulator.AdvanceTo(scenario.duration)
        runs.append(read_trajectory(diagram, simulator.get_context(), 100))
    np.testing.assert_array_equal(runs[0].positions, runs[1].positions)
    np.testing.assert_array_equal(runs[0].phase, runs[1].phase)


# --- confidence_alpha (Dragan & Srinivasa 2013; Jain-style margin confidence) -------------


def test_confidence_alpha_is_a_known_mode():
    assert "confidence_alpha" in BLEND_MODES
    validate_mode("confidence_alpha")
    Blender("confidence_alpha", 2, 3, 0.01)


@pytest.mark.parametrize("k", [2, 3, 5])
def test_uniform_probabilities_give_no_assistance(k):
    for selected in range(k):
        assert goal_confidence(np.full(k, 1.0 / k), selected) == 0.0
        assert confidence_alpha(np.full(k, 1.0 / k), selected) == 0.0


@pytest.mark.parametrize("alpha_max", [0.3, 1.0])
def test_one_hot_on_the_selected_goal_gives_alpha_max(alpha_max):
    one_hot = np.array([0.0, 0.0, 1.0, 0.0])
    assert goal_confidence(one_hot, 2) == 1.0
    assert confidence_alpha(one_hot, 2, alpha_max=alpha_max) == pytest.approx(alpha_max)
    # Certain of another goal than the selected one: no assistance.
    assert confidence_alpha(one_hot, 0, alpha_max=alpha_max) == 0.0


def test_a_single_goal_is_certain():
    assert goal_confidence([1.0], 0) == 1.0
    assert confidence_alpha([0.7], 0, alpha_max=0.8) == pytest.approx(0.8)


def test_confidence_is_the_margin_over_the_runner_up():
    assert goal_confidence([0.5, 0.3, 0.2], 0) == pytest.approx(0.2)
    # A tie between the selected goal and another is no confidence, whatever the rest.
    assert goal_confidence([0.5, 0.5, 0.0], 0) == 0.0
    # Unnormalised likelihoods are normalised first.
    assert goal_confidence([5.0, 3.0, 2.0], 0) == pytest.approx(0.2)


def test_confidence_alpha_is_the_linear_ramp():
    # Two goals, p = [q, 1 - q]: confidence of goal 0 is 2 q - 1.
    def alpha(q, low, high, alpha_max=1.0):
        return confidence_alpha([q, 1.0 - q], 0, low, high, alpha_max)

    assert alpha(0.75, 0.0, 1.0) == pytest.approx(0.5)
    assert alpha(0.75, 0.0, 1.0, 0.5) == pytest.approx(0.25)
    assert alpha(0.6, 0.4, 0.8) == 0.0               # confidence 0.2, below low
    assert alpha(0.8, 0.4, 0.8) == pytest.approx(0.5)  # confidence 0.6, half-way
    assert alpha(0.95, 0.4, 0.8) == pytest.approx(1.0)  # confidence 0.9, above high


@pytest.mark.parametrize("ramp", [(0.0, 1.0, 1.0), (0.2, 0.6, 0.7)])
def test_confidence_alpha_is_monotone_in_the_confidence(ramp):
    rng = np.random.default_rng(1)
    alphas, confidences = [], []
    for _ in range(200):
        probabilities = rng.dirichlet(np.ones(4))
        selected = int(np.argmax(probabilities))
        confidences.append(goal_confidence(probabilities, selected))
        alphas.append(confidence_alpha(probabilities, selected, *ramp))
    order = np.argsort(confidences)
    assert np.all(np.diff(np.asarray(alphas)[order]) >= 0.0)
    assert min(alphas) >= 0.0 and max(alphas) <= ramp[2]


@pytest.mark.parametrize("kwargs, name", [
    (dict(confidence_range=(-0.1, 1.0)), "confidence_low"),
    (dict(confidence_range=(0.0, 1.5)), "confidence_high"),
    (dict(confidence_range=(0.6, 0.6)), "confidence_low must be below confidence_high"),
    (dict(confidence_range=(0.8, 0.2)), "confidence_low must be below confidence_high"),
    (dict(confidence_range=(float("nan"), 1.0)), "confidence_low"),
    (dict(confidence_range=0.5), "confidence_range"),
    (dict(alpha_max=0.0), "alpha_max"),
    (dict(alpha_max=1.2), "alpha_max"),
    (dict(alpha_max=float("nan")), "alpha_max"),
])
def test_bad_confidence_ramp_is_refused(kwargs, name):
    with pytest.raises(ValueError, match=name):
        Blender("confidence_alpha", 2, 2, 0.01, **kwargs)
    if "confidence_range" in kwargs and np.ndim(kwargs["confidence_range"]) == 1:
        low, high = kwargs["confidence_range"]
        with pytest.raises(ValueError, match=name):
            confidence_alpha([0.5, 0.5], 0, low, high)
    if "alpha_max" in kwargs:
        with pytest.raises(ValueError, match=name):
            confidence_alpha([0.5, 0.5], 0, alpha_max=kwargs["alpha_max"])


@pytest.mark.parametrize("probabilities, selected, message", [
    ([0.5, -0.1, 0.6], 0, "non-negative"),
    ([0.5, np.nan, 0.5], 0, "finite"),
    ([0.0, 0.0], 0, "sum"),
    ([0.5, 0.5], 2, "not one of the 2 goals"),
    ([], 0, "goal_probabilities is empty"),
])
def test_bad_goal_probabilities_are_refused(probabilities, selected, message):
    with pytest.raises(ValueError, match=message):
        confidence_alpha(probabilities, selected)


def test_confidence_alpha_blend_needs_an_alpha():
    with pytest.raises(ValueError, match="alpha must lie in \\[0, 1\\] for confidence_alpha"):
        blend("confidence_alpha", np.zeros(2), np.ones(2), np.ones(2), np.ones(2), True, 0.1)


def _confidence_blender_output(probabilities, selected, active, *, connect_probabilities=True,
                               **kwargs):
    """A Blender in confidence_alpha mode with fixed inputs: robot at (0.2, -0.1), three
    goals' references, the operator pushing (0, 1) m/s; returns the evaluated command."""
    builder = DiagramBuilder()
    blender = builder.AddSystem(Blender("confidence_alpha", 2, 3, 0.1, **kwargs))
    references = np.array([[[1.0, 0.0], [0.0, 2.0], [-1.0, -1.0]],      # next positions
                           [[2.0, 0.0], [0.0, 3.0], [0.5, 0.5]]])       # next velocities
    inputs = [(blender.get_robot_state_input_port(), [0.2, -0.1, 0.0, 0.0]),
              (blender.get_references_input_port(), references.reshape(-1)),
              (blender.get_selected_goal_input_port(), [float(selected)]),
              (blender.get_operator_command_input_port(), [0.0, 1.0]),
              (blender.get_operator_active_input_port(), [1.0 if active else 0.0])]
    if connect_probabilities:
        inputs.append((blender.get_goal_probabilities_input_port(), probabilities))
    for port, value in inputs:
        source = builder.AddSystem(ConstantVectorSource(np.asarray(value, dtype=float)))
        builder.Connect(source.get_output_port(), port)
    builder.ExportOutput(blender.get_command_output_port(), "command")
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    blender_context = blender.GetMyContextFromRoot(context)
    command = diagram.get_output_port().Eval(context)
    alpha = blender.alpha(blender_context) if connect_probabilities else None
    return command, references[:, selected], alpha


@pytest.mark.parametrize("probabilities, selected, kwargs, expected_alpha", [
    ([0.6, 0.3, 0.1], 0, {}, 0.3),
    ([0.1, 0.7, 0.2], 1, {}, 0.5),
    ([0.1, 0.7, 0.2], 1, dict(confidence_range=(0.25, 0.75), alpha_max=0.8), 0.4),
    ([1 / 3, 1 / 3, 1 / 3], 2, {}, 0.0),
    ([0.0, 0.0, 1.0], 2, dict(alpha_max=0.9), 0.9),
])
def test_blender_confidence_alpha_blends_operator_and_policy(probabilities, selected, kwargs,
                                                             expected_alpha):
    command, (policy_position, policy_velocity), alpha = _confidence_blender_output(
        probabilities, selected, True, **kwargs)
    assert alpha == pytest.approx(expected_alpha)
    u, dt = np.array([0.0, 1.0]), 0.1
    operator_position = np.array([0.2, -0.1]) + u * dt
    np.testing.assert_allclose(
        command[:2], (1 - expected_alpha) * operator_position + expected_alpha * policy_position)
    np.testing.assert_allclose(
        command[2:], (1 - expected_alpha) * u + expected_alpha * policy_velocity)


def test_blender_confidence_alpha_with_an_idle_operator_plays_the_policy():
    for probabilities in ([0.6, 0.3, 0.1], [1 / 3, 1 / 3, 1 / 3]):
        command, (policy_position, policy_velocity), _ = _confidence_blender_output(
            probabilities, 0, False)
        np.testing.assert_array_equal(command, np.concatenate([policy_position,
                                                               policy_velocity]))


def test_blender_confidence_alpha_without_goal_probabilities_is_refused():
    with pytest.raises(RuntimeError, match="confidence_alpha mode needs its "
                                           "goal_probabilities input port connected"):
        _confidence_blender_output(None, 0, True, connect_probabilities=False)


def test_other_modes_ignore_the_goal_probabilities_port():
    builder = DiagramBuilder()
    blender = builder.AddSystem(Blender("fixed_alpha", 2, 1, 0.1, alpha=0.25))
    for port, value in [(blender.get_robot_state_input_port(), [0.0, 0.0, 0.0, 0.0]),
                        (blender.get_references_input_port(), [1.0, 0.0, 2.0, 0.0]),
                        (blender.get_operator_command_input_port(), [0.0, 1.0]),
                        (blender.get_operator_active_input_port(), [1.0])]:
        source = builder.AddSystem(ConstantVectorSource(value))
        builder.Connect(source.get_output_port(), port)
    builder.ExportOutput(blender.get_command_output_port(), "command")
    diagram = builder.Build()
    np.testing.assert_allclose(diagram.get_output_port().Eval(diagram.CreateDefaultContext()),
                               [0.25, 0.075, 0.5, 0.75])


def test_fixed_alpha_is_a_context_parameter_set_live():
    blender = Blender("fixed_alpha", 2, 1, 0.1, alpha=0.3)
    context, other = blender.CreateDefaultContext(), blender.CreateDefaultContext()
    blender.set_alpha(context, 0.8)
    assert blender.alpha(context) == 0.8 and blender.alpha(other) == 0.3
    for bad in (-0.1, 1.5, float("nan")):
        with pytest.raises(ValueError, match="alpha must lie in"):
            blender.set_alpha(context, bad)
    with pytest.raises(ValueError, match="this blender is teleop"):
        Blender("teleop", 2, 1, 0.1).set_alpha(context, 0.5)
