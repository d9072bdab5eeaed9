"""The goal estimators, their hysteresis, and the GoalEstimator system."""

import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.core.goal_estimation import (
    GOAL_ESTIMATION_METHODS, GoalEstimatorSettings, SelectionMemory, estimate,
    goal_probabilities, update_selection)
from pbp_drake.core.reach_task import heading_error
from pbp_drake.systems.pbp.goal_estimator import GoalEstimator

START = np.array([0.0, 0.0, 0.7])
# Left, ahead and right of the end effector at START, which points along +x.
GOALS = np.array([[2.0, 1.5, 0.7], [2.0, 0.0, 0.7], [2.0, -1.5, 0.7]])


def toward(goal, position=START):
    return math.atan2(goal[1] - position[1], goal[0] - position[0])


def run_headings(settings, headings, goals=GOALS, position=START):
    """Selections of successive updates at `headings`, starting with no memory."""
    memory, selections = None, []
    for heading in headings:
        selected, probabilities, memory = estimate(settings, goals, position, heading, memory)
        selections.append(selected)
    return selections


def switch_count(selections):
    return int(np.count_nonzero(np.diff(selections)))


def test_angle_picks_the_goal_in_the_pointing_direction():
    settings = GoalEstimatorSettings(method="angle")
    for index, goal in enumerate(GOALS):
        selected, probabilities, memory = estimate(settings, GOALS, START, toward(goal))
        assert selected == index == memory.selected
        assert np.argmax(probabilities) == index
        assert probabilities.sum() == pytest.approx(1.0, abs=1e-12)


def test_angle_wraps_around_pi():
    """A goal behind is found whether the heading is written as pi or -pi."""
    goals = np.array([[-2.0, 0.01, 0.7], [2.0, 0.0, 0.7]])
    settings = GoalEstimatorSettings(method="angle")
    for heading in (math.pi, -math.pi, 3 * math.pi):
        assert estimate(settings, goals, START, heading).selected == 0


def test_turning_switches_only_after_hold_steps():
    settings = GoalEstimatorSettings(method="angle", margin=0.1, hold_steps=3)
    left, right = toward(GOALS[0]), toward(GOALS[2])
    # Point at the left goal, then turn at once to the right goal and stay.
    selections = run_headings(settings, [left] * 5 + [right] * 6)
    assert selections == [0] * 5 + [0, 0, 2, 2, 2, 2]
    # A slow sweep from left to right switches once per goal passed, never back.
    sweep = run_headings(settings, np.linspace(left, right, 60).tolist() + [right] * 5)
    assert sweep[0] == 0 and sweep[-1] == 2
    assert np.all(np.diff(sweep) >= 0)
    assert switch_count(sweep) == 2


def test_a_heading_halfway_with_noise_does_not_chatter():
    goals = GOALS[[0, 2]]
    halfway = 0.5 * (toward(goals[0]) + toward(goals[1]))
    rng = np.random.default_rng(3)
    headings = halfway + rng.uniform(-0.01, 0.01, 400)
    sticky = run_headings(GoalEstimatorSettings(margin=0.1, hold_steps=2), headings, goals)
    assert switch_count(sticky) == 0
    # Without hysteresis the same headings chatter: the test has teeth.
    jumpy = run_headings(GoalEstimatorSettings(margin=0.0, hold_steps=1), headings, goals)
    assert switch_count(jumpy) > 50


def test_hysteresis_count_resets_when_the_challenge_stops():
    memory = SelectionMemory(0)
    challenged = np.array([0.2, 0.8])
    memory = update_selection(challenged, memory, margin=0.1, hold_steps=2)
    assert memory == SelectionMemory(0, 1, 1)
    memory = update_selection(np.array([0.5, 0.5]), memory, margin=0.1, hold_steps=2)
    assert memory == SelectionMemory(0)
    memory = update_selection(challenged, memory, margin=0.1, hold_steps=2)
    memory = update_selection(challenged, memory, margin=0.1, hold_steps=2)
    assert memory == SelectionMemory(1)


def test_bayesian_moving_toward_a_goal_makes_it_most_probable():
    settings = GoalEstimatorSettings(method="bayesian", beta=3.0)
    goals = np.array([[2.0, 1.0, 0.7], [2.0, -1.0, 0.7], [-1.0, 0.0, 0.7]])
    target = 1
    direction = (goals[target] - START) / np.linalg.norm(goals[target] - START)
    position, path_length, memory, previous = START.copy(), 0.0, None, 0.0
    for _ in range(15):
        step = 0.1 * direction
        position, path_length = position + step, path_length + np.linalg.norm(step)
        selected, probabilities, memory = estimate(
            settings, goals, position, heading=0.0, memory=memory, start=START,
            path_length=path_length)
        assert probabilities.sum() == pytest.approx(1.0, abs=1e-12)
        assert selected == target == np.argmax(probabilities)
        assert probabilities[target] > previous
        previous = probabilities[target]
    assert previous > 0.95


