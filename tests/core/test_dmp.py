"""The DMP math (pbp_drake.core.dmp): learning, convergence, the vectorised bank, bad input."""

import numpy as np
import pytest
from scipy import integrate

from pbp_drake.core.dmp import FORMULATIONS, Dmp, DmpBankModel, DmpSettings, minimum_jerk
from pbp_drake.core.toy_scene import bent_path


def path_length(positions):
    return np.sum(np.linalg.norm(np.diff(positions, axis=0), axis=1))


def curvy_demonstration():
    """A 3-D demonstration, rest to rest, with a detour and a dimension that starts and ends
    at the same value."""
    times = np.linspace(0.0, 1.5, 300)
    u = times / times[-1]
    s = 10 * u**3 - 15 * u**4 + 6 * u**5
    positions = np.stack([s**2 * 0.8 + 0.1, 0.4 * np.sin(np.pi * s), 0.3 * s - 0.2 * s**3], 1)
    return times, positions


@pytest.mark.parametrize("formulation", FORMULATIONS)
@pytest.mark.parametrize("demonstration", [curvy_demonstration(),
                                           bent_path([0, 0], [1, 0], 0.3, 1.0)])
def test_learned_dmp_reproduces_its_demonstration(formulation, demonstration):
    times, positions = demonstration
    dmp = Dmp.from_demonstration(times, positions, DmpSettings(formulation=formulation))
    reproduced = dmp.rollout(times[1] - times[0])
    rmse = np.sqrt(np.mean(np.sum((reproduced - positions) ** 2, axis=1)))
    assert rmse < 0.01 * path_length(positions)


def all_kinds_of_dmp(formulation, start, goal):
    settings = DmpSettings(formulation=formulation)
    times, positions = curvy_demonstration()
    learned = Dmp.from_demonstration(times, positions, settings)
    learned.start, learned.goal = start, goal
    return [learned, Dmp.straight(start, goal, 1.0, settings),
            Dmp.straight(start, goal, 0.7, settings, profile="zero_forcing")]


@pytest.mark.slow
@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_every_dmp_converges_to_its_goal_from_any_start(formulation):
    rng = np.random.default_rng(7)
    for _ in range(5):
        start, goal = rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3)
        for dmp in all_kinds_of_dmp(formulation, start, goal):
            # Disturbed: started away from its start, moving in a random direction.
            dmp.reset(position=rng.uniform(-3, 3, 3), scaled_velocity=rng.uniform(-5, 5, 3))
            path = dmp.rollout(0.01, duration=5 * dmp.duration)
            assert np.linalg.norm(path[-1] - goal) < 1e-3


def test_straight_dmp_moves_on_the_line_and_arrives_on_time():
    dmp = Dmp.straight([0.0, 0.0], [1.0, 2.0], 1.0)
    path = dmp.rollout(0.01, duration=1.0)
    off_line = np.abs(path[:, 1] - 2.0 * path[:, 0])
    assert off_line.max() < 1e-9
    assert np.linalg.norm(path[-1] - [1.0, 2.0]) < 0.03
    _, expected = minimum_jerk([0.0, 0.0], [1.0, 2.0], 1.0, 101)
    assert np.abs(path - expected).max() < 0.05


@pytest.mark.slow
def test_bank_of_k_equals_k_single_dmps():
    rng = np.random.default_rng(3)
    settings = DmpSettings(basis_count=30)
    times, positions = curvy_demonstration()
    dmps = []
    for k in range(6):
        warped = positions * rng.uniform(0.5, 1.5, 3) + rng.uniform(-1, 1, 3)
        dmps.append(Dmp.from_demonstration(times, warped, settings))
    bank = DmpBankModel.from_dmps(dmps)
    goals = rng.uniform(-1, 1, (6, 3))
    goals_dk = bank.goals_matrix(goals)
    phase, _, scaled_velocity = bank.initial_state()
    robot_position = rng.uniform(-1, 1, 3)
    for step in range(120):
        robot_velocity = rng.uniform(-1, 1, 3)
        locked = 40 <= step < 50
        phase, bank_positions, scaled_velocity = bank.advance(
            phase, robot_position[:, None], scaled_velocity, goals_dk, 0.01, locked=locked,
            robot_velocity=robot_velocity)
        bank_positions, bank_velocities = bank_positions.T, scaled_velocity.T / bank.duration
        for k, dmp in enumerate(dmps):
            position, velocity = dmp.next_step(0.01, goals[k], robot_position, robot_velocity,
                                               phase_locked=locked)
            np.testing.assert_allclose(bank_positions[k], position, rtol=0, atol=1e-12)
            np.testing.assert_allclose(bank_velocities[k], velocity, rtol=0, atol=1e-12)
            assert phase[k] == pytest.approx(dmp.phase, abs=1e-15)
        # The robot follows the first DMP loosely: a stand-in for a lagging tracker.
        robot_position = 0.7 * robot_position + 0.3 * bank_positions[0]


