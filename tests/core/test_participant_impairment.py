"""The virtual participant's impairments in NumPy (`pbp_drake.core.participant_impairment`,
and the grasping task's participant under them): the motor noise has the documented spread
and correlation time and comes from the seed alone, the wrong first choices come at the
documented rate and never name the target, and unusable settings are refused by name."""

import dataclasses
import math

import numpy as np
import pytest

from pbp_drake.core.grasp_task import (
    approach_direction, side_grasp_orientation, top_grasp_orientation)
from pbp_drake.core.participant_grasp import (
    GraspParticipant, GraspParticipantParams, ParticipantMemory, turn_toward)
from pbp_drake.core.participant_impairment import (
    PARTICIPANT_CONDITIONS, ParticipantImpairment, condition, delay_ticks, first_choice,
    initial_motor_noise, next_motor_noise)
from pbp_drake.core.participant_serving import NO_INTENT, ServingMemory, update_own_motion

PERIOD = 0.03
SCALES = np.array([0.036, 0.036, 0.24])  # 0.3 times a speed of 0.12 m/s and 0.8 rad/s


def noise_series(impairment, seed, ticks, scales=SCALES):
    noise = initial_motor_noise(seed, scales)
    series = []
    for tick in range(ticks):
        noise = next_motor_noise(impairment, PERIOD, seed, tick, noise, scales)
        series.append(noise)
    return np.array(series)


@pytest.mark.slow
def test_white_motor_noise_has_the_documented_spread_and_no_memory():
    series = noise_series(ParticipantImpairment(command_noise=0.3, command_noise_time=0.0),
                          seed=3, ticks=6000)
    assert np.allclose(series.mean(axis=0), 0.0, atol=0.05 * SCALES)
    assert np.allclose(series.std(axis=0), SCALES, rtol=0.05)
    lag_one = [np.corrcoef(series[1:, axis], series[:-1, axis])[0, 1] for axis in range(3)]
    assert np.all(np.abs(lag_one) < 0.05)


@pytest.mark.slow
def test_correlated_motor_noise_keeps_its_spread_and_lasts_its_correlation_time():
    impairment = ParticipantImpairment(command_noise=0.3, command_noise_time=0.6)
    series = noise_series(impairment, seed=11, ticks=20000)
    # 20,000 ticks are 600 s, about 500 correlation times: the spread within 10 %.
    assert np.allclose(series.std(axis=0), SCALES, rtol=0.1)
    lag = int(round(0.6 / PERIOD))
    correlation = np.mean([np.corrcoef(series[lag:, axis], series[:-lag, axis])[0, 1]
                           for axis in range(3)])
    assert correlation == pytest.approx(math.exp(-1.0), abs=0.08)
    # It is as spread from the first tick as later on (it starts from its stationary law).
    starts = np.array([noise_series(impairment, seed, 1)[0] for seed in range(400)])
    assert np.allclose(starts.std(axis=0), SCALES, rtol=0.12)


def test_motor_noise_is_a_function_of_the_seed_and_tick_alone():
    impairment = ParticipantImpairment(command_noise=0.3)
    first, again = noise_series(impairment, 7, 200), noise_series(impairment, 7, 200)
    assert np.array_equal(first, again)
    assert not np.allclose(first, noise_series(impairment, 8, 200))
    # Its level only scales it: a quieter participant makes the same motions, smaller.
    quiet = noise_series(impairment, 7, 200, scales=SCALES / 3)
    assert np.allclose(quiet, first / 3)


@pytest.mark.slow
def test_the_mistaken_participant_errs_at_its_rate_and_never_names_the_target():
    impairment = ParticipantImpairment(mistake_probability=0.2)
    choices = np.array([[first_choice(impairment, seed, number, 1, 4) for number in range(3)]
                        for seed in range(2000)])
    wrong = choices != 1
    assert wrong.mean() == pytest.approx(0.2, abs=0.02)
    # Each of the three other objects about as likely.
    counts = np.bincount(choices[wrong], minlength=4)
    assert counts[1] == 0
    assert np.all(np.abs(counts[[0, 2, 3]] / wrong.sum() - 1 / 3) < 0.05)
    # The same seed and target number, the same choice: one seed errs alike under every
    # method.
    assert [first_choice(impairment, 5, n, 1, 4) for n in range(3)] == list(choices[5])


