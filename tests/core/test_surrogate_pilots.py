"""The surrogate pilots' math against their sources' definitions (docs/concepts/pilots.md):
the noisy pilot corrupts a share eps of the ticks with keys drawn uniformly over the
enabled states; the laggy pilot repeats a share p of them, p converted from the sources'
50 Hz to our tick; HOP's simulated user is u = gain (goal - hand) clipped to max_speed; the
population's draws stay in their ranges, follow their parameters' levels and come back
from the seed."""

import dataclasses

import numpy as np
import pytest

from pbp_drake.core.pilot_population import (
    LEVEL_RAISES, ParticipantPopulationParams, drawn_participant, drawn_values,
    population_levels, population_problem)
from pbp_drake.core.surrogate_pilots import (
    ProportionalPilotParams, grasp_key_command, grasp_proportional_command, key_state,
    lag_per_tick, laggy_draw, noisy_draw, proportional_velocity, reach_key_command,
    reach_proportional_command)

TICKS = 20_000


def within_binomial(count, trials, probability, sigmas=5.0):
    """Whether `count` successes of `trials` lie within `sigmas` standard deviations of
    the binomial's mean."""
    spread = np.sqrt(trials * probability * (1.0 - probability))
    return abs(count - trials * probability) <= sigmas * spread


@pytest.mark.slow
@pytest.mark.parametrize("eps", [0.3, 0.6])
def test_the_noisy_pilot_corrupts_a_share_eps_of_the_ticks(eps):
    corrupted = sum(noisy_draw(7, tick, eps, 3, True)[0] for tick in range(TICKS))
    assert within_binomial(corrupted, TICKS, eps)


@pytest.mark.slow
@pytest.mark.parametrize("forward_enabled, states", [(True, (-1.0, 0.0, 1.0)),
                                                     (False, (-1.0, 0.0))])
def test_corrupted_keys_are_uniform_over_the_enabled_states(forward_enabled, states):
    keys = np.array([noisy_draw(11, tick, 1.0, 4, forward_enabled)[1]
                     for tick in range(6000)])
    # The forward/back axis: its enabled states only, each as often.
    for state in states:
        assert within_binomial(np.sum(keys[:, 0] == state), len(keys), 1 / len(states))
    assert set(np.unique(keys[:, 0])) == set(states)
    # Every other axis: -1, 0, +1, each a third of the time.
    for axis in range(1, 4):
        for state in (-1.0, 0.0, 1.0):
            assert within_binomial(np.sum(keys[:, axis] == state), len(keys), 1 / 3)


def test_one_seed_draws_the_same_keys_whatever_keys_the_method_enables():
    for tick in range(200):
        enabled = noisy_draw(3, tick, 0.3, 3, True)
        disabled = noisy_draw(3, tick, 0.3, 3, False)
        assert enabled[0] == disabled[0]
        np.testing.assert_array_equal(enabled[1][1:], disabled[1][1:])
        # Where forward is enabled and drawn, the same number gives none or back without it.
        assert disabled[1][0] in (-1.0, 0.0)


def test_key_state_splits_the_unit_interval_evenly():
    np.testing.assert_array_equal(key_state([0.1, 0.5, 0.9], True), [-1.0, 0.0, 1.0])
    np.testing.assert_array_equal(key_state([0.4, 0.6, 0.9], False), [-1.0, 0.0, 1.0])


def test_reach_keys_combine_into_one_direction_at_the_operator_speed():
    # Forward and left at heading 0: diagonally at 0.1 m/s; the turn key at 0.8 rad/s.
    command, active = reach_key_command([1.0, 1.0, -1.0], 0.0, 0.1, 0.8)
    np.testing.assert_allclose(command, [0.1 / np.sqrt(2), 0.1 / np.sqrt(2), 0.0, -0.8])
    assert active
    # Forward at heading 90 degrees moves along +y; up (vertical keys) adds to it.
    command, _ = reach_key_command([1.0, 0.0, 1.0, 0.0], np.pi / 2, 0.1, 0.8)
    np.testing.assert_allclose(command, [0.0, 0.1 / np.sqrt(2), 0.1 / np.sqrt(2), 0.0],
                               atol=1e-15)
    command, active = reach_key_command([0.0, 0.0, 0.0], 0.3, 0.1, 0.8)
    assert not active and not np.any(command)