@pytest.mark.slow
def test_shared_demonstration_bank_sends_one_shape_to_every_goal():
    times, positions = bent_path([0, 0], [1, 0], 0.3, 1.0)
    goals = np.array([[1.0, 0.0], [2.0, 0.0], [1.0, 1.0]])
    bank = DmpBankModel.from_demonstration(times, positions, goal_count=3)
    assert bank.shared_weights
    dt = times[1] - times[0]
    paths = bank.predict(*bank.initial_state(), bank.goals_matrix(goals), dt,
                         5 * (len(times) - 1))
    # The DMP sent to the demonstration's goal reproduces the demonstration...
    error = np.linalg.norm(paths[0, :len(times)] - positions, axis=1)
    assert np.sqrt(np.mean(error**2)) < 0.01 * path_length(positions)
    # ...and every DMP reaches its own goal, keeping the sideways detour (y scaling is off
    # in the demonstration, whose start and goal share y).
    np.testing.assert_allclose(paths[:, -1], goals, atol=1e-3)
    assert paths[1, :, 1].max() == pytest.approx(0.3, abs=0.02)


def test_phase_lock_holds_the_phase_and_follows_the_robot():
    bank = DmpBankModel.straight([0.0, 0.0], goal_count=2, duration=1.0)
    goals_dk = bank.goals_matrix([[1.0, 0.0], [0.0, 1.0]])
    phase, _, scaled_velocity = bank.initial_state()
    phase, _, scaled_velocity = bank.advance(phase, np.zeros((2, 1)), scaled_velocity,
                                             goals_dk, 0.01)
    locked_phase, positions, scaled_velocity = bank.advance(
        phase, np.array([[0.3], [-0.2]]), scaled_velocity, goals_dk, 0.01, locked=True,
        robot_velocity=[0.5, 0.1])
    np.testing.assert_array_equal(locked_phase, phase)
    np.testing.assert_allclose(positions.T, [[0.3, -0.2], [0.3, -0.2]])
    np.testing.assert_allclose(scaled_velocity.T / bank.duration, [[0.5, 0.1], [0.5, 0.1]])


@pytest.mark.parametrize("goals", [[], np.zeros((0, 2))])
def test_empty_goal_set_is_refused(goals):
    bank = DmpBankModel.straight([0.0, 0.0], goal_count=1, duration=1.0)
    with pytest.raises(ValueError, match="goals is empty"):
        bank.goals_matrix(goals)
    with pytest.raises(ValueError, match="at least one goal"):
        DmpBankModel.straight([0.0, 0.0], goal_count=0, duration=1.0)


@pytest.mark.parametrize("bad", [np.nan, np.inf, 1e200, -2e6])
def test_a_goal_that_is_not_a_position_is_refused_by_number(bad):
    bank = DmpBankModel.straight([0.0, 0.0], goal_count=2, duration=1.0)
    with pytest.raises(ValueError, match=r"goal 1 is \[.*\]: positions must be finite and "
                                         r"within ±1e\+06 m"):
        bank.goals_matrix([[0.5, 0.0], [bad, 0.0]])
    bank.goals_matrix([[0.5, 0.0], [-1e6, 1e6]])  # the bound itself is a position


def test_short_or_nan_demonstrations_are_refused():
    with pytest.raises(ValueError, match="2 samples; at least 3"):
        Dmp.from_demonstration([0.0, 1.0], [[0.0, 0.0], [1.0, 1.0]])
    times, positions = bent_path([0, 0], [1, 0], 0.3, 1.0)
    positions[17, 1] = np.nan
    with pytest.raises(ValueError, match="NaN or infinite at sample 17"):
        Dmp.from_demonstration(times, positions)


def test_unknown_formulation_is_refused():
    with pytest.raises(ValueError, match="formulation 'ijsperet' is unknown"):
        DmpSettings(formulation="ijsperet")


