"""The surrogate pilots as Drake systems: the filters alone in a small diagram, their inputs
given, do what `core.surrogate_pilots` defines, tick by tick; and the pilots of the
reaching, obstacle and grasping tasks, built as a study builds them, have the
participant's ports, are built from the same arguments under every method, and draw the
same under pbp_alternated and hop for one seed."""

import dataclasses

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.builder import build_diagram
from pbp_drake.builder.grasp import _operator as grasp_operator
from pbp_drake.builder.operators import make_hsr_operator
from pbp_drake.core.surrogate_pilots import (
    lag_per_tick, laggy_draw, noisy_draw, reach_key_command)
from pbp_drake.scenarios import METHODS, PILOT_NAMES, load_scenario_file, resolve, with_pilot
from pbp_drake.systems.operators.pilot_filters import LaggyFilter, NoisyFilter, ReachKeys
from pbp_drake.systems.ports import EeState
from pbp_drake.systems.tick import decide_offset

PERIOD = 0.03
SEED = 12
BASE_COMMAND = np.array([0.05, -0.02, 0.0, 0.1])
HEADING = 0.4


def _ee_state():
    state = np.zeros(EeState.size)
    state[6] = HEADING
    return state


def filter_outputs(pilot_filter, ticks, forward_key, base_commands=None):
    """`(commands (ticks, 4), active (ticks,))` of a lone filter after each tick, its base
    command `BASE_COMMAND` (active) or `base_commands` (ticks, 4), one a tick."""
    builder = DiagramBuilder()
    system = builder.AddSystem(pilot_filter)
    if base_commands is None:
        source = builder.AddSystem(ConstantVectorSource(BASE_COMMAND))
    else:
        times = PERIOD * np.arange(ticks + 1)
        values = np.vstack([base_commands, base_commands[-1:]]).T
        source = builder.AddSystem(TrajectorySource(
            PiecewisePolynomial.ZeroOrderHold(times, values)))
    for name, value in (("base_active", [1.0]), ("ee_state", _ee_state()),
                        ("forward_key", [forward_key])):
        builder.Connect(builder.AddSystem(ConstantVectorSource(value)).get_output_port(),
                        system.GetInputPort(name))
    builder.Connect(source.get_output_port(), system.GetInputPort("base_command"))
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = system.GetMyContextFromRoot(simulator.get_mutable_context())
    commands, active = [], []
    for tick in range(ticks):
        simulator.AdvanceTo(tick * PERIOD + decide_offset(PERIOD))
        commands.append(system.get_operator_command_output_port().Eval(context).copy())
        active.append(system.get_operator_active_output_port().Eval(context)[0] > 0.5)
    return np.array(commands), np.array(active)


KEYS = ReachKeys(0.1, 0.8)


@pytest.mark.slow
@pytest.mark.parametrize("forward_key", [1.0, 0.0])
def test_the_noisy_filter_replaces_exactly_the_drawn_ticks_with_their_keys(forward_key):
    ticks = 600
    commands, active = filter_outputs(NoisyFilter(KEYS, PERIOD, SEED, 0.3), ticks,
                                      forward_key)
    corrupted = 0
    for tick in range(ticks):
        replaced, keys = noisy_draw(SEED, tick, 0.3, 3, forward_key > 0.5)
        if replaced:
            corrupted += 1
            expected, pressed = reach_key_command(keys, HEADING, 0.1, 0.8)
            np.testing.assert_allclose(commands[tick], expected, atol=1e-15)
            assert active[tick] == pressed
        else:
            np.testing.assert_array_equal(commands[tick], BASE_COMMAND)
            assert active[tick]
    assert 0.3 * ticks - 5 * np.sqrt(ticks * 0.21) < corrupted < 0.3 * ticks + 5 * np.sqrt(
        ticks * 0.21)