def test_a_participant_without_mistakes_or_with_one_object_never_errs():
    assert all(first_choice(ParticipantImpairment(), seed, 0, 2, 4) == 2
               for seed in range(200))
    always = ParticipantImpairment(mistake_probability=1.0)
    assert all(first_choice(always, seed, 0, 0, 1) == 0 for seed in range(50))
    assert all(first_choice(always, seed, 0, 0, 2) == 1 for seed in range(50))


def test_delays_round_to_whole_ticks():
    assert delay_ticks(0.3, PERIOD) == 10
    assert delay_ticks(0.0, PERIOD) == 0
    assert delay_ticks(0.31, PERIOD) == 10


@pytest.mark.parametrize("field, value, words", [
    ("command_noise", float("nan"), "command_noise must be finite and not negative"),
    ("command_noise", -0.1, "command_noise must be finite and not negative"),
    ("command_noise_time", float("inf"), "command_noise_time must be finite"),
    ("command_delay", -0.2, "command_delay must be finite and not negative"),
    ("command_delay", 60.0, "command_delay 60.0 s is longer than any person's reaction"),
    ("mistake_probability", 1.5, "mistake_probability must be a probability, 0 to 1"),
    ("mistake_probability", -0.01, "mistake_probability must be a probability"),
    ("mistake_probability", float("nan"), "mistake_probability must be a probability"),
    ("mistake_time", -1.0, "mistake_time must be finite and not negative"),
])
def test_unusable_settings_are_refused_by_name(field, value, words):
    impairment = dataclasses.replace(ParticipantImpairment(), **{field: value})
    assert words in impairment.problem()
    with pytest.raises(ValueError, match=words.replace("(", r"\(")):
        impairment.validate()


def test_the_defaults_and_the_conditions_are_usable_and_each_one_impairment():
    assert ParticipantImpairment().problem() is None
    unimpaired = ParticipantImpairment()
    acting = {"noisy": {"command_noise"}, "late": {"command_delay"},
              "mistaken": {"mistake_probability"}}
    for name, impairment in PARTICIPANT_CONDITIONS.items():
        assert impairment.problem() is None
        levels = {"command_noise", "command_delay", "mistake_probability"}
        assert {field for field in levels
                if getattr(impairment, field) != getattr(unimpaired, field)} == acting[name]
    # `condition` hands out a copy: changing it leaves the named level alone.
    late = condition("late")
    late.command_delay = 5.0
    assert PARTICIPANT_CONDITIONS["late"].command_delay == 0.3
    with pytest.raises(ValueError, match="unknown; use one of noisy, late, mistaken"):
        condition("sleepy")


@pytest.mark.slow
def test_the_motor_noise_draws_apart_from_the_calibrated_participants_noise():
    # The calibrated participant draws its direction and speed noise from (seed, tick); no
    # tick of the motor noise may repeat one of those draws (NumPy's seeds ignore trailing
    # zeros, so a careless key like [seed, 1, 0] draws what [seed, 1] draws).
    white = ParticipantImpairment(command_noise=1.0, command_noise_time=0.0)
    seeds, ticks = range(200), range(6)
    motor = np.array([[next_motor_noise(white, PERIOD, seed, tick, [0.0], np.ones(1))[0]
                       for tick in ticks] for seed in seeds])
    calibrated = np.array([[np.random.default_rng([seed, tick]).normal() for tick in ticks]
                           for seed in seeds])
    start = np.array([initial_motor_noise(seed, np.ones(1))[0] for seed in seeds])
    for tick in ticks:
        assert abs(np.corrcoef(start, motor[:, tick])[0, 1]) < 0.3
        for other in ticks:
            assert abs(np.corrcoef(motor[:, tick], calibrated[:, other])[0, 1]) < 0.3


