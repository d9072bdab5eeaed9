"""The six-DoF DMP bank system: the NumPy banks' steps inside a LeafSystem (to 1e-12), one
phase lock for position and orientation, bad goals and hand states refused by name, and the
compact state (`compact_state=True`: with `followed_goal` connected, 16 numbers whatever K,
the K stepped DMPs a cache entry computed from them, the per-goal state's outputs bit for
bit, distinct weights included)."""

import numpy as np
import pytest
from bit_for_bit import assert_same_outputs
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.core import quaternion
from pbp_drake.core.dmp import DmpBankModel as PositionModel
from pbp_drake.core.dmp import DmpSettings
from pbp_drake.core.dmp.orientation_bank import OrientationDmpBank
from pbp_drake.systems.pbp.goals_source import GoalsSource
from pbp_drake.systems.pbp.pose_dmp_bank import PoseDmpBank

DT = 0.01
K = 5
SETTINGS = DmpSettings(basis_count=20)
ROBOT_ORIENTATION = quaternion.exp_map(np.array([0.3, -0.2, 0.5]))
ROBOT = np.concatenate([[0.1, -0.2, 0.3], ROBOT_ORIENTATION, [0.05, 0.0, -0.02],
                        [0.1, -0.3, 0.2]])


def make_banks(seed=0):
    """Distinct weights for every goal in both parts (as learned ones would be)."""
    rng = np.random.default_rng(seed)
    straight = OrientationDmpBank.straight(quaternion.IDENTITY, K, 1.2, SETTINGS)
    rotation_weights = np.asarray(straight._weights)[None] * rng.uniform(0.5, 1.5, (K, 1, 3))
    orientations = OrientationDmpBank(rotation_weights, quaternion.IDENTITY, 1.2, SETTINGS)
    position_weights = rng.normal(0.0, 50.0, (K, SETTINGS.basis_count, 3))
    positions = PositionModel(position_weights, np.zeros(3), 1.2, SETTINGS)
    goal_rows = rng.normal(size=(K, 4))
    goal_rows /= np.linalg.norm(goal_rows, axis=1, keepdims=True)
    goals = np.hstack([rng.uniform(0.3, 0.8, (K, 3)), goal_rows])
    return positions, orientations, goals


def simulate(seconds, followed=None, active=None, lock=False, robot=ROBOT, goals=None):
    positions, orientations, default_goals = make_banks()
    goals = default_goals if goals is None else goals
    builder = DiagramBuilder()
    bank = builder.AddSystem(PoseDmpBank(positions, orientations, DT,
                                         lock_phase_when_operator_acts=lock))
    state = builder.AddSystem(ConstantVectorSource(robot))
    builder.Connect(state.get_output_port(), bank.get_robot_state_input_port())
    source = builder.AddSystem(GoalsSource(goals))
    builder.Connect(source.get_output_port(), bank.get_goal_poses_input_port())
    if followed is not None:
        index = builder.AddSystem(ConstantVectorSource([float(followed)]))
        builder.Connect(index.get_output_port(), bank.get_followed_goal_input_port())
    if active is not None:
        times, values = active
        script = builder.AddSystem(TrajectorySource(PiecewisePolynomial.ZeroOrderHold(
            times, np.asarray(values, dtype=float)[np.newaxis])))
        builder.Connect(script.get_output_port(), bank.get_operator_active_input_port())
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(seconds)
    context = bank.GetMyContextFromRoot(simulator.get_context())
    return bank, context, (positions, orientations, goals)