@pytest.mark.slow
@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_the_step_is_second_order_against_the_continuous_ode(formulation):
    """The step against SciPy's `solve_ivp` (DOP853, rtol = atol = 1e-12) on the continuous
    DMP: a 1-D minimum-jerk `Dmp.straight` reach from 0 to 1 m with tau = 1.5 s and the
    default settings (alpha_z 25, beta_z 25/4, alpha_x ln 100, 50 basis functions), from
    rest, the phase `x(t) = exp(-alpha_x t / tau)` continuous, compared at every step of a
    rollout over tau; the error is the largest position difference.

    The zero-order hold this step replaced (attractor held over each step, first order) was
    20.8 mm off at 30 Hz and 6.2 mm at 100 Hz; the first-order hold is 0.31 mm and 0.044 mm.
    """
    settings = DmpSettings(formulation=formulation)
    tau = 1.5
    dmp = Dmp.straight([0.0], [1.0], tau, settings)

    def derivative(t, state):
        attractor = dmp.attractor(np.exp(-settings.alpha_x * t / tau), dmp.goal)[0]
        position, z = state
        return [z / tau, (settings.stiffness * (attractor - position) - settings.damping * z)
                / tau]

    errors = {}
    for rate in (30, 100):
        dt = 1.0 / rate
        path = dmp.rollout(dt)[:, 0]
        times = dt * np.arange(path.size)
        exact = integrate.solve_ivp(derivative, (0.0, times[-1]), [0.0, 0.0], method="DOP853",
                                    t_eval=times, rtol=1e-12, atol=1e-12)
        assert exact.success
        assert exact.y[0, -1] == pytest.approx(1.0, abs=0.02)  # the whole reach
        errors[rate] = np.abs(path - exact.y[0]).max()
    assert errors[30] < 2e-3
    assert errors[100] < 1e-4
    # Second order: (100 / 30)^2 = 11 asymptotically; 7 here, a first-order step gives 3.3.
    assert errors[30] / errors[100] > 6


def test_a_goal_switch_keeps_the_velocity_of_the_followed_dmp():
    """The issue's minimal reproduction: two straight DMPs to (2, 1) and (2, -1), tau 10 s,
    30 Hz, the robot on DMP 0 for 3 s. Each DMP keeping its own velocity, selecting DMP 1
    makes the commanded velocity jump by 0.41 m/s; stepping every DMP from DMP 0's velocity
    leaves only the other attractor's pull over one step."""
    bank = DmpBankModel.straight([0.0, 0.0], goal_count=2, duration=10.0)
    goals_dk = bank.goals_matrix([[2.0, 1.0], [2.0, -1.0]])
    jumps = {}
    for followed in (None, 0):
        phase, positions, scaled_velocity = bank.initial_state()
        robot = positions[:, :1]
        for _ in range(100):
            phase, positions, scaled_velocity = bank.advance(
                phase, robot, scaled_velocity, goals_dk, 0.03, followed=followed)
            robot = positions[:, :1]  # the robot follows DMP 0 exactly
        velocities = scaled_velocity.T / bank.duration
        jumps[followed] = np.linalg.norm(velocities[1] - velocities[0])
    assert jumps[None] == pytest.approx(0.41, abs=0.02)
    assert jumps[0] < 0.05


@pytest.mark.parametrize("build, message", [
    (lambda: Dmp.straight([], [1.0], 1.0), "start is empty"),
    (lambda: Dmp.straight([0.0, 0.0], [1.0], 1.0), "goal has 1 numbers, expected 2"),
    (lambda: Dmp.straight([0.0, np.nan], [1.0, 1.0], 1.0), "start contains NaN"),
    (lambda: Dmp(np.zeros((50, 1)), [0.0], [1.0], 0.0),
     "duration must be positive and finite, got 0"),
    (lambda: Dmp.straight([0.0], [1.0], 0.0), "duration must be positive and finite, got 0"),
    (lambda: DmpBankModel.straight([0.0, 0.0], 2, -1.0),
     "duration must be positive and finite, got -1"),
    (lambda: Dmp.straight([0.0], [1.0], 1.0, profile="cubic"), "profile 'cubic' is unknown"),
    (lambda: Dmp(np.zeros((50, 3)), [0.0, 0.0], [1.0, 1.0], 1.0),
     "weights have 3 dimensions, expected 2"),
    (lambda: DmpSettings(alpha_z=0.0), "alpha_z must be positive, got 0"),
    (lambda: DmpSettings(beta_z=-1.0), "beta_z must be positive, got -1"),
    (lambda: DmpBankModel(np.zeros(50), [0.0], 1.0), r"weights must be \(N, D\) or \(K, N, D\)"),
    (lambda: DmpBankModel(np.zeros((40, 2)), [0.0, 0.0], 1.0),
     "weights have shape .*; the settings say 50 basis functions"),
    (lambda: DmpBankModel(np.zeros((50, 2)), np.zeros((3, 2)), 1.0, goal_count=2),
     r"starts must be \(2, 2\) or \(2,\)"),
    (lambda: DmpBankModel(np.zeros((50, 2)), [0.0, np.inf], 1.0), "starts contains NaN"),
    (lambda: DmpBankModel.from_dmps([]), "at least one DMP"),
    (lambda: DmpBankModel.from_dmps([Dmp.straight([0.0], [1.0], 1.0),
                                     Dmp.straight([0.0], [1.0], 2.0)]),
     "must share duration and settings"),
    (lambda: DmpBankModel.straight([0.0, 0.0], 2, 1.0).goals_matrix([1.0, 2.0, 3.0]),
     "goals has 3 numbers; the bank expects 2 goals of dimension 2"),
])
def test_a_model_that_cannot_be_built_is_refused_naming_the_field(build, message):
    with pytest.raises(ValueError, match=message):
        build()


