"""The fast DMP bank equals a plain per-goal loop of single DMPs, and pydmps agrees with the
Ijspeert form.

The bank takes shortcuts (the bases at a step's two phases evaluated once for equal phases,
one product with distinct weights, step terms affine in the goal for shared weights and one
start); the single `Dmp` steps each dimension in a Python loop. They must give the same
states to 1e-12, with distinct and shared weights, both formulations, mixed amplitude
scaling, goals locked one by one (unequal phases), and inside the Drake LeafSystem. Timing
lives in `pbp-drake bench`, not here.
"""

import numpy as np
import pytest

from pbp_drake.core.dmp import FORMULATIONS, Dmp, DmpBankModel, DmpSettings, fit_weights

DT = 0.01


def demonstration(dimension):
    """A rest-to-rest path whose last dimension starts and ends at one value (so the Ijspeert
    amplitude scaling is switched off there)."""
    times = np.linspace(0.0, 1.2, 240)
    s = times / times[-1]
    s = 10 * s**3 - 15 * s**4 + 6 * s**5
    columns = [s * (1.0 + 0.3 * d) + 0.2 * np.sin(np.pi * s) * d for d in range(dimension - 1)]
    columns.append(0.4 * np.sin(np.pi * s))
    return times, np.stack(columns, axis=1)


def make_banks(formulation, shared, goal_count, dimension, uniform_start, seed):
    """A bank and the equal list of single DMPs."""
    rng = np.random.default_rng(seed)
    settings = DmpSettings(formulation=formulation, basis_count=20)
    times, positions = demonstration(dimension)
    weights, scaling = fit_weights(times, positions, settings)
    starts = (np.broadcast_to(rng.uniform(-0.5, 0.5, dimension), (goal_count, dimension))
              if uniform_start else rng.uniform(-0.5, 0.5, (goal_count, dimension)))
    duration = 0.9
    if shared:
        bank = DmpBankModel(weights, starts, duration, settings, scaling, goal_count=goal_count)
        per_goal_weights = [weights] * goal_count
    else:
        distinct = weights[None] * rng.uniform(0.5, 1.5, (goal_count, 1, dimension))
        bank = DmpBankModel(distinct, starts, duration, settings, scaling)
        per_goal_weights = list(distinct)
    dmps = [Dmp(w, starts[k], starts[k] + 1.0, duration, settings, scaling)
            for k, w in enumerate(per_goal_weights)]
    goals = rng.uniform(-1.5, 1.5, (goal_count, dimension))
    return bank, dmps, goals


def run_both(bank, dmps, goals, steps, lock_pattern, seed):
    rng = np.random.default_rng(seed + 1)
    k, d = bank.goal_count, bank.dimension
    phase, _, scaled_velocity = bank.initial_state()
    goals_dk = bank.goals_matrix(goals)
    robot = rng.uniform(-1, 1, d)
    worst = 0.0
    for step in range(steps):
        robot_velocity = rng.uniform(-1, 1, d)
        locked = lock_pattern(step, k)
        phase, positions, scaled_velocity = bank.advance(
            phase, robot[:, None], scaled_velocity, goals_dk, DT, locked=locked,
            robot_velocity=robot_velocity)
        for j, dmp in enumerate(dmps):
            is_locked = bool(np.broadcast_to(locked, (k,))[j]) if locked is not None else False
            position, velocity = dmp.next_step(DT, goals[j], robot, robot_velocity,
                                               phase_locked=is_locked)
            worst = max(worst, np.abs(positions[:, j] - position).max(),
                        np.abs(scaled_velocity[:, j] / bank.duration - velocity).max())
            assert phase[j] == pytest.approx(dmp.phase, abs=1e-15)
        # The robot follows DMP 0 loosely, a stand-in for a lagging tracker.
        robot = 0.7 * robot + 0.3 * positions[:, 0]
    return worst


def never(step, k):
    return None


def all_together(step, k):
    return 20 <= step < 30  # PBP-Alt: the operator acts, every phase freezes


def one_by_one(step, k):
    # Goals locked at different times: the phases become unequal (the per-goal path).
    return (np.arange(k) % 3 == step % 3) if 10 <= step < 25 else None


