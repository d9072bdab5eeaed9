"""The vectorised orientation bank equals a plain per-goal loop of single `OrientationDmp`s to
1e-12: shared and distinct weights, both formulations, one start or many, free, locked
together and locked one by one (unequal phases), from the robot's orientation or one per
DMP."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pbp_drake.core import quaternion
from pbp_drake.core.dmp import FORMULATIONS, DmpSettings
from pbp_drake.core.dmp.orientation import OrientationDmp, fit_orientation_weights
from pbp_drake.core.dmp.orientation_bank import OrientationDmpBank

DT = 1 / 30


def random_rows(count, rng):
    return np.roll(np.atleast_2d(Rotation.random(count, random_state=rng).as_quat()), 1, axis=1)


def demonstration():
    """A turn of 140 degrees whose axis turns, and a last axis the amplitude guard switches
    off (it goes out and comes back)."""
    times = np.linspace(0.0, 1.2, 240)
    u = times / times[-1]
    s = 10 * u**3 - 15 * u**4 + 6 * u**5
    vectors = np.stack([2.0 * s, 1.0 * s**2, 0.6 * np.sin(np.pi * s)])
    return times, quaternion.exp_map(vectors).T


def make_banks(formulation, shared, goal_count, uniform_start, seed):
    rng = np.random.default_rng(seed)
    settings = DmpSettings(formulation=formulation, basis_count=20)
    weights, scaling = fit_orientation_weights(*demonstration(), settings)
    assert not scaling.all() or formulation == "pastor"
    starts = (np.repeat(random_rows(1, rng), goal_count, axis=0) if uniform_start
              else random_rows(goal_count, rng))
    if shared:
        bank = OrientationDmpBank(weights, starts, 0.9, settings, scaling, goal_count)
        per_goal = [weights] * goal_count
    else:
        per_goal = list(weights[None] * rng.uniform(0.5, 1.5, (goal_count, 1, 3)))
        bank = OrientationDmpBank(np.stack(per_goal), starts, 0.9, settings, scaling)
    dmps = [OrientationDmp(w, starts[k], random_rows(1, rng)[0], 0.9, settings, scaling)
            for k, w in enumerate(per_goal)]
    return bank, dmps, random_rows(goal_count, rng)


def never(step, k):
    return None


def all_together(step, k):
    return 10 <= step < 18


def one_by_one(step, k):
    return (np.arange(k) % 3 == step % 3) if 5 <= step < 15 else None


@pytest.mark.slow
@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
@pytest.mark.parametrize("uniform_start", [True, False], ids=["one_start", "many_starts"])
@pytest.mark.parametrize("locks", [never, all_together, one_by_one],
                         ids=["free", "locked", "locked_one_by_one"])
def test_bank_of_k_equals_k_single_dmps(formulation, shared, uniform_start, locks):
    bank, dmps, goals = make_banks(formulation, shared, 7, uniform_start, seed=21)
    rng = np.random.default_rng(22)
    goals_4k = bank.goals_matrix(goals)
    phase, robot, velocity = bank.initial_state()
    robot = robot[:, :1]
    for step in range(30):
        robot_velocity = rng.uniform(-1, 1, 3)
        locked = locks(step, bank.goal_count)
        phase, orientations, velocity = bank.advance(phase, robot, velocity, goals_4k, DT,
                                                     locked=locked,
                                                     robot_angular_velocity=robot_velocity)
        for k, dmp in enumerate(dmps):
            is_locked = locked is not None and bool(np.broadcast_to(locked, (7,))[k])
            orientation, angular_velocity = dmp.next_step(
                DT, goals[k], robot[:, 0], robot_velocity, phase_locked=is_locked)
            np.testing.assert_allclose(orientations[:, k], orientation, rtol=0, atol=1e-12)
            np.testing.assert_allclose(velocity[:, k] / bank.duration, angular_velocity,
                                       rtol=0, atol=1e-12)
            assert phase[k] == pytest.approx(dmp.phase, abs=1e-15)
        # The robot follows DMP 0 with a lag, and is knocked away once.
        robot = quaternion.slerp(robot, orientations[:, :1], 0.5)
        if step == 20:
            robot = random_rows(1, rng).T


@pytest.mark.slow
@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
def test_an_orientation_per_dmp_steps_as_the_per_goal_loop(formulation, shared):
    """Orientations `(4, K)`, one per DMP (as `predict` passes them)."""
    bank, dmps, goals = make_banks(formulation, shared, 5, False, seed=23)
    rng = np.random.default_rng(24)
    goals_4k = bank.goals_matrix(goals)
    phase, _, velocity = bank.initial_state()
    for _ in range(10):
        measured = random_rows(5, rng).T
        phase, orientations, velocity = bank.advance(phase, measured, velocity, goals_4k, DT)
        for k, dmp in enumerate(dmps):
            orientation, angular_velocity = dmp.next_step(DT, goals[k], measured[:, k])
            np.testing.assert_allclose(orientations[:, k], orientation, rtol=0, atol=1e-12)
            np.testing.assert_allclose(velocity[:, k] / bank.duration, angular_velocity,
                                       rtol=0, atol=1e-12)


@pytest.mark.slow
def test_from_dmps_and_predict_match_the_single_rollouts():
    bank, dmps, goals = make_banks("ijspeert", False, 4, False, seed=25)
    rebuilt = OrientationDmpBank.from_dmps(dmps)
    goals_4k = rebuilt.goals_matrix([dmp.goal for dmp in dmps])
    paths = rebuilt.predict(*rebuilt.initial_state(), goals_4k, DT, 40)
    for k, dmp in enumerate(dmps):
        np.testing.assert_allclose(paths[k], dmp.rollout(DT, 40 * DT), rtol=0, atol=1e-12)


def test_the_bank_model_is_immutable():
    bank, _, _ = make_banks("pastor", True, 3, True, seed=26)
    for array in (bank.starts, bank.amplitude_scaling, bank._weights):
        assert not array.flags.writeable
    with pytest.raises(AttributeError, match="immutable"):
        bank.duration = 2.0


@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_in_place_steps_with_one_workspace_match_advance_when_goals_change(formulation):
    """`advance_into` stepping the state in place with one workspace (which keeps the start
    errors of the last goals) equals `advance`, as the goals move every few steps; a copied
    workspace and another bank's workspace recompute them."""
    bank, _, goals = make_banks(formulation, False, 6, False, seed=27)
    other_bank, _, _ = make_banks(formulation, False, 6, False, seed=28)
    rng = np.random.default_rng(29)
    goals_4k = bank.goals_matrix(goals)
    workspace = bank.make_workspace()
    phase, orientations, velocity = bank.initial_state()
    expected = bank.initial_state()
    for step in range(20):
        if step % 4 == 3:
            goals_4k = bank.goals_matrix(random_rows(6, rng))
        if step == 10:
            other_bank.advance_into(*other_bank.initial_state(), goals_4k, DT,
                                    *other_bank.initial_state(), workspace)
        robot = orientations[:, :1].copy()
        bank.advance_into(phase, robot, velocity, goals_4k, DT, phase, orientations,
                          velocity, workspace)
        expected = bank.advance(expected[0], robot, expected[2], goals_4k, DT)
        for ours, theirs in zip((phase, orientations, velocity), expected):
            np.testing.assert_array_equal(ours, theirs)