def test_bayesian_is_safe_for_large_beta():
    settings = GoalEstimatorSettings(method="bayesian", beta=1e6)
    goals = np.array([[2.0, 1.0, 0.7], [2.0, -1.0, 0.7]])
    probabilities = goal_probabilities(settings, goals, START + [0.1, -0.05, 0.0], 0.0,
                                       start=START, path_length=1e3)
    assert np.isfinite(probabilities).all()
    np.testing.assert_array_equal(probabilities, [0.0, 1.0])


def test_bayesian_at_the_start_is_uniform():
    settings = GoalEstimatorSettings(method="bayesian")
    probabilities = goal_probabilities(settings, GOALS, START, 0.0, start=START)
    np.testing.assert_allclose(probabilities, np.full(3, 1 / 3), atol=1e-15)


def test_nearest_picks_the_nearest_goal():
    rng = np.random.default_rng(1)
    settings = GoalEstimatorSettings(method="nearest", temperature=0.05)
    for _ in range(20):
        goals = rng.uniform(-2.0, 2.0, (8, 3))
        position = rng.uniform(-2.0, 2.0, 3)
        selected, probabilities, _ = estimate(settings, goals, position, heading=0.0)
        assert selected == np.argmin(np.linalg.norm(goals - position, axis=1))
        assert probabilities.sum() == pytest.approx(1.0, abs=1e-12)


def loop_probabilities(settings, goals, position, heading, start, path_length):
    """The estimators one goal at a time in plain Python (the reference)."""
    costs = []
    for goal in goals:
        if settings.method == "angle":
            costs.append(abs(heading_error(heading, position, goal)) / settings.temperature)
        elif settings.method == "nearest":
            costs.append(math.dist(goal, position) / settings.temperature)
        else:
            costs.append(settings.beta * (path_length + math.dist(position, goal)
                                          - math.dist(start, goal)))
    lowest = min(costs)
    weights = [math.exp(-(cost - lowest)) for cost in costs]
    total = sum(weights)
    return np.array([weight / total for weight in weights])


@pytest.mark.slow
@pytest.mark.parametrize("method", GOAL_ESTIMATION_METHODS)
def test_vectorised_equals_a_loop_over_ten_thousand_goals(method):
    rng = np.random.default_rng(2)
    goals = rng.uniform([-3.0, -3.0, 0.2], [3.0, 3.0, 1.0], (10_000, 3))
    position, start = np.array([0.3, -0.2, 0.7]), START
    settings = GoalEstimatorSettings(method=method, temperature=0.3, beta=2.0)
    vectorised = goal_probabilities(settings, goals, position, 0.4, start=start,
                                    path_length=0.5)
    looped = loop_probabilities(settings, goals, position, 0.4, start, 0.5)
    np.testing.assert_allclose(vectorised, looped, rtol=0.0, atol=1e-12)
    assert estimate(settings, goals, position, 0.4, start=start,
                    path_length=0.5).selected == int(np.argmax(looped))