@pytest.mark.slow
def test_the_noisy_filter_corrupts_the_same_ticks_whatever_the_keys():
    with_forward, _ = filter_outputs(NoisyFilter(KEYS, PERIOD, SEED, 0.3), 300, 1.0)
    without, _ = filter_outputs(NoisyFilter(KEYS, PERIOD, SEED, 0.3), 300, 0.0)
    changed = [np.any(row != BASE_COMMAND) for row in with_forward]
    assert changed == [np.any(row != BASE_COMMAND) for row in without]
    # Its turn key is drawn from the same number either way.
    np.testing.assert_array_equal(with_forward[:, 3], without[:, 3])
    # Without the forward key no command it draws pushes forward.
    forward = np.array([np.cos(HEADING), np.sin(HEADING)])
    drawn = without[np.array(changed)]
    assert np.all(drawn[:, :2] @ forward <= 1e-12)
    assert np.any(with_forward[np.array(changed), :2] @ forward > 0.05)


@pytest.mark.slow
def test_the_laggy_filter_repeats_its_last_output_on_the_drawn_ticks():
    ticks = 1500
    base = np.outer(np.arange(ticks), [1e-3, 0.0, 0.0, 0.0])  # every tick a new command
    commands, _ = filter_outputs(LaggyFilter(KEYS, PERIOD, SEED, 0.85), ticks, 1.0, base)
    p_tick = lag_per_tick(0.85, PERIOD)
    np.testing.assert_array_equal(commands[0], base[0])  # nothing to repeat yet
    repeats = 0
    for tick in range(1, ticks):
        if laggy_draw(SEED, tick, p_tick):
            repeats += 1
            np.testing.assert_array_equal(commands[tick], commands[tick - 1])
        else:
            np.testing.assert_array_equal(commands[tick], base[tick])
    assert abs(repeats - p_tick * (ticks - 1)) < 5 * np.sqrt(ticks * p_tick * (1 - p_tick))


# --- The pilots as the builders make them. ---

TASKS = ["hsr_reach.yaml", "hsr_obstacles.yaml", "hsr_grasp.yaml"]
PILOTS = [name for name in PILOT_NAMES if name != "attentive"]
# Every method with an operator (PBP-NoUser has none).
OPERATED = [method for method in METHODS if method != "pbp_no_user"]


@pytest.fixture(scope="module")
def resolved(repo):
    """`{(task file, pilot): resolved scenario}`, the task's own seed."""
    return {(task, pilot): resolve(with_pilot(
        load_scenario_file(repo / "diagrams" / task).scenario, pilot))
        for task in TASKS for pilot in PILOT_NAMES}


def _operator(resolved_scenario, method):
    """The operator system the task's builder makes under `method`, alone."""
    resolved_scenario = resolved_scenario.with_method(method)
    if resolved_scenario.scene.grasps is not None:
        return grasp_operator(resolved_scenario, resolved_scenario.scene.grasps, None)
    return make_hsr_operator(resolved_scenario, None)


def _ports(system):
    inputs = [(system.get_input_port(i).get_name(), system.get_input_port(i).size())
              for i in range(system.num_input_ports())]
    outputs = [(system.get_output_port(i).get_name(), system.get_output_port(i).size())
               for i in range(system.num_output_ports())]
    return inputs, outputs


@pytest.mark.slow
@pytest.mark.parametrize("task", TASKS)
def test_every_pilot_has_the_participants_ports(resolved, task):
    participant = _ports(_operator(resolved[task, "attentive"], "pbp_alternated"))
    for pilot in PILOTS:
        assert _ports(_operator(resolved[task, pilot], "pbp_alternated")) == participant