@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_the_bank_equals_single_dmps_at_tiny_angles_and_half_turns(formulation):
    """Measured orientations at 0, 1e-12, 1e-6, 5e-3 and 2e-2 rad from their goals (both
    sides of the series' switch) and at 180 degrees less 1e-9 and exactly: the bank's
    allocation-free kernels against `pbp_drake.core.quaternion`."""
    offsets = [0.0, 1e-12, 1e-6, 5e-3, 2e-2, np.pi - 1e-9, np.pi]
    count = len(offsets)
    bank, dmps, goals = make_banks(formulation, True, count, True, seed=30)
    rng = np.random.default_rng(31)
    axes = rng.normal(size=(3, count))
    axes /= np.linalg.norm(axes, axis=0)
    measured = quaternion.multiply(quaternion.exp_map(axes * offsets), goals.T)
    velocity = rng.normal(size=(3, count))
    phase = np.full(count, 0.4)
    stepped = bank.advance(phase, measured, velocity, bank.goals_matrix(goals), DT)
    for k, dmp in enumerate(dmps):
        dmp.phase, dmp.scaled_angular_velocity = 0.4, velocity[:, k].copy()
        orientation, angular_velocity = dmp.next_step(DT, goals[k], measured[:, k])
        np.testing.assert_allclose(stepped[1][:, k], orientation, rtol=0, atol=1e-12)
        np.testing.assert_allclose(stepped[2][:, k] / bank.duration, angular_velocity,
                                   rtol=0, atol=1e-12)