# ---------------------------------------------------------------------------------------------
# The grasping task's participant (`pbp_drake.core.participant_grasp`)


def grasp_scene():
    positions = np.array([[1.6, 0.6, 0.75], [1.6, -0.6, 0.75]])
    orientations = np.array([side_grasp_orientation(0.8), top_grasp_orientation(1.0)])
    return positions, orientations


def grasp_twists(impairment, forward_key=True, seconds=2.5, selected=NO_INTENT, noise=None):
    """The twists toward object 1 of a participant whose hand stays where it is (as under
    teleop by default: the forward key enabled, no intent shown)."""
    positions, orientations = grasp_scene()
    params = GraspParticipantParams(direction_noise=0.0, speed_noise=0.0,
                                    impairment=impairment)
    participant = GraspParticipant.create(params, 0.12, positions, orientations, seed=3)
    memory, serving, own_motion, twists = ParticipantMemory(), ServingMemory(), np.zeros(3), []
    hand, level = np.array([0.5, 0.0, 0.7]), side_grasp_orientation(0.0)
    for tick in range(int(round(seconds / PERIOD))):
        twist, active, memory, serving = participant.step(
            memory, serving, tick * PERIOD, tick, hand, level, np.zeros(3), own_motion, 1,
            selected, forward_key, PERIOD, None if noise is None else noise[tick])
        own_motion = update_own_motion(params, PERIOD, own_motion, np.zeros(3),
                                       twist[:3] if active else np.zeros(3))
        twists.append(twist)
    return np.array(twists), hand, level


@pytest.mark.slow
def test_the_mistaken_grasp_participant_heads_for_the_other_grasp_pose_then_the_target():
    positions, orientations = grasp_scene()
    twists, hand, level = grasp_twists(
        ParticipantImpairment(mistake_probability=1.0, mistake_time=0.9))
    # It notices the target (object 1) after its reaction_delay, then heads for object 0's
    # grasp pose, position and orientation, for 0.9 s; the hand still, it takes over once
    # it has watched it `serve_patience`.
    defaults = GraspParticipantParams()
    patience = round(defaults.serve_patience / PERIOD)
    known = int(np.ceil(defaults.reaction_delay / PERIOD - 1e-9))
    noticed, corrected = known + patience, known + int(round(0.9 / PERIOD))
    assert not twists[:noticed].any()

    def heads_for(twist, index):
        offset = positions[index] - hand
        turn = turn_toward(GraspParticipantParams(), level, orientations[index])
        return (twist[:3] @ offset / (np.linalg.norm(twist[:3]) * np.linalg.norm(offset))
                > 0.999 and np.allclose(twist[3:], turn))

    assert all(heads_for(twist, 0) for twist in twists[noticed:corrected])
    assert all(heads_for(twist, 1) for twist in twists[corrected + 1:])
    unimpaired, _, _ = grasp_twists(ParticipantImpairment())
    assert all(heads_for(twist, 1) for twist in unimpaired[noticed:])


@pytest.mark.slow
def test_the_noisy_grasp_participant_adds_its_noise_while_it_acts_and_never_forward():
    ticks = int(round(2.5 / PERIOD))
    noise = np.random.default_rng(0).normal(0.0, 0.05, (ticks, 6))
    clean, _, _ = grasp_twists(ParticipantImpairment())
    noisy, _, level = grasp_twists(ParticipantImpairment(command_noise=0.3), noise=noise)
    acting = clean.any(axis=1)
    assert np.allclose(noisy[acting], clean[acting] + noise[acting])
    assert not noisy[~acting].any()
    # Assisting (the estimate names object 0), the forward key stays disabled.
    assisted, _, _ = grasp_twists(ParticipantImpairment(command_noise=0.3),
                                  forward_key=False, selected=0, noise=noise)
    assert assisted.any()
    assert np.all(assisted[:, :3] @ approach_direction(level) <= 1e-12)