@pytest.mark.parametrize("field, value, message", [
    ("method", "closest", "unknown; choose one of angle, nearest, bayesian, pose, "
                          "maxent_command, intent_filter"),
    ("temperature", 0.0, "temperature must be a positive"),
    ("temperature", -1.0, "temperature must be a positive"),
    ("temperature", float("nan"), "temperature must be a positive"),
    ("beta", 0.0, "beta must be a positive"),
    ("beta", float("inf"), "beta must be a positive"),
    ("margin", -0.1, "margin must lie in"),
    ("hold_steps", 0, "hold_steps must be an integer"),
    ("hold_steps", 1.5, "hold_steps must be an integer"),
    ("intent_filter", {}, "intent_filter must be an IntentFilterSettings, got dict"),
])
def test_bad_settings_name_the_field(field, value, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        GoalEstimatorSettings(**{field: value})


@pytest.mark.parametrize("goals, message", [
    (np.empty((0, 3)), "goals must be"),
    (np.zeros((2, 2)), "goals must be"),
    (np.array([[1.0, np.nan, 0.7]]), "goal 0 is .*must be finite"),
    (np.array([[1.0, 0.0, 0.7], [1e200, 0.0, 0.7]]), "goal 1 is .*within"),
])
def test_bad_goals_are_refused(goals, message):
    with pytest.raises(ValueError, match=message):
        estimate(GoalEstimatorSettings(), goals, START, 0.0)


def test_bad_positions_and_missing_start_are_refused():
    with pytest.raises(ValueError, match="position is NaN"):
        estimate(GoalEstimatorSettings(), GOALS, [np.nan, 0.0, 0.0], 0.0)
    with pytest.raises(ValueError, match="heading must be a finite"):
        estimate(GoalEstimatorSettings(), GOALS, START, np.inf)
    with pytest.raises(ValueError, match="needs start"):
        estimate(GoalEstimatorSettings(method="bayesian"), GOALS, START, 0.0)
    with pytest.raises(ValueError, match="path_length must be >= 0"):
        estimate(GoalEstimatorSettings(method="bayesian"), GOALS, START, 0.0, start=START,
                 path_length=-1.0)


def test_system_refuses_bad_arguments():
    with pytest.raises(ValueError, match="goal_count"):
        GoalEstimator(0, GoalEstimatorSettings(), 0.1)
    with pytest.raises(ValueError, match="control_period"):
        GoalEstimator(3, GoalEstimatorSettings(), 0.0)
    with pytest.raises(ValueError, match="settings"):
        GoalEstimator(3, "angle", 0.1)


def ee_state(position, heading):
    return np.concatenate([position, np.zeros(3), [heading, 0.0]])


def build_estimator(settings, goals, position, heading, period=0.1):
    builder = DiagramBuilder()
    ee = builder.AddSystem(ConstantVectorSource(ee_state(position, heading)))
    goal_source = builder.AddSystem(ConstantVectorSource(goals.reshape(-1)))
    estimator = builder.AddSystem(GoalEstimator(len(goals), settings, period))
    builder.Connect(ee.get_output_port(), estimator.get_ee_state_input_port())
    builder.Connect(goal_source.get_output_port(), estimator.get_goals_input_port())
    simulator = Simulator(builder.Build())
    return simulator, ee, estimator


def test_system_selects_at_once_then_switches_after_hold_steps():
    settings = GoalEstimatorSettings(method="angle", margin=0.1, hold_steps=2)
    simulator, ee, estimator = build_estimator(settings, GOALS, START, toward(GOALS[1]))
    root = simulator.get_mutable_context()
    context = estimator.GetMyContextFromRoot(root)
    selected = estimator.get_selected_goal_output_port()
    probabilities = estimator.get_goal_probabilities_output_port()
    simulator.Initialize()
    # Selected at initialisation, without waiting for hysteresis.
    assert selected.Eval(context)[0] == 1.0
    expected = estimate(settings, GOALS, START, toward(GOALS[1]))
    np.testing.assert_allclose(probabilities.Eval(context), expected.probabilities,
                               atol=1e-15)
    simulator.AdvanceTo(0.45)
    # Turn toward the left goal between ticks: the outputs hold until the next tick.
    ee.get_mutable_source_value(ee.GetMyContextFromRoot(root)).set_value(
        ee_state(START, toward(GOALS[0])))
    np.testing.assert_allclose(probabilities.Eval(context), expected.probabilities,
                               atol=1e-15)
    history = []
    for tick in range(5, 10):
        simulator.AdvanceTo(tick * 0.1 + 0.05)
        history.append(int(selected.Eval(context)[0]))
    # The ticks at 0.5 and 0.6 see the new heading; the switch comes at the second.
    assert history == [1, 0, 0, 0, 0]
    turned = estimate(settings, GOALS, START, toward(GOALS[0]))
    np.testing.assert_allclose(probabilities.Eval(context), turned.probabilities, atol=1e-15)


def test_system_bayesian_records_start_and_path_length():
    settings = GoalEstimatorSettings(method="bayesian", beta=3.0)
    goals = np.array([[2.0, 1.0, 0.7], [2.0, -1.0, 0.7]])
    simulator, ee, estimator = build_estimator(settings, goals, START, 0.0)
    root = simulator.get_mutable_context()
    context = estimator.GetMyContextFromRoot(root)
    simulator.Initialize()
    np.testing.assert_allclose(
        estimator.get_goal_probabilities_output_port().Eval(context), [0.5, 0.5])
    moved = START + 0.3 * (goals[1] - START) / np.linalg.norm(goals[1] - START)
    ee.get_mutable_source_value(ee.GetMyContextFromRoot(root)).set_value(ee_state(moved, 0.0))
    simulator.AdvanceTo(0.35)
    expected = estimate(settings, goals, moved, 0.0, start=START, path_length=0.3)
    np.testing.assert_allclose(
        estimator.get_goal_probabilities_output_port().Eval(context), expected.probabilities,
        atol=1e-12)
    assert estimator.get_selected_goal_output_port().Eval(context)[0] == 1.0


def test_system_without_initialisation_events_initialises_at_its_first_update():
    from pydrake.systems.analysis import InitializeParams

    settings = GoalEstimatorSettings(method="angle", hold_steps=5)
    simulator, _, estimator = build_estimator(settings, GOALS, START, toward(GOALS[2]))
    context = estimator.GetMyContextFromRoot(simulator.get_mutable_context())
    simulator.Initialize(InitializeParams(suppress_initialization_events=True))
    assert estimator.get_selected_goal_output_port().Eval(context)[0] == 0.0
    simulator.AdvanceTo(0.05)
    # The first tick selects at once, not after hold_steps.
    assert estimator.get_selected_goal_output_port().Eval(context)[0] == 2.0