def operator_run(operator, resolved_scenario, forward_key, ticks=40):
    """`(commands, active, inner)` of a lone operator system after each of `ticks` ticks,
    its inputs held: the hand at the task's start, the first target shown, the shown intent
    on another object (none where there is no other), the keys `forward_key`; `inner` is
    its base participant's commands (None without one)."""
    builder = DiagramBuilder()
    system = builder.AddSystem(operator)
    scene = resolved_scenario.scene
    target = scene.targets[0]
    count = len(scene.objects)
    selected = (target + 1) % count if count > 1 else -1
    hand = resolved_scenario.initial_ee_state
    if system.HasInputPort("hand_pose"):
        hand = _grasp_start(resolved_scenario)
    values = {"ee_state": hand, "hand_pose": hand,
              "target": [*scene.objects[target], target], "selected_goal": [selected],
              "forward_key": [forward_key]}
    if scene.obstacles is not None:
        values["obstacle_positions"] = np.asarray(scene.obstacles.obstacle_starts)[:, :2]
    for index in range(system.num_input_ports()):
        port = system.get_input_port(index)
        source = builder.AddSystem(ConstantVectorSource(
            np.asarray(values[port.get_name()], float).reshape(-1)))
        builder.Connect(source.get_output_port(), port)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    root = simulator.get_mutable_context()
    context = system.GetMyContextFromRoot(root)
    inner = (system.GetSubsystemByName("participant")
             if hasattr(system, "GetSubsystemByName") else None)
    commands, active, inner_commands = [], [], []
    for tick in range(ticks):
        simulator.AdvanceTo(tick * PERIOD + decide_offset(PERIOD))
        commands.append(system.get_operator_command_output_port().Eval(context).copy())
        active.append(system.get_operator_active_output_port().Eval(context)[0])
        if inner is not None:
            inner_commands.append(inner.get_operator_command_output_port().Eval(
                inner.GetMyContextFromRoot(root)).copy())
    return np.array(commands), np.array(active), (np.array(inner_commands) if inner_commands
                                                  else None)


def _grasp_start(resolved_scenario):
    """The grasping task's hand pose at the start (its diagram's sampled pose)."""
    diagram = build_diagram(resolved_scenario, None)
    sample = diagram.GetSubsystemByName("hand_pose_sample")
    return sample.get_output_port().Eval(sample.GetMyContextFromRoot(
        diagram.CreateDefaultContext())).copy()


@pytest.mark.slow
@pytest.mark.parametrize("task", TASKS)
@pytest.mark.parametrize("pilot", PILOT_NAMES)
def test_every_pilot_is_built_from_the_same_arguments_under_every_method(resolved, task,
                                                                         pilot):
    # Given the same inputs (the keys included), every method's pilot does the same.
    reference = None
    for method in OPERATED:
        commands, active, _ = operator_run(_operator(resolved[task, pilot], method),
                                           resolved[task, pilot], forward_key=1.0)
        if reference is None:
            reference = commands, active
            assert np.any(active), "a pilot that never acts tells nothing here"
            continue
        np.testing.assert_array_equal(commands, reference[0], err_msg=method)
        np.testing.assert_array_equal(active, reference[1], err_msg=method)


@pytest.mark.slow
@pytest.mark.parametrize("task", TASKS)
@pytest.mark.parametrize("pilot", ["noisy", "laggy"])
def test_one_seed_draws_the_same_under_pbp_alternated_and_hop(resolved, task, pilot):
    """Each method's own keys (hop's forward key, PBP's none): the filter replaces (noisy)
    or repeats (laggy) its participant's output on the same ticks."""
    ticks = 80
    changed = {}
    for method, forward_key in (("pbp_alternated", 0.0), ("hop", 1.0)):
        commands, _, inner = operator_run(_operator(resolved[task, pilot], method),
                                          resolved[task, pilot], forward_key, ticks)
        if pilot == "laggy":
            # A repeated tick holds the last output; the participant's own may equal it.
            changed[method] = [tick for tick in range(1, ticks)
                               if laggy_draw(resolved[task, pilot].scenario.seed, tick,
                                             lag_per_tick(0.85, PERIOD))]
            for tick in changed[method]:
                np.testing.assert_array_equal(commands[tick], commands[tick - 1])
        else:
            changed[method] = [tick for tick in range(ticks)
                               if np.any(commands[tick] != inner[tick])]
    assert changed["pbp_alternated"] == changed["hop"]
    assert changed["hop"], "no tick was drawn: the test would tell nothing"


def test_the_population_draws_one_participant_per_seed_whatever_the_method(resolved):
    scenario = resolved["hsr_reach.yaml", "population"]
    participants = {method: _operator(scenario, method).params for method in OPERATED}
    assert all(params == participants["teleop"] for params in participants.values())
    other = dataclasses.replace(scenario, scenario=dataclasses.replace(
        scenario.scenario, seed=scenario.scenario.seed + 1))
    assert _operator(other, "teleop").params != participants["teleop"]
