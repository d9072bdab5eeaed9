"""A method or a goal estimator is its module and one registry entry: one registered here is
run by name from a scenario (resolve, build, simulate) with nothing else changed, and an
unknown name is refused naming the nearest one."""

import dataclasses
import pathlib

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from pbp_drake.builder import build_diagram, find_system
from pbp_drake.core.goal_estimation import (
    ESTIMATORS, READS_POSITION, Estimator, register_estimator, softmax_of_costs)
from pbp_drake.core.methods import METHODS, Method, method_colour, register_method
from pbp_drake.scenarios import (
    METHOD_NAMES, NoOperator, ScenarioError, load_scenario_file, parse_method_label, resolve)

REPO = pathlib.Path(__file__).resolve().parents[2]


def _farthest(settings, goals, position, heading, start, path_length):
    """A toy estimator: the goal farthest from the hand is the most probable."""
    return softmax_of_costs(-np.linalg.norm(goals - position, axis=1), settings.temperature)


@pytest.fixture
def toy_method():
    method = register_method(Method(
        "pbp_alternated_forward", "PBP-Alt with forward", "tab:olive",
        blend_mode="pbp_alternated", lock_phase=True, forward_key=True))
    yield method
    del METHODS[method.name]


@pytest.fixture
def toy_estimator():
    estimator = register_estimator(Estimator("farthest", READS_POSITION, _farthest))
    yield estimator
    del ESTIMATORS[estimator.name]


@pytest.fixture(scope="module")
def reach():
    scenario = load_scenario_file(REPO / "diagrams/hsr_reach.yaml").scenario
    return dataclasses.replace(scenario, operator=NoOperator(), duration=0.2)


def _first_tick(diagram):
    simulator = Simulator(diagram)
    simulator.AdvanceTo(0.05)
    return simulator.get_context()


def test_a_registered_method_runs_by_name(reach, toy_method):
    assert parse_method_label(toy_method.name) == (toy_method.name, None)
    with pytest.raises(ScenarioError, match="only fixed_alpha=A takes a weight"):
        parse_method_label(f"{toy_method.name}=0.5")
    resolved = resolve(dataclasses.replace(reach, method=toy_method.name))
    assert resolved.blend_mode == "pbp_alternated"
    assert resolved.controller.blend_mode == "pbp_alternated"
    assert METHOD_NAMES[toy_method.name] == "PBP-Alt with forward"
    assert dict(METHOD_NAMES)[toy_method.name] == "PBP-Alt with forward"
    assert len(METHOD_NAMES) == len(METHODS)
    assert method_colour(toy_method.name) == "tab:olive"
    diagram = build_diagram(resolved)
    context = _first_tick(diagram)
    keys = find_system(diagram, "keys")
    # The entry's forward key reaches the operator's input.
    assert keys.get_output_port().Eval(keys.GetMyContextFromRoot(context))[0] == 1.0
    assert find_system(diagram, "blender").mode == "pbp_alternated"


def test_a_registered_estimator_runs_by_name(reach, toy_estimator):
    scenario = dataclasses.replace(reach, goal_estimator=dataclasses.replace(
        reach.goal_estimator, method=toy_estimator.name))
    resolved = resolve(scenario)
    diagram = build_diagram(resolved)
    context = _first_tick(diagram)
    estimator = find_system(diagram, "goal_estimator")
    probabilities = estimator.get_goal_probabilities_output_port().Eval(
        estimator.GetMyContextFromRoot(context))
    assert estimator.settings.method == "farthest"
    hand = resolved.initial_ee_state[:3]
    distances = np.linalg.norm(resolved.scene.objects - hand, axis=1)
    assert int(np.argmax(probabilities)) == int(np.argmax(distances))


def test_a_name_is_registered_once(toy_method):
    with pytest.raises(ValueError, match="already registered"):
        register_method(toy_method)
    with pytest.raises(ValueError, match="already registered"):
        register_estimator(ESTIMATORS["nearest"])


@pytest.mark.parametrize("entry", [None, {"name": "mine"}, ("mine", "position", None)])
def test_an_entry_of_another_type_is_refused_by_name(entry):
    # None and a dict raised AttributeError 'name'; a tuple too.
    with pytest.raises(ValueError, match=f"^method must be a Method, got {type(entry).__name__}$"):
        register_method(entry)
    with pytest.raises(ValueError, match=f"^estimator must be an Estimator, got "
                                         f"{type(entry).__name__}$"):
        register_estimator(entry)


def test_an_entry_names_a_law_or_an_assistance_that_exists():
    with pytest.raises(ValueError, match="blend_mode 'pbp_alternate' is not one of"):
        Method("toy", "Toy", "k", blend_mode="pbp_alternate")
    with pytest.raises(ValueError, match="give a blend_mode or an assistance"):
        Method("toy", "Toy", "k", blend_mode="teleop", assistance="hop")
    with pytest.raises(ValueError, match="needed by"):
        register_estimator(Estimator("toy", READS_POSITION))
    with pytest.raises(ValueError, match="assistance 'help' is not one of"):
        Method("toy", "Toy", "k", assistance="help")
    with pytest.raises(ValueError, match="goal estimator 'toy': reads 'gaze' is not one of"):
        register_estimator(Estimator("toy", "gaze"))


def test_unknown_names_are_refused_with_the_nearest_one(reach):
    with pytest.raises(ScenarioError, match=r"scenario.method 'pbp_alternatd' is unknown; "
                                            r"choose one of .*did you mean 'pbp_alternated'"):
        resolve(dataclasses.replace(reach, method="pbp_alternatd"))
    settings = dataclasses.replace(reach.goal_estimator)
    settings.method = "neerest"  # as a YAML loader sets it, after construction
    with pytest.raises(ScenarioError, match=r"scenario.goal_estimator: goal estimation method "
                                            r"'neerest' is unknown.*did you mean 'nearest'"):
        resolve(dataclasses.replace(reach, goal_estimator=settings))