# The hand's approach axis z_H along world +x: a quarter turn about +y.
APPROACH_X = np.array([np.cos(np.pi / 4), 0.0, np.sin(np.pi / 4), 0.0])


def test_grasp_keys_lose_the_forward_push_without_the_forward_key():
    forward = [1.0, 0, 0, 0, 0, 0]
    twist, active = grasp_key_command(forward, APPROACH_X, 0.1, 0.8, True)
    np.testing.assert_allclose(twist, [0.1, 0, 0, 0, 0, 0], atol=1e-12)
    assert active
    twist, active = grasp_key_command(forward, APPROACH_X, 0.1, 0.8, False)
    np.testing.assert_allclose(twist, np.zeros(6), atol=1e-12)
    assert not active
    # Back and a yaw still work.
    twist, active = grasp_key_command([-1.0, 0, 0, 1.0, 0, 0], APPROACH_X, 0.1, 0.8, False)
    np.testing.assert_allclose(twist, [-0.1, 0, 0, 0, 0, 0.8], atol=1e-12)
    assert active


@pytest.mark.parametrize("p, period, expected", [(0.85, 0.03, 0.85 ** 1.5),
                                                 (0.8, 0.02, 0.8), (0.85, 0.06, 0.85 ** 3)])
def test_the_lag_is_converted_from_50_hz_to_our_tick(p, period, expected):
    assert lag_per_tick(p, period) == pytest.approx(expected, rel=1e-12)
    # A held output survives one second with the source's probability p ** 50.
    assert lag_per_tick(p, period) ** (1.0 / period) == pytest.approx(p ** 50, rel=1e-9)


@pytest.mark.slow
def test_the_laggy_pilot_repeats_a_share_p_of_the_ticks():
    p_tick = lag_per_tick(0.85, 0.03)
    repeated = sum(laggy_draw(5, tick, p_tick) for tick in range(TICKS))
    assert within_binomial(repeated, TICKS, p_tick)


PROPORTIONAL = ProportionalPilotParams(gain=10.0, max_speed=0.25)


@pytest.mark.parametrize("goal, expected", [
    ([0.01, 0.0], [0.1, 0.0]),           # 10 /s times 1 cm, under the clip
    ([1.0, 0.0], [0.25, 0.0]),           # clipped to 0.25 m/s
    ([0.3, 0.4], [0.15, 0.2]),           # 5 m/s along (0.6, 0.8), clipped
    ([0.015, -0.02], [0.15, -0.2]),      # 0.25 m/s exactly: not clipped
])
def test_hops_simulated_user_is_a_clipped_proportional_law(goal, expected):
    velocity = proportional_velocity(PROPORTIONAL, [0.0, 0.0], goal, 0.25)
    np.testing.assert_allclose(velocity, expected, rtol=1e-12)


def test_hops_simulated_user_in_the_reaching_task():
    hand, goal = np.array([1.0, 0.0, 0.7]), np.array([1.0 + 0.003, 0.004, 0.75])
    command, active = reach_proportional_command(PROPORTIONAL, hand, 0.0, goal, 0.25,
                                                 vertical=False, forward_enabled=True)
    np.testing.assert_allclose(command, [0.03, 0.04, 0.0, 0.0], rtol=1e-12)
    assert active
    # Forward disabled and the hand facing +x: only the sideways part is left.
    command, _ = reach_proportional_command(PROPORTIONAL, hand, 0.0, goal, 0.25,
                                            vertical=False, forward_enabled=False)
    np.testing.assert_allclose(command, [0.0, 0.04, 0.0, 0.0], atol=1e-15)
    # With vertical keys it moves up too: (3, 4, 50) mm -> clipped to 0.25 m/s.
    command, _ = reach_proportional_command(PROPORTIONAL, hand, 0.0, goal, 0.25,
                                            vertical=True, forward_enabled=True)
    offset = goal - hand
    np.testing.assert_allclose(command[:3], 0.25 * offset / np.linalg.norm(offset))
    # Straight ahead with forward disabled: nothing it may press.
    command, active = reach_proportional_command(PROPORTIONAL, hand, 0.0, hand + [0.5, 0, 0],
                                                 0.25, vertical=False, forward_enabled=False)
    assert not active and not np.any(command)


