"""The virtual participant is blind to the method: it is built from the same arguments
under every method, and what differs between methods reaches it only as a person at the
page sees it (which keys work, the robot's shown intent). With HOP's assistance off, the
robot adds nothing and the keys are teleop's, so its trial equals teleop's tick for tick."""

import dataclasses

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from pbp_drake.builder import build_diagram, find_system
from pbp_drake.builder.grasp import _operator as grasp_operator
from pbp_drake.builder.operators import participant_arguments
from pbp_drake.core.participant_reach import facing
from pbp_drake.systems.ports import EeState
from pbp_drake.scenarios import METHODS, load_scenario_file, resolve

# Every method a participant drives (PBP-NoUser has none; fixed_alpha needs its weight).
DRIVEN = [m if m != "fixed_alpha" else "fixed_alpha=0.5" for m in METHODS
          if m != "pbp_no_user"]
SEED = 3  # a tuning seed


def resolved(repo, name, method, seed=SEED):
    scenario = load_scenario_file(repo / "diagrams" / name).scenario
    return resolve(dataclasses.replace(scenario, seed=seed)).with_method(method)


def same(a, b):
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(a, b)
    return a == b


@pytest.mark.slow
@pytest.mark.parametrize("task", ["hsr_reach.yaml", "hsr_obstacles.yaml", "arm_reach.yaml"])
def test_the_participant_is_built_alike_under_every_method(repo, task):
    first = participant_arguments(resolved(repo, task, DRIVEN[0]))
    for method in DRIVEN[1:]:
        arguments = participant_arguments(resolved(repo, task, method))
        assert arguments.keys() == first.keys()
        for name, value in arguments.items():
            assert same(value, first[name]), (method, name)


@pytest.mark.slow
def test_the_grasp_participant_is_built_alike_under_every_method(repo):
    participants = []
    for method in DRIVEN:
        run = resolved(repo, "hsr_grasp.yaml", method)
        participants.append(grasp_operator(run, run.scene.grasps, None).participant)
    for participant in participants[1:]:
        for field in dataclasses.fields(participant):
            assert same(getattr(participant, field.name),
                        getattr(participants[0], field.name)), field.name


def participant_inputs(run):
    """`(forward_key, shown goal)` the operator reads in a fresh context of the run's
    diagram."""
    diagram = build_diagram(run)
    operator = find_system(diagram, "operator")
    context = operator.GetMyContextFromRoot(diagram.CreateDefaultContext())
    return (operator.GetInputPort("forward_key").Eval(context)[0],
            operator.GetInputPort("selected_goal").Eval(context)[0])


@pytest.mark.slow
@pytest.mark.parametrize("task", ["hsr_reach.yaml", "hsr_grasp.yaml"])
def test_the_keys_and_the_shown_intent_reach_it_through_its_ports(repo, task):
    assert participant_inputs(resolved(repo, task, "teleop")) == (1.0, -1.0)
    forward, shown = participant_inputs(resolved(repo, task, "pbp_alternated"))
    assert forward == 0.0 and shown >= 0.0
    forward, shown = participant_inputs(resolved(repo, task, "hop"))
    assert forward == 1.0 and shown >= 0.0


def commands_and_headings(run, seconds):
    """The participant's command at each control tick of the first `seconds` of `run`'s
    trial, with the hand's heading it was decided at."""
    diagram = build_diagram(run)
    operator = find_system(diagram, "operator")
    simulator = Simulator(diagram)
    context = operator.GetMyContextFromRoot(simulator.get_context())
    ticks = []
    period = run.scenario.control_period
    for tick in range(1, int(round(seconds / period))):
        # At the tick, before its events: the heading the tick's decision reads.
        simulator.AdvanceTo(tick * period)
        heading = EeState(operator.GetInputPort("ee_state").Eval(context)).heading
        simulator.AdvanceTo((tick + 0.5) * period)
        ticks.append((np.array(operator.GetOutputPort("operator_command").Eval(context)),
                      heading))
    return ticks


@pytest.mark.slow
@pytest.mark.parametrize("method", ["pbp_alternated", "pbp_continuous"])
def test_among_obstacles_it_presses_no_forward_the_keys_lack(repo, method):
    run = resolved(repo, "hsr_obstacles.yaml", method, seed=10000)  # an evaluation seed
    ticks = commands_and_headings(run, 12.0)
    acting = [(command, heading) for command, heading in ticks
              if np.linalg.norm(command[:2]) > 0.0]
    assert len(acting) > 20  # it does steer round the cylinders
    for command, heading in acting:
        assert command[:2] @ facing(heading) <= 1e-12