@pytest.mark.slow
@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
@pytest.mark.parametrize("goal_count", [5, 70])
@pytest.mark.parametrize("uniform_start", [True, False], ids=["one_start", "many_starts"])
@pytest.mark.parametrize("locks", [never, all_together, one_by_one],
                         ids=["free", "locked", "locked_one_by_one"])
def test_fast_bank_equals_a_plain_per_goal_loop(formulation, shared, goal_count,
                                                uniform_start, locks):
    bank, dmps, goals = make_banks(formulation, shared, goal_count, 3, uniform_start, seed=4)
    assert run_both(bank, dmps, goals, 40, locks, seed=4) < 1e-12


@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
@pytest.mark.parametrize("uniform_start", [True, False], ids=["one_start", "many_starts"])
def test_a_position_per_goal_steps_as_the_per_goal_loop(formulation, shared, uniform_start):
    """Positions given `(D, K)`, one per DMP (as `predict` passes them), not the robot's."""
    bank, dmps, goals = make_banks(formulation, shared, 7, 3, uniform_start, seed=3)
    rng = np.random.default_rng(3)
    phase, _, scaled_velocity = bank.initial_state()
    goals_dk = bank.goals_matrix(goals)
    for _ in range(20):
        positions = rng.uniform(-1, 1, (3, 7))
        phase, stepped, scaled_velocity = bank.advance(phase, positions, scaled_velocity,
                                                       goals_dk, DT)
        for j, dmp in enumerate(dmps):
            position, velocity = dmp.next_step(DT, goals[j], positions[:, j])
            np.testing.assert_allclose(stepped[:, j], position, rtol=0, atol=1e-12)
            np.testing.assert_allclose(scaled_velocity[:, j] / bank.duration, velocity,
                                       rtol=0, atol=1e-12)


@pytest.mark.slow
def test_many_distinct_goals_step_as_the_per_goal_loop():
    """Many distinct weights, contracted over the basis rows that matter at each phase
    (`pbp_drake.core.dmp.contraction`, its blocks tested in tests/core/test_contraction.py);
    a sample of goals, the last ones included, checked."""
    goal_count = 3400
    bank, dmps, goals = make_banks("ijspeert", False, goal_count, 3, False, seed=8)
    assert bank._weight_rows is not None
    checked = list(range(0, goal_count, 97)) + [goal_count - 2, goal_count - 1]
    phase, _, scaled_velocity = bank.initial_state()
    goals_dk = bank.goals_matrix(goals)
    robot = np.array([0.1, -0.3, 0.2])
    for _ in range(5):
        phase, positions, scaled_velocity = bank.advance(phase, robot[:, None],
                                                         scaled_velocity, goals_dk, DT)
        for j in checked:
            position, velocity = dmps[j].next_step(DT, goals[j], robot)
            np.testing.assert_allclose(positions[:, j], position, rtol=0, atol=1e-12)
            np.testing.assert_allclose(scaled_velocity[:, j] / bank.duration, velocity,
                                       rtol=0, atol=1e-12)


@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
def test_in_place_steps_with_a_workspace_and_predict_match_advance(shared):
    bank, _, goals = make_banks("ijspeert", shared, 70, 2, True, seed=9)
    goals_dk = bank.goals_matrix(goals)
    workspace = bank.make_workspace()
    phase, positions, scaled_velocity = bank.initial_state()
    expected = bank.initial_state()
    robot = np.array([[0.1], [-0.2]])
    for _ in range(15):
        bank.advance_into(phase, robot, scaled_velocity, goals_dk, DT,
                          phase, positions, scaled_velocity, workspace)
        expected = bank.advance(expected[0], robot, expected[2], goals_dk, DT)
        for ours, theirs in zip((phase, positions, scaled_velocity), expected):
            np.testing.assert_array_equal(ours, theirs)
    saved = phase.copy(), positions.copy(), scaled_velocity.copy()
    paths = bank.predict(phase, positions, scaled_velocity, goals_dk, DT, 10, workspace)
    for before, after in zip(saved, (phase, positions, scaled_velocity)):
        np.testing.assert_array_equal(before, after)  # predict leaves its inputs alone
    np.testing.assert_array_equal(
        paths, bank.predict(phase, positions, scaled_velocity, goals_dk, DT, 10))
    p, y, z = saved
    for step in range(10):
        p, y, z = bank.advance(p, y, z, goals_dk, DT)
        np.testing.assert_allclose(paths[:, step + 1], y.T, rtol=0, atol=1e-12)