def test_hops_simulated_user_in_the_grasping_task_translates_only():
    twist, active = grasp_proportional_command(PROPORTIONAL, [1.0, 0.0, 0.7], APPROACH_X,
                                               [1.01, 0.02, 0.7], 0.25, True)
    # 10 /s times (1, 2) cm: 0.22 m/s, under the clip.
    np.testing.assert_allclose(twist[:3], [0.1, 0.2, 0.0], rtol=1e-12)
    np.testing.assert_array_equal(twist[3:], 0.0)
    assert active
    twist, _ = grasp_proportional_command(PROPORTIONAL, [1.0, 0.0, 0.7], APPROACH_X,
                                          [1.01, 0.02, 0.7], 0.25, False)
    np.testing.assert_allclose(twist[:3], [0.0, 0.2, 0.0], atol=1e-12)


POPULATION = ParticipantPopulationParams()


def test_the_population_draws_within_its_ranges_and_by_its_levels():
    for seed in range(300):
        levels = population_levels(seed)
        values = drawn_values(POPULATION, seed)
        for name, (parameter, raises) in LEVEL_RAISES.items():
            low, high = getattr(POPULATION, name)
            assert low <= values[name] <= high
            level = levels[parameter] if raises else 1.0 - levels[parameter]
            assert values[name] == pytest.approx(low + level * (high - low))


@pytest.mark.slow
def test_the_levels_are_uniform_over_seeds():
    levels = np.array([list(population_levels(seed).values()) for seed in range(4000)])
    for column in levels.T:
        assert within_binomial(np.sum(column < 0.5), len(column), 0.5)
        assert within_binomial(np.sum(column < 0.1), len(column), 0.1)


def test_one_seed_gives_one_participant_and_the_speed_is_a_factor():
    population = dataclasses.replace(POPULATION, speed_factor=[0.5, 1.5])
    first = drawn_participant(population, 42, operator_speed=0.2)
    assert first == drawn_participant(population, 42, operator_speed=0.2)
    assert first != drawn_participant(population, 43, operator_speed=0.2)
    factor = 0.5 + population_levels(42)["speed"]
    assert first.speed == pytest.approx(factor * 0.2)
    # Fields the population does not draw are the base participant's.
    assert first.slow_radius == population.participant.slow_radius


@pytest.mark.parametrize("field, value, words", [
    ("insist_time", [2.0, 1.0], "insist_time [2.0, 1.0] is reversed"),
    ("reaction_delay", [0.1, float("nan")], "reaction_delay"),
    ("speed_factor", [0.0, 1.0], "speed_factor [0.0, 1.0] must be positive"),
    ("direction_noise", [0.1], "needs two numbers"),
    ("serve_patience", [-0.1, 0.2], "must be not negative"),
])
def test_a_population_range_that_cannot_be_used_is_named(field, value, words):
    problem = population_problem(dataclasses.replace(POPULATION, **{field: value}))
    assert problem is not None and words in problem
    assert population_problem(POPULATION) is None


def test_a_dead_zone_presses_no_key_for_a_slow_command():
    slow = dataclasses.replace(PROPORTIONAL, dead_zone=0.05)
    hand = np.array([1.0, 0.0, 0.7])
    # 10 /s times 4 mm: 0.04 m/s, inside the dead zone; 6 mm: 0.06 m/s, outside.
    command, active = reach_proportional_command(slow, hand, 0.0, hand + [0.0, 0.004, 0.0],
                                                 0.25, vertical=False, forward_enabled=True)
    assert not active and not np.any(command)
    command, active = reach_proportional_command(slow, hand, 0.0, hand + [0.0, 0.006, 0.0],
                                                 0.25, vertical=False, forward_enabled=True)
    assert active
    np.testing.assert_allclose(command, [0.0, 0.06, 0.0, 0.0], atol=1e-15)