@pytest.mark.parametrize("times, positions, message", [
    (np.linspace(0.0, 1.0, 5), np.zeros((5, 2, 1)), r"must be \(T, D\), got shape \(5, 2, 1\)"),
    (np.linspace(0.0, 1.0, 4), np.zeros((5, 2)), r"times have shape \(4,\), expected \(5,\)"),
    ([0.0, 0.5, 0.5, 1.0, 1.5], np.zeros((5, 2)), "finite and strictly increasing"),
])
def test_a_demonstration_of_the_wrong_shape_or_times_is_refused(times, positions, message):
    with pytest.raises(ValueError, match=message):
        Dmp.from_demonstration(times, positions)


def test_a_one_dimensional_demonstration_is_one_column():
    times = np.linspace(0.0, 1.0, 50)
    dmp = Dmp.from_demonstration(times, times**2)
    np.testing.assert_array_equal([dmp.start, dmp.goal], [[0.0], [1.0]])


def test_shared_weights_give_one_goal_per_start_row():
    weights = np.zeros((DmpSettings().basis_count, 2))
    assert DmpBankModel(weights, np.zeros((3, 2)), 1.0).goal_count == 3
    assert DmpBankModel(weights, np.zeros(2), 1.0).goal_count == 1


def test_a_lock_mask_of_no_goal_steps_as_no_lock():
    bank = DmpBankModel.straight([0.0, 0.0], goal_count=2, duration=1.0)
    goals_dk = bank.goals_matrix([[1.0, 0.0], [0.0, 1.0]])
    state = bank.advance(*bank.initial_state(), goals_dk, 0.01)
    free = bank.advance(*state, goals_dk, 0.01)
    masked = bank.advance(*state, goals_dk, 0.01, locked=[False, False])
    for free_part, masked_part in zip(free, masked):
        np.testing.assert_array_equal(masked_part, free_part)
    assert (free[0] < state[0]).all()  # the phases moved: nothing was locked


def test_affine_coefficients_are_refused_to_dmps_of_their_own_weights_or_starts():
    bank = DmpBankModel.from_dmps([Dmp.straight([0.0], [1.0], 1.0),
                                   Dmp.straight([0.5], [1.0], 1.0)])
    assert not bank.affine_in_goal
    with pytest.raises(ValueError, match="affine_coefficients needs DMPs that share weights "
                                         "and start"):
        bank.affine_coefficients(1.0, np.zeros((1, 1)), 0.01, bank.make_workspace())
    straight = DmpBankModel.straight([0.0], 2, 1.0)
    assert straight.affine_in_goal
    straight.affine_coefficients(1.0, np.zeros((1, 1)), 0.01, straight.make_workspace())


_DMP = Dmp.straight([0.0, 0.0], [1.0, 0.0], 1.0)
_BANK = DmpBankModel.straight([0.0, 0.0], 2, 1.0)