@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_the_step_from_one_position_matches_advance_with_followed_velocities(formulation,
                                                                             shared):
    # What Drake's pose bank keeps: `y' - p` and `z'` from one measured position, every DMP
    # continuing from one DMP's velocity; with unchanged goals the distinct Ijspeert weights
    # take the shortcut of contracting straight into the output (goals switched midway).
    bank, _, goals = make_banks(formulation, shared, 40, 3, False, seed=4)
    workspace = bank.make_workspace()
    stepped = np.empty((2, 3, 40))
    expected = bank.initial_state()
    rng = np.random.default_rng(5)
    for step in range(25):
        if step in (0, 12):
            goals_dk = bank.goals_matrix(goals if step == 0 else goals[::-1])
            unchanged = False
        robot = rng.uniform(-1.0, 1.0, (3, 1))
        followed = step % 7
        phase = expected[0]
        expected = bank.advance(phase, robot, expected[2], goals_dk, DT, followed=followed)
        column = (bank.initial_state()[2] if step == 0 else stepped[1])[:, followed:followed + 1]
        bank.stepped_from_one_into(phase, robot, column.copy(), goals_dk, DT, stepped,
                                   workspace, goals_unchanged=unchanged)
        unchanged = True
        np.testing.assert_allclose(robot + stepped[0], expected[1], rtol=0, atol=1e-12)
        np.testing.assert_allclose(stepped[1], expected[2], rtol=0, atol=1e-12)


def _model_arrays(bank):
    return {name: value for name, value in vars(bank).items() if isinstance(value, np.ndarray)}


@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_the_bank_model_is_immutable_and_untouched_by_steps(formulation, shared):
    """Every array of the model is read-only (a write raises), no attribute can be set, and
    stepping (free, locked, partly locked, predicting) leaves the model as it was."""
    bank, _, goals = make_banks(formulation, shared, 9, 3, False, seed=6)
    arrays = _model_arrays(bank)
    assert {"starts", "amplitude_scaling", "_weights"} <= set(arrays)
    before = {name: value.copy() for name, value in arrays.items()}
    attributes = dict(vars(bank))
    for name, value in arrays.items():
        assert not value.flags.writeable, name
        with pytest.raises(ValueError, match="read-only"):
            value.flat[0] = value.flat[0]
    with pytest.raises(AttributeError, match="immutable"):
        bank.duration = 2.0
    with pytest.raises(AttributeError, match="immutable"):
        bank.scratch = np.zeros(3)

    goals_dk = bank.goals_matrix(goals)
    workspace = bank.make_workspace()
    phase, positions, scaled_velocity = bank.initial_state()
    robot = np.array([[0.2], [0.1], [-0.3]])
    for locked in (None, True, np.arange(9) % 2 == 0, None):
        bank.advance_into(phase, robot, scaled_velocity, goals_dk, DT, phase, positions,
                          scaled_velocity, workspace, locked, robot_velocity=[0.1, 0.0, 0.2])
        bank.advance(phase, positions, scaled_velocity, goals_dk, 2 * DT)
    bank.predict(phase, positions, scaled_velocity, goals_dk, DT, 5)
    bank.attractors(phase, goals_dk)
    assert vars(bank).keys() == attributes.keys()
    for name, value in vars(bank).items():
        assert value is attributes[name], name
    for name, value in before.items():
        np.testing.assert_array_equal(arrays[name], value, err_msg=name)
    # The caller's arrays are not the model's: changing them later changes nothing.
    weights = np.ones((bank.settings.basis_count, 3))
    other = DmpBankModel(weights, np.zeros(3), 1.0, bank.settings, goal_count=2)
    weights[...] = 5.0
    assert weights.flags.writeable
    np.testing.assert_array_equal(other._weights, 1.0)


