"""The DmpBank system's compact state (`compact_state=True`): for DMPs that share weights and
start and step from the followed DMP's velocity, a state whatever K (`2 + 6 D` numbers),
whose outputs are the per-goal state's bit for bit; and `selected_reference`, the selected
goal's reference alone, which the blender can follow instead of all K."""

import numpy as np
import pytest
from bit_for_bit import assert_same_outputs
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from pbp_drake.core.dmp import DmpBankModel as DmpBankMath
from pbp_drake.core.dmp import DmpSettings
from pbp_drake.core.dmp.stepping import limit_speeds
from pbp_drake.systems import Blender
from pbp_drake.systems.pbp.dmp_bank import DmpBank

DT = 0.01
GOALS = np.array([[0.6, 0.2, 0.3], [0.5, -0.4, 0.1], [-0.3, 0.7, 0.5], [0.1, 0.1, -0.6]])


def shared_bank(formulation="ijspeert"):
    settings = DmpSettings(basis_count=15, formulation=formulation)
    return DmpBankMath.straight(np.array([0.05, -0.02, 0.1]), len(GOALS), 1.2, settings)


def distinct_bank(formulation="ijspeert"):
    """Weights of its own for every goal, as learned ones would be."""
    settings = DmpSettings(basis_count=15, formulation=formulation)
    weights = np.random.default_rng(4).normal(0.0, 40.0, (len(GOALS), 15, 3))
    return DmpBankMath(weights, np.array([0.05, -0.02, 0.1]), 1.2, settings)


def drive(system, context, step):
    """Fixes what tick `step` feeds the bank: a moving robot, PBP-Alt locks now and then, and
    the followed goal changing."""
    rng = np.random.default_rng(step)
    system.get_robot_state_input_port().FixValue(context, rng.uniform(-0.5, 0.5, 6))
    system.get_goals_input_port().FixValue(context, GOALS.reshape(-1))
    system.get_operator_active_input_port().FixValue(context, [float(step % 9 in (4, 5))])
    system.get_followed_goal_input_port().FixValue(context, [float(step // 6 % len(GOALS))])
    system.get_selected_goal_input_port().FixValue(context, [float(step // 5 % len(GOALS))])


def outputs(system, context):
    return [port.Eval(context).copy() for port in (
        system.get_references_output_port(), system.get_selected_reference_output_port(),
        system.get_phase_output_port(), system.get_predicted_paths_output_port())]


@pytest.mark.parametrize("formulation", ["ijspeert", "pastor"])
@pytest.mark.parametrize("max_speed", [None, 0.3])
def test_the_compact_state_gives_the_per_goal_states_outputs_bit_for_bit(formulation,
                                                                          max_speed):
    bank = shared_bank(formulation)
    runs = []
    for compact in (False, True):
        system = DmpBank(bank, DT, lock_phase_when_operator_acts=True, prediction_steps=3,
                         max_speed=max_speed, compact_state=compact)
        simulator = Simulator(system)
        context = simulator.get_mutable_context()
        run = []
        for step in range(40):
            drive(system, context, step)
            simulator.AdvanceTo(step * DT + DT / 2)
            run.append(outputs(system, context))
        runs.append(run)
    per_goal, compact = runs
    assert_same_outputs(per_goal, compact,
                        ("references", "selected_reference", "phase", "paths"))
    # The run did move, lock and unlock.
    assert not np.array_equal(per_goal[3][0], per_goal[30][0])


@pytest.mark.slow
def test_one_velocity_is_limited_as_each_column_of_many_bit_for_bit():
    """The compact layouts limit the followed DMP's velocity alone, the per-goal layout every
    column: the same scale to the last bit, on any Python and NumPy (the one column's sum of
    squares once differed from NumPy's norm in one column of ten on Python 3.12)."""
    rng = np.random.default_rng(12)
    for _ in range(2000):
        column = rng.normal(0.0, 1.0, (3, 1)) * 10.0 ** rng.uniform(-2, 1)
        one, many = column.copy(), np.repeat(column, 4, axis=1)
        limit_speeds(one, 0.3, 1.2)
        limit_speeds(many, 0.3, 1.2)
        for k in range(4):
            assert np.array_equal(one[:, 0], many[:, k])
        # The limit itself, from its definition (a speed of |tau v| / tau at most 0.3).
        assert np.linalg.norm(one) / 1.2 <= 0.3 * (1 + 1e-12)


def test_the_compact_state_does_not_grow_with_the_goals():
    bank = DmpBankMath.straight(np.zeros(3), 100_000, 1.0)
    system = DmpBank(bank, DT, compact_state=True)
    assert system.CreateDefaultContext().get_discrete_state_vector().size() == 2 + 6 * 3
    assert DmpBank.state_size(100_000, 3, compact_state=True) == 20
    assert DmpBank.state_size(100_000, 3) == 2 + 3 + 9 * 100_000


def test_the_compact_state_refuses_distinct_weights():
    with pytest.raises(ValueError, match="share weights and start"):
        DmpBank(distinct_bank(), DT, compact_state=True)
    system = DmpBank(distinct_bank(), DT)
    assert system.CreateDefaultContext().get_discrete_state_vector().size() == 2 + 3 + 9 * 4


def test_the_compact_state_needs_the_followed_goal_connected():
    system = DmpBank(shared_bank(), DT, compact_state=True)
    simulator = Simulator(system)
    context = simulator.get_mutable_context()
    system.get_robot_state_input_port().FixValue(context, np.zeros(6))
    system.get_goals_input_port().FixValue(context, GOALS.reshape(-1))
    with pytest.raises(RuntimeError, match="connect its followed_goal"):
        simulator.AdvanceTo(DT)


def test_the_selected_reference_is_the_selected_goals_row_of_the_references():
    system = DmpBank(shared_bank(), DT)
    simulator = Simulator(system)
    context = simulator.get_mutable_context()
    for step in range(12):
        drive(system, context, step)
        simulator.AdvanceTo(step * DT + DT / 2)
    selected = int(system.get_selected_goal_input_port().Eval(context)[0])
    references = system.get_references_output_port().Eval(context).reshape(2, len(GOALS), 3)
    assert np.array_equal(system.get_selected_reference_output_port().Eval(context),
                          references[:, selected].reshape(-1))


def test_the_blender_follows_a_policy_reference_as_it_follows_the_selected_row():
    references = np.arange(2 * 3 * 2, dtype=float).reshape(2, 3, 2) / 10.0  # (2, K, D)
    commands = []
    for policy in (False, True):
        builder = DiagramBuilder()
        blender = builder.AddSystem(Blender("pbp_continuous", 2, 3, 0.1))
        diagram = builder.Build()
        context = blender.GetMyContextFromRoot(diagram.CreateDefaultContext())
        blender.get_robot_state_input_port().FixValue(context, [0.1, 0.2, 0.0, 0.0])
        blender.get_selected_goal_input_port().FixValue(context, [2.0])
        blender.get_operator_command_input_port().FixValue(context, [0.3, -0.1])
        blender.get_operator_active_input_port().FixValue(context, [1.0])
        if policy:
            blender.get_policy_reference_input_port().FixValue(
                context, references[:, 2].reshape(-1))
        else:
            blender.get_references_input_port().FixValue(context, references.reshape(-1))
        commands.append(blender.get_command_output_port().Eval(context))
    assert np.array_equal(commands[0], commands[1])
