"""The DmpBank system keeps everything a step changes in its Context: two Contexts of one
system, two Simulators of one diagram, or two threads give exactly what each gives alone,
and the bank's model is not touched by any step."""

import threading

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.core.dmp import DmpBankModel as DmpBankMath
from pbp_drake.core.dmp import DmpSettings, fit_weights
from pbp_drake.systems.pbp.dmp_bank import DmpBank
from pbp_drake.systems.pbp.goals_source import GoalsSource
from pbp_drake.systems.tick import decide_offset

DT = 0.01
STEPS = 30


def make_bank(shared, goal_count=8, dimension=3, seed=0):
    rng = np.random.default_rng(seed)
    settings = DmpSettings(basis_count=20)
    times = np.linspace(0.0, 1.0, 120)
    s = times / times[-1]
    path = np.stack([s**2 * (1 + d) + 0.2 * np.sin(np.pi * s) * d for d in range(dimension)], 1)
    weights, scaling = fit_weights(times, path, settings)
    if not shared:
        weights = weights[None] * rng.uniform(0.5, 1.5, (goal_count, 1, dimension))
    return DmpBankMath(weights, np.zeros(dimension), 0.8, settings, scaling,
                       goal_count=goal_count)


def inputs(seed, step, goal_count, dimension):
    """What one run feeds its bank at `step`: a moving robot, goals that jump, and PBP-Alt
    locks, all different for different seeds."""
    rng = np.random.default_rng(1000 * seed + step)
    robot = rng.uniform(-1, 1, 2 * dimension)
    goals = np.random.default_rng(seed).uniform(-1, 1, (goal_count, dimension))
    goals += 0.1 * (step // 7)
    locked = (step + seed) % 11 in (3, 4)
    return robot, goals, locked


def outputs(system, context):
    return [port.Eval(context).copy() for port in (
        system.get_references_output_port(), system.get_phase_output_port(),
        system.get_predicted_paths_output_port())]


def step_once(system, simulator, seed, step):
    context = system.GetMyContextFromRoot(simulator.get_mutable_context())
    bank = system.bank
    robot, goals, locked = inputs(seed, step, bank.goal_count, bank.dimension)
    system.get_robot_state_input_port().FixValue(context, robot)
    system.get_goals_input_port().FixValue(context, goals.reshape(-1))
    system.get_operator_active_input_port().FixValue(context, [float(locked)])
    simulator.AdvanceTo(step * DT + DT / 2)  # the update of tick `step`
    return outputs(system, context)


def run_alone(system, seed):
    simulator = Simulator(system, system.CreateDefaultContext())
    return [step_once(system, simulator, seed, step) for step in range(STEPS)]


def model_snapshot(bank):
    return {name: value.copy() for name, value in vars(bank).items()
            if isinstance(value, np.ndarray)}


def assert_same_runs(ours, alone):
    for step, (got, expected) in enumerate(zip(ours, alone)):
        for a, b in zip(got, expected):
            np.testing.assert_array_equal(a, b, err_msg=f"step {step}")


@pytest.mark.slow
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
def test_two_contexts_of_one_system_stepped_alternately_equal_each_alone(shared):
    bank = make_bank(shared)
    system = DmpBank(bank, DT, lock_phase_when_operator_acts=True, prediction_steps=4)
    before = model_snapshot(bank)
    alone = [run_alone(system, seed) for seed in (1, 2)]

    contexts = [system.CreateDefaultContext() for _ in range(2)]
    simulators = [Simulator(system, context) for context in contexts]
    runs = [[], []]
    for step in range(STEPS):
        for index, seed in enumerate((1, 2)):
            runs[index].append(step_once(system, simulators[index], seed, step))
    for run, expected in zip(runs, alone):
        assert_same_runs(run, expected)
    # Each context has a workspace of its own; a clone gets its own too, and steps on alone.
    workspaces = [system._workspace(context) for context in contexts]
    assert workspaces[0] is not workspaces[1]
    clone = contexts[0].Clone()
    assert system._workspace(clone) is not workspaces[0]
    np.testing.assert_array_equal(outputs(system, clone)[0], runs[0][-1][0])
    for name, value in before.items():
        np.testing.assert_array_equal(getattr(bank, name), value, err_msg=name)


def bank_diagram(bank):
    builder = DiagramBuilder()
    system = builder.AddNamedSystem("dmp_bank", DmpBank(bank, DT, prediction_steps=3))
    d = bank.dimension
    robot = builder.AddSystem(ConstantVectorSource(np.r_[0.1 * np.arange(d), np.zeros(d)]))
    goals = builder.AddNamedSystem("goals", GoalsSource(np.ones((bank.goal_count, d))))
    builder.Connect(robot.get_output_port(), system.get_robot_state_input_port())
    builder.Connect(goals.get_goals_output_port(), system.get_goals_input_port())
    return builder.Build(), system, goals


def run_diagram(simulator, system, goals_source, seed, steps):
    """Steps of one Simulator of the diagram; its goals move with `seed`."""
    root = simulator.get_mutable_context()
    rng = np.random.default_rng(seed)
    shape = (system.bank.goal_count, system.bank.dimension)
    for step in range(steps):
        if step % 5 == 0:
            goals_source.set_goals(goals_source.GetMyMutableContextFromRoot(root),
                                   rng.uniform(-1, 1, shape))
        simulator.AdvanceTo(step * DT + DT / 2)
        yield outputs(system, system.GetMyContextFromRoot(root))


@pytest.mark.slow
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
def test_two_simulators_of_one_diagram_stepped_alternately_equal_each_alone(shared):
    diagram, system, goals_source = bank_diagram(make_bank(shared, goal_count=6))
    alone = [list(run_diagram(Simulator(diagram), system, goals_source, seed, STEPS))
             for seed in (3, 4)]
    runs = [run_diagram(Simulator(diagram), system, goals_source, seed, STEPS)
            for seed in (3, 4)]
    together = [[], []]
    for _ in range(STEPS):
        for index, run in enumerate(runs):
            together[index].append(next(run))
    for run, expected in zip(together, alone):
        assert_same_runs(run, expected)


@pytest.mark.slow
def test_two_threads_stepping_one_bank_equal_each_alone():
    """Large enough that NumPy releases the GIL inside a step, so the threads interleave
    within steps: a workspace shared between the contexts would mix their numbers."""
    diagram, system, goals_source = bank_diagram(make_bank(True, goal_count=20000))
    alone = [list(run_diagram(Simulator(diagram), system, goals_source, seed, 12))
             for seed in (5, 6)]
    results = [None, None]

    def work(index, seed):
        results[index] = list(run_diagram(Simulator(diagram), system, goals_source, seed, 12))

    threads = [threading.Thread(target=work, args=(index, seed))
               for index, seed in enumerate((5, 6))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for run, expected in zip(results, alone):
        assert_same_runs(run, expected)


def test_the_bank_updates_at_the_decide_stage_unless_told_otherwise():
    bank = make_bank(True, goal_count=2)
    default = DmpBank(bank, DT).GetUniquePeriodicDiscreteUpdateAttribute()
    assert default.period_sec() == DT
    assert default.offset_sec() == decide_offset(DT)
    expert = DmpBank(bank, DT, update_offset=0.0).GetUniquePeriodicDiscreteUpdateAttribute()
    assert expert.offset_sec() == 0.0
    with pytest.raises(ValueError, match="update_offset"):
        DmpBank(bank, DT, update_offset=DT)