@pytest.mark.parametrize("build, message", [
    (lambda: Dmp.straight([0.0], [1.0], "1 s"), "duration must be positive and finite, got 1 s"),
    (lambda: Dmp.straight([0.0], [1.0], None), "duration must be positive and finite, got None"),
    (lambda: Dmp.straight([0.0], [1.0], 1.0, settings=None),
     "settings must be DmpSettings, got NoneType"),
    (lambda: Dmp(np.zeros((50, 1)), [0.0], [1.0], 1.0, settings="ijspeert"),
     "settings must be DmpSettings, got str"),
    (lambda: Dmp(np.full((50, 1), np.nan), [0.0], [1.0], 1.0),
     "weights contain NaN or infinite values"),
    (lambda: DmpBankModel(np.full((50, 1), np.inf), [0.0], 1.0),
     "weights contain NaN or infinite values"),
    (lambda: DmpBankModel.straight([0.0], 2, 1.0, settings=None),
     "settings must be DmpSettings, got NoneType"),
    (lambda: DmpBankModel.straight([0.0], np.nan, 1.0), "goal_count must be an integer >= 1"),
    (lambda: DmpBankModel.straight([0.0], 1.5, 1.0), "goal_count must be an integer >= 1"),
    (lambda: DmpBankModel.straight([0.0], None, 1.0),
     "goal_count must be an integer >= 1, got None"),
    (lambda: DmpSettings(basis_count=np.nan), "basis_count must be a whole number, got nan"),
    (lambda: DmpSettings(basis_count=None), "basis_count must be a whole number, got None"),
    (lambda: DmpSettings(alpha_z=np.inf), "alpha_z must be finite, got inf"),
    (lambda: DmpSettings(alpha_x="fast"), "alpha_x must be a number, got 'fast'"),
    (lambda: minimum_jerk([0.0], [1.0], 0.0), "duration must be positive and finite, got 0"),
    (lambda: minimum_jerk([0.0], [1.0], np.nan), "duration must be positive and finite"),
    (lambda: minimum_jerk([0.0], [1.0], 1.0, sample_count=1),
     "sample_count must be a whole number >= 2, got 1"),
    (lambda: minimum_jerk([0.0], [1.0], 1.0, sample_count=np.inf),
     "sample_count must be a whole number >= 2, got inf"),
    (lambda: _DMP.rollout(0.0), "dt must be positive and finite, got 0"),
    (lambda: _DMP.rollout(-0.01), "dt must be positive and finite, got -0.01"),
    (lambda: _DMP.rollout(0.01, duration=np.inf), "duration must be positive and finite"),
    (lambda: _DMP.next_step(np.nan), "dt must be positive and finite, got nan"),
    (lambda: _DMP.next_step(0.01, robot_velocity=[np.nan, 0.0], phase_locked=True),
     "robot_velocity contains NaN"),
    (lambda: _BANK.predict(*_BANK.initial_state(), _BANK.goals_matrix([[1.0, 0.0]] * 2), 0.01,
                           -1), "steps must be a whole number >= 0, got -1"),
    (lambda: _BANK.predict(*_BANK.initial_state(), _BANK.goals_matrix([[1.0, 0.0]] * 2), 0.01,
                           np.inf), "steps must be a whole number >= 0, got inf"),
    (lambda: _BANK.predict(*_BANK.initial_state(), _BANK.goals_matrix([[1.0, 0.0]] * 2), 0.0,
                           10), "dt must be positive and finite, got 0"),
])
def test_a_bad_argument_is_refused_naming_it(build, message):
    with pytest.raises(ValueError, match=message):
        build()


def test_a_dmp_keeps_its_own_settings():
    """Changing the settings a DMP was made with, or the `settings` it gives, changes neither
    that DMP nor, through the shared default, the DMPs made after it."""
    settings = DmpSettings()
    times, positions = minimum_jerk([0.0, 0.0], [1.0, 0.5], 1.0)
    dmp = Dmp.from_demonstration(times, positions, settings)
    path = dmp.rollout(0.01)
    settings.alpha_x = 1.0
    dmp.settings.alpha_z = 5.0
    assert np.array_equal(dmp.rollout(0.01), path)
    defaulted = Dmp.straight([0.0], [1.0], 1.0)
    defaulted.settings.alpha_x = 1.0
    assert Dmp.straight([0.0], [1.0], 1.0).settings == DmpSettings()


@pytest.mark.parametrize("state, message", [
    ({"position": [0.1, 0.0, 0.0]}, "position has 3 numbers, expected 2"),
    ({"scaled_velocity": [0.1, 0.0, 5.0]}, "scaled_velocity has 3 numbers, expected 2"),
    ({"scaled_velocity": [np.nan, 0.0]}, "scaled_velocity contains NaN"),
])
def test_a_reset_state_that_is_not_the_dmps_is_refused_naming_it(state, message):
    """A third velocity was ignored without a word, a NaN one stepped into NaN positions,
    and a third position ended in an IndexError at the next step."""
    dmp = Dmp.straight([0.0, 0.0], [1.0, 0.0], 1.0)
    with pytest.raises(ValueError, match=message):
        dmp.reset(**state)


def test_a_whole_float_basis_count_fits_as_its_integer():
    """`basis_count=10.0` (a number read from a file or computed) fits the same DMP as 10."""
    times, positions = minimum_jerk([0.0, 0.0], [1.0, 0.5], 1.0)
    fitted = [Dmp.from_demonstration(times, positions, DmpSettings(basis_count=count))
              for count in (10.0, 10)]
    assert np.array_equal(fitted[0].rollout(0.01), fitted[1].rollout(0.01))