def numpy_references(models, steps, followed=None):
    """The banks stepped `steps` times from the fixed hand pose: (K, 13) references."""
    positions, orientations, goals = models
    phase, _, velocity = positions.initial_state()
    rotation_phase, _, eta = orientations.initial_state()
    goals_dk = positions.goals_matrix(goals[:, :3])
    goals_4k = orientations.goals_matrix(goals[:, 3:])
    for _ in range(steps):
        phase, stepped, velocity = positions.advance(phase, ROBOT[:3, None], velocity,
                                                     goals_dk, DT, followed=followed)
        rotation_phase, rotations, eta = orientations.advance(
            rotation_phase, ROBOT_ORIENTATION[:, None], eta, goals_4k, DT, followed=followed)
    np.testing.assert_array_equal(phase, rotation_phase)  # one phase for both parts
    return np.hstack([stepped.T, rotations.T, velocity.T / positions.duration,
                      eta.T / orientations.duration]), phase


def steps_taken(bank, context):
    """How many free steps the bank took: its phase is `decay^steps`."""
    phase = bank.get_phase_output_port().Eval(context)[0]
    return int(round(np.log(phase) / np.log(bank.position_bank.decay(DT))))


@pytest.mark.parametrize("followed", [None, 3], ids=["own velocities", "followed goal"])
def test_the_system_steps_as_the_numpy_banks(followed):
    bank, context, models = simulate(0.255, followed=followed)
    steps = steps_taken(bank, context)
    assert steps == 26  # one step at each tick, 0.00 to 0.25 s
    expected, phase = numpy_references(models, steps, followed)
    references = bank.get_references_output_port().Eval(context).reshape(K, 13)
    np.testing.assert_allclose(references, expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(bank.get_phase_output_port().Eval(context), phase, rtol=1e-15)


def test_the_selected_reference_is_that_goals_row():
    bank, context, _ = simulate(0.155, followed=2)
    references = bank.get_references_output_port().Eval(context).reshape(K, 13)
    selected = bank.get_selected_reference_output_port().Eval(context)
    np.testing.assert_allclose(selected, references[2], rtol=0, atol=1e-14)
    reference = bank.selected_reference(context)
    np.testing.assert_array_equal(reference.to_vector(), selected)  # a PoseReference


def test_pbp_alternated_locks_both_phases_while_the_operator_acts():
    presses = ([0.0, 0.1, 0.2, 1.0], [0.0, 1.0, 0.0, 0.0])  # pressed from 0.1 s to 0.2 s
    phases, rows = [], []
    bank, context, _ = simulate(0.095, active=presses, lock=True)
    phases.append(bank.get_phase_output_port().Eval(context)[0])
    for seconds in (0.135, 0.195):
        bank, context, _ = simulate(seconds, active=presses, lock=True)
        phases.append(bank.get_phase_output_port().Eval(context)[0])
        rows.append(bank.get_references_output_port().Eval(context).reshape(K, 13))
    bank, context, _ = simulate(0.255, active=presses, lock=True)
    after = bank.get_phase_output_port().Eval(context)[0]
    assert phases[0] == phases[1] == phases[2]  # frozen from the press on
    assert after < phases[2]  # running again after the release
    for references in rows:
        # Every DMP sits at the hand's pose and moves with its twist, both parts.
        np.testing.assert_allclose(references[:, :3], np.tile(ROBOT[:3], (K, 1)), atol=1e-15)
        assert all(quaternion.angle_between(row[3:7], ROBOT_ORIENTATION) < 1e-12
                   for row in references)
        np.testing.assert_allclose(references[:, 7:], np.tile(ROBOT[7:], (K, 1)), atol=1e-15)


def test_a_goal_whose_quaternion_is_not_unit_is_refused_by_name():
    _, _, goals = make_banks()
    goals[3, 3:] *= 1.5
    with pytest.raises(ValueError, match="goal_poses orientation is not a unit quaternion"):
        simulate(0.02, goals=goals)


def test_a_nan_hand_twist_is_refused_with_its_field_named():
    robot = ROBOT.copy()
    robot[11] = np.nan
    with pytest.raises(ValueError, match="robot_state wy is NaN or infinite"):
        simulate(0.02, robot=robot)


def test_banks_of_different_phases_dimensions_or_goal_counts_are_refused():
    positions, _, _ = make_banks()
    slower = OrientationDmpBank.straight(quaternion.IDENTITY, K, 2.0, SETTINGS)
    with pytest.raises(ValueError, match="share one phase"):
        PoseDmpBank(positions, slower, DT)
    with pytest.raises(ValueError, match="the position bank must be 3-D, got D = 2"):
        PoseDmpBank(PositionModel.straight(np.zeros(2), K, 1.2, SETTINGS), slower, DT)
    same_phase = OrientationDmpBank.straight(quaternion.IDENTITY, K + 1, 1.2, SETTINGS)
    with pytest.raises(ValueError, match=f"the banks have {K} and {K + 1} goals; a pose bank "
                                         f"needs one count"):
        PoseDmpBank(positions, same_phase, DT)


def test_a_prediction_period_of_zero_is_refused_not_taken_for_the_default():
    positions, orientations, _ = make_banks()
    with pytest.raises(ValueError, match="prediction_period must be positive, got 0"):
        PoseDmpBank(positions, orientations, DT, prediction_steps=3, prediction_period=0)


def test_a_hand_quaternion_that_is_not_unit_is_refused_by_name():
    robot = ROBOT.copy()
    robot[3:7] *= 1.01
    with pytest.raises(ValueError, match="robot_state orientation is not a unit quaternion"):
        simulate(0.02, robot=robot)


def test_a_cloned_context_steps_as_the_original():
    """The state and the scratch (a cache entry, deep-copied with the Context) are the
    Context's: a clone stepped in between the original's steps gives the same numbers."""
    positions, orientations, goals = make_banks()
    builder = DiagramBuilder()
    bank = builder.AddSystem(PoseDmpBank(positions, orientations, DT))
    state = builder.AddSystem(ConstantVectorSource(ROBOT))
    source = builder.AddSystem(GoalsSource(goals))
    builder.Connect(state.get_output_port(), bank.get_robot_state_input_port())
    builder.Connect(source.get_output_port(), bank.get_goal_poses_input_port())
    diagram = builder.Build()
    first = Simulator(diagram)
    first.AdvanceTo(0.05)
    second = Simulator(diagram, first.get_context().Clone())
    for seconds in (0.1, 0.15):
        first.AdvanceTo(seconds)
        second.AdvanceTo(seconds)
        rows = [bank.get_references_output_port().Eval(
            bank.GetMyContextFromRoot(simulator.get_context())) for simulator in (first, second)]
        np.testing.assert_array_equal(rows[0], rows[1])


@pytest.mark.parametrize("selected", [1, 3])
def test_the_predicted_poses_are_the_selected_dmps_rollout_to_its_goal(selected):
    positions, orientations, goals = make_banks()
    steps = 30
    bank = PoseDmpBank(positions, orientations, DT, prediction_steps=steps)
    context = bank.CreateDefaultContext()
    bank.get_robot_state_input_port().FixValue(context, ROBOT)
    bank.get_goal_poses_input_port().FixValue(context, goals.reshape(-1))
    bank.get_selected_goal_input_port().FixValue(context, [float(selected)])
    for _ in range(20):  # 0.2 s of steps, so the rollout starts mid-way
        context.SetDiscreteState(bank.EvalUniquePeriodicDiscreteUpdate(context).value())
    path = bank.get_predicted_poses_output_port().Eval(context).reshape(steps + 1, 7)
    phase, stepped, rotations, velocity, eta = bank.dmp_states(context)
    period = positions.duration / steps
    expected = positions.predict(phase, stepped, velocity, goals[:, :3].T, period, steps)
    turns = orientations.predict(phase, rotations, eta, goals[:, 3:].T, period, steps)
    np.testing.assert_allclose(path[:, :3], expected[selected], atol=1e-12)
    np.testing.assert_allclose(path[:, 3:], turns[selected], atol=1e-12)
    # What the page draws: a path from the selected DMP's pose that ends near its goal.
    np.testing.assert_allclose(path[0, :3], stepped[:, selected], atol=1e-12)
    assert np.linalg.norm(path[-1, :3] - goals[selected, :3]) < 0.05
    assert quaternion.angle_between(path[-1, 3:], goals[selected, 3:]) < 0.05


def test_goals_set_between_steps_are_stepped_to():
    """New goals (`GoalsSource.set_goals`) reach the next step: the orientation part then
    recomputes its start errors (it reuses them only while the goals are not recomputed)."""
    positions, orientations, goals = make_banks()
    _, _, new_goals = make_banks(seed=1)
    builder = DiagramBuilder()
    bank = builder.AddSystem(PoseDmpBank(positions, orientations, DT))
    state = builder.AddSystem(ConstantVectorSource(ROBOT))
    source = builder.AddSystem(GoalsSource(goals))
    index = builder.AddSystem(ConstantVectorSource([3.0]))
    builder.Connect(state.get_output_port(), bank.get_robot_state_input_port())
    builder.Connect(source.get_output_port(), bank.get_goal_poses_input_port())
    builder.Connect(index.get_output_port(), bank.get_followed_goal_input_port())
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(0.105)
    context = bank.GetMyContextFromRoot(simulator.get_context())
    before = steps_taken(bank, context)
    source.set_goals(source.GetMyMutableContextFromRoot(simulator.get_context()), new_goals)
    simulator.AdvanceTo(0.255)
    phase, _, velocity = positions.initial_state()
    rotation_phase, _, eta = orientations.initial_state()
    for step in range(steps_taken(bank, context)):
        rows = goals if step < before else new_goals
        phase, stepped, velocity = positions.advance(
            phase, ROBOT[:3, None], velocity, positions.goals_matrix(rows[:, :3]), DT,
            followed=3)
        rotation_phase, rotations, eta = orientations.advance(
            rotation_phase, ROBOT_ORIENTATION[:, None], eta,
            orientations.goals_matrix(rows[:, 3:]), DT, followed=3)
    expected = np.hstack([stepped.T, rotations.T, velocity.T / positions.duration,
                          eta.T / orientations.duration])
    references = bank.get_references_output_port().Eval(context).reshape(K, 13)
    np.testing.assert_allclose(references, expected, rtol=0, atol=1e-12)


def drive_compact(system, context, step, goals):
    """Fixes what tick `step` feeds the bank: a moving and turning hand, PBP-Alt locks now
    and then, the followed and selected goals changing; the goals once (goals recomputed
    may take the banks' other path, equal to rounding: the layouts then differ by it)."""
    rng = np.random.default_rng(step)
    hand = ROBOT.copy()
    hand[:3] += rng.uniform(-0.1, 0.1, 3)
    hand[3:7] = quaternion.exp_map(rng.uniform(-0.4, 0.4, 3))
    hand[7:] = rng.uniform(-0.5, 0.5, 6)
    system.get_robot_state_input_port().FixValue(context, hand)
    if step == 0:
        system.get_goal_poses_input_port().FixValue(context, goals.reshape(-1))
    system.get_operator_active_input_port().FixValue(context, [float(step % 9 in (4, 5))])
    system.get_followed_goal_input_port().FixValue(context, [float(step // 6 % K)])
    system.get_selected_goal_input_port().FixValue(context, [float(step // 5 % K)])


def outputs(system, context):
    ports = (system.get_references_output_port(), system.get_selected_reference_output_port(),
             system.get_phase_output_port(), system.get_predicted_poses_output_port())
    return [port.Eval(context).copy() for port in ports]


@pytest.mark.slow
@pytest.mark.parametrize("limits", [(None, None), (0.2, 0.5)], ids=["free", "speed limits"])
def test_the_compact_state_gives_the_per_goal_states_outputs_bit_for_bit(limits):
    positions, orientations, goals = make_banks()
    runs = []
    for compact in (False, True):
        system = PoseDmpBank(positions, orientations, DT, lock_phase_when_operator_acts=True,
                             max_speed=limits[0], max_angular_speed=limits[1],
                             prediction_steps=3, compact_state=compact)
        simulator = Simulator(system)
        context = simulator.get_mutable_context()
        run = []
        for step in range(40):
            drive_compact(system, context, step, goals)
            simulator.AdvanceTo(step * DT + DT / 2)
            # Every other tick read before the next update, as a blender would; the others
            # leave the compact state's step to the next update.
            if step % 2:
                run.append(outputs(system, context))
        runs.append(run)
    per_goal, compact = runs
    assert_same_outputs(per_goal, compact,
                        ("references", "selected_reference", "phase", "poses"))
    assert not np.array_equal(per_goal[2][0], per_goal[15][0])  # the run moved


def test_the_compact_state_does_not_grow_with_the_goals():
    positions, orientations, _ = make_banks()
    system = PoseDmpBank(positions, orientations, DT, compact_state=True)
    assert system.CreateDefaultContext().get_discrete_state_vector().size() == 16
    assert PoseDmpBank.state_size(10_000, compact_state=True) == 16
    assert PoseDmpBank.state_size(10_000) == 12 + 12 * 10_000


def test_the_compact_state_needs_the_followed_goal_connected():
    positions, orientations, goals = make_banks()
    system = PoseDmpBank(positions, orientations, DT, compact_state=True)
    simulator = Simulator(system)
    context = simulator.get_mutable_context()
    system.get_robot_state_input_port().FixValue(context, ROBOT)
    system.get_goal_poses_input_port().FixValue(context, goals.reshape(-1))
    with pytest.raises(RuntimeError, match="connect its followed_goal"):
        simulator.AdvanceTo(DT)


def test_a_cloned_context_of_the_compact_state_steps_as_the_original():
    """The cache entry of the K stepped DMPs is the Context's: a clone stepped in between
    the original's steps gives the same numbers."""
    positions, orientations, goals = make_banks()
    system = PoseDmpBank(positions, orientations, DT, compact_state=True)
    first = Simulator(system)
    drive_compact(system, first.get_mutable_context(), 0, goals)
    first.AdvanceTo(0.05)
    system.get_references_output_port().Eval(first.get_context())  # a cache up to date
    second = Simulator(system, first.get_context().Clone())
    for seconds in (0.1, 0.15):
        first.AdvanceTo(seconds)
        second.AdvanceTo(seconds)
        rows = [system.get_references_output_port().Eval(simulator.get_context())
                for simulator in (first, second)]
        np.testing.assert_array_equal(rows[0], rows[1])


@pytest.mark.parametrize("options, message", [
    ({"max_speed": 0.0}, r"max_speed must be positive \(None: no limit\), got 0.0"),
    ({"max_angular_speed": np.nan}, r"max_angular_speed must be positive \(None: no limit\)"),
    ({"prediction_steps": -2}, r"prediction_steps must be a whole number >= 0, got -2"),
    ({"prediction_steps": 3, "prediction_period": -0.1},
     r"prediction_period must be positive, got -0.1"),
])
def test_the_pose_bank_names_an_option_it_cannot_run(options, message):
    positions, orientations, _ = make_banks()
    with pytest.raises(ValueError, match=message):
        PoseDmpBank(positions, orientations, DT, **options)


@pytest.mark.parametrize("which, message", [
    ("position_bank", "position_bank must be DmpBankModel, got NoneType"),
    ("orientation_bank", "orientation_bank must be OrientationDmpBank, got str"),
])
def test_the_pose_bank_names_a_bank_of_the_wrong_kind(which, message):
    positions, orientations, _ = make_banks()
    banks = {"position_bank": positions, "orientation_bank": orientations}
    banks[which] = None if which == "position_bank" else "turns"
    with pytest.raises(ValueError, match=message):
        PoseDmpBank(control_period=DT, **banks)