@pytest.mark.slow
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
def test_leaf_system_equals_the_per_goal_loop(shared):
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from pbp_drake.systems.pbp.dmp_bank import DmpBank as DmpBankSystem

    bank, dmps, goals = make_banks("ijspeert", shared, 90, 3, True, seed=2)
    robot = np.array([0.05, -0.1, 0.2])
    builder = DiagramBuilder()
    system = builder.AddSystem(DmpBankSystem(bank, DT))
    robot_source = builder.AddSystem(ConstantVectorSource(np.concatenate([robot, np.zeros(3)])))
    goal_source = builder.AddSystem(ConstantVectorSource(goals.reshape(-1)))
    builder.Connect(robot_source.get_output_port(), system.get_robot_state_input_port())
    builder.Connect(goal_source.get_output_port(), system.get_goals_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    steps = 25
    simulator.AdvanceTo((steps - 0.5) * DT)  # updates at 0, DT, ..., (steps - 1) DT
    context = system.GetMyContextFromRoot(simulator.get_context())
    references = system.get_references_output_port().Eval(context).reshape(2, 90, 3)
    for j, dmp in enumerate(dmps):
        for _ in range(steps):
            position, velocity = dmp.next_step(DT, goals[j], robot)
        np.testing.assert_allclose(references[0, j], position, rtol=0, atol=1e-12)
        np.testing.assert_allclose(references[1, j], velocity, rtol=0, atol=1e-12)


@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
def test_leaf_system_follows_the_bank_through_locks_and_moving_goals(shared):
    """The system keeps its state in another form (see its docstring); stepped with a moving
    robot, goals that change and PBP-Alt locks, it must read out what `advance` returns."""
    from pydrake.systems.analysis import Simulator

    from pbp_drake.systems.pbp.dmp_bank import DmpBank as DmpBankSystem

    bank, _, goals = make_banks("ijspeert", shared, 12, 3, not shared, seed=5)
    system = DmpBankSystem(bank, DT, lock_phase_when_operator_acts=True)
    simulator = Simulator(system)
    context = simulator.get_mutable_context()
    rng = np.random.default_rng(5)
    phase, positions, scaled_velocity = bank.initial_state()
    for step in range(40):
        robot = rng.uniform(-1, 1, 6)
        goals = goals + (0.05 if step % 7 == 0 else 0.0)
        locked = 12 <= step < 18 or step == 30
        system.get_robot_state_input_port().FixValue(context, robot)
        system.get_goals_input_port().FixValue(context, goals.reshape(-1))
        system.get_operator_active_input_port().FixValue(context, [float(locked)])
        simulator.AdvanceTo(step * DT + DT / 2)  # the update at step * DT
        phase, positions, scaled_velocity = bank.advance(
            phase, robot[:3, None], scaled_velocity, bank.goals_matrix(goals), DT,
            locked=locked, robot_velocity=robot[3:])
        references = system.get_references_output_port().Eval(context).reshape(2, 12, 3)
        np.testing.assert_allclose(references[0], positions.T, rtol=0, atol=1e-12)
        np.testing.assert_allclose(references[1], scaled_velocity.T / bank.duration,
                                   rtol=0, atol=1e-12)
        np.testing.assert_array_equal(system.get_phase_output_port().Eval(context), phase)


def test_leaf_system_refuses_a_nan_goal_at_its_first_update():
    from pydrake.systems.analysis import Simulator

    from pbp_drake.systems.pbp.dmp_bank import DmpBank as DmpBankSystem

    bank, _, goals = make_banks("ijspeert", True, 4, 3, True, seed=1)
    system = DmpBankSystem(bank, DT)
    simulator = Simulator(system)
    context = simulator.get_mutable_context()
    goals[2, 1] = np.nan
    system.get_robot_state_input_port().FixValue(context, np.zeros(6))
    system.get_goals_input_port().FixValue(context, goals.reshape(-1))
    with pytest.raises(ValueError, match="goal 2 is .*must be finite"):
        simulator.AdvanceTo(DT / 2)


def pydmps_path(dmp_parameters, dt, duration, y_start, yd_start):
    """pydmps' DMPs_discrete from a disturbed state: its positions at every `dt`."""
    pydmps = pytest.importorskip("pydmps")
    weights, start, goal, centres, widths, alpha_x = dmp_parameters
    other = pydmps.DMPs_discrete(n_dmps=start.size, n_bfs=weights.shape[0], dt=dt,
                                 y0=start.copy(), goal=goal.copy(), w=weights.T.copy(),
                                 ax=alpha_x)
    other.c, other.h = centres.copy(), widths.copy()
    other.y, other.dy = y_start.copy(), yd_start.copy()
    return np.array([other.step()[0].copy() for _ in range(int(round(duration / dt)))])


@pytest.mark.slow
def test_pydmps_agrees_with_the_ijspeert_form():
    """pydmps integrates `ydd = alpha_z (beta_z (g - y) - yd) + x (g - y0) psi.w / sum psi`
    (tau = 1) with explicit Euler on the phase and semi-implicit Euler on (y, yd); ours steps
    the same ODE in closed form with the forcing linear in time over each step (second order
    in dt). Same parameters (alpha_z 25, beta_z 25/4, alpha_x, our centres and widths,
    weights, y0, g) and the same disturbed start. They cannot agree to rounding; they must
    agree to O(dt), and halving dt must halve the gap, pydmps' first-order error (else it is
    a parameter mismatch, which would not shrink)."""
    pytest.importorskip("pydmps")
    settings = DmpSettings(basis_count=20)
    times, positions = demonstration(2)
    positions = positions + np.array([0.0, 0.3]) * (times / times[-1])[:, None]
    weights, _ = fit_weights(times, positions, settings)
    start, goal = np.array([0.0, 0.0]), np.array([1.3, 0.6])
    centres, widths = settings.basis()
    parameters = (weights, start, goal, centres, widths, settings.alpha_x)
    y_start, yd_start = np.array([0.2, -0.3]), np.array([-1.0, 0.8])  # pushed off its start

    gaps = []
    for dt in (4e-4, 2e-4):
        ours = Dmp(weights, start, goal, 1.0, settings)
        ours.reset(position=y_start, scaled_velocity=yd_start)  # tau = 1: z = yd
        path = np.array([ours.next_step(dt)[0] for _ in range(int(round(1.5 / dt)))])
        theirs = pydmps_path(parameters, dt, 1.5, y_start, yd_start)
        gaps.append(np.abs(path - theirs).max())
    scale = np.abs(path).max()
    assert gaps[1] < 2e-3 * scale  # O(dt) at dt = 0.2 ms
    assert 0.4 < gaps[1] / gaps[0] < 0.6  # first order: the gap is discretisation only


def test_the_goals_are_read_once_per_change_from_a_goals_source(monkeypatch):
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from pbp_drake.systems.pbp.dmp_bank import DmpBank as DmpBankSystem
    from pbp_drake.systems.pbp.goals_source import GoalsSource

    bank, _, goals = make_banks("ijspeert", True, 6, 3, True, seed=3)
    builder = DiagramBuilder()
    system = builder.AddSystem(DmpBankSystem(bank, DT))
    source = builder.AddSystem(GoalsSource(goals))
    robot = builder.AddSystem(ConstantVectorSource(np.zeros(6)))
    builder.Connect(source.get_goals_output_port(), system.get_goals_input_port())
    builder.Connect(robot.get_output_port(), system.get_robot_state_input_port())
    simulator = Simulator(builder.Build())
    reads = []
    original = DmpBankModel.goals_matrix
    # On the class: the bank itself is immutable.
    monkeypatch.setattr(DmpBankModel, "goals_matrix",
                        lambda self, g: (reads.append(1), original(self, g))[1])
    simulator.AdvanceTo(10 * DT)
    assert len(reads) == 1
    # New goals in the context are seen at the next update.
    source.set_goals(source.GetMyContextFromRoot(simulator.get_mutable_context()), goals + 1)
    simulator.AdvanceTo(11.5 * DT)
    assert len(reads) == 2
    with pytest.raises(ValueError, match="shape"):
        source.set_goals(source.CreateDefaultContext(), goals[:2])