@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
def test_the_banks_attractors_are_the_single_dmps(formulation, shared):
    bank, dmps, goals = make_banks(formulation, shared, 5, False, seed=32)
    phases = np.array([1.0, 0.7, 0.3, 0.05, 0.7])
    attractors = bank.attractors(phases, bank.goals_matrix(goals))
    for k, dmp in enumerate(dmps):
        np.testing.assert_allclose(attractors[:, k], dmp.attractor(phases[k], goals[k]),
                                   rtol=0, atol=1e-12)


@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("shared", [True, False], ids=["shared", "distinct"])
def test_one_orientation_and_one_velocity_for_all_equal_single_dmps(formulation, shared):
    """The fused step (`orientation_log_step`: one measured orientation `(4, 1)` and one
    `eta` `(3, 1)`, as the six-DoF system steps with a followed goal) against single DMPs,
    with errors at 0, 1e-12, 1e-6, 5e-3 and 2e-2 rad (both sides of the series' switch),
    180 degrees less 1e-9, and exactly 180 degrees (`w = 0` and `-0.0`); at one phase for
    all and at a phase per DMP."""
    offsets = [0.0, 1e-12, 1e-6, 5e-3, 2e-2, np.pi - 1e-9, 0.7, 2.5]
    count = len(offsets) + 2
    bank, dmps, _ = make_banks(formulation, shared, count, True, seed=33)
    rng = np.random.default_rng(34)
    axes = rng.normal(size=(3, len(offsets)))
    axes /= np.linalg.norm(axes, axis=0)
    measured = quaternion.IDENTITY[:, np.newaxis]
    # q g* = Exp(offset axis) for g = Exp(offset axis)*, and two goals at exactly 180 degrees.
    goals = np.hstack([quaternion.conjugate(quaternion.exp_map(axes * offsets)),
                       [[0.0, -0.0], [0.0, 0.0], [0.6, -0.0], [-0.8, 1.0]]]).T
    velocity = rng.normal(size=(3, 1))
    for phases in (np.full(count, 1.0), np.full(count, 0.4), np.linspace(1.0, 0.4, count)):
        stepped = bank.advance(phases, measured, velocity, bank.goals_matrix(goals), DT)
        for k, dmp in enumerate(dmps):
            dmp.phase, dmp.scaled_angular_velocity = phases[k], velocity[:, 0].copy()
            orientation, angular_velocity = dmp.next_step(DT, goals[k], measured[:, 0])
            np.testing.assert_allclose(stepped[1][:, k], orientation, rtol=0, atol=1e-12)
            np.testing.assert_allclose(stepped[2][:, k] / bank.duration, angular_velocity,
                                       rtol=0, atol=1e-12)


@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_in_place_steps_from_one_velocity_match_advance_when_goals_change(formulation):
    """The fused step with one workspace (which keeps the start errors and the weights
    times `-e0` of the last goals) equals `advance` with a new workspace each step, as the
    goals move every few steps and another bank uses the workspace in between."""
    bank, _, goals = make_banks(formulation, False, 6, False, seed=35)
    other_bank, _, _ = make_banks(formulation, False, 6, False, seed=36)
    rng = np.random.default_rng(37)
    goals_4k = bank.goals_matrix(goals)
    workspace = bank.make_workspace()
    phase, orientations, velocity = bank.initial_state()
    expected = bank.initial_state()
    for step in range(40):
        if step % 7 == 6:
            goals_4k = bank.goals_matrix(random_rows(6, rng))
        if step == 20:
            other_bank.advance_into(*other_bank.initial_state()[:2], velocity[:, :1],
                                    goals_4k, DT, *other_bank.initial_state(), workspace)
        robot, eta = orientations[:, :1].copy(), velocity[:, 2:3].copy()
        bank.advance_into(phase, robot, eta, goals_4k, DT, phase, orientations, velocity,
                          workspace)
        expected = bank.advance(expected[0], robot, expected[2][:, 2:3], goals_4k, DT)
        for ours, theirs in zip((phase, orientations, velocity), expected):
            np.testing.assert_array_equal(ours, theirs)
