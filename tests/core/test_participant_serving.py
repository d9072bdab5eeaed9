"""When the virtual participant acts (`pbp_drake.core.participant_serving`), the one rule
under every method, with expectations worked out by hand from its definitions: it acts at
once while the robot shows another object; hands off, it watches `serve_patience` a robot
that does not bring the hand to the target at `serve_speed_fraction` of its own preferred
speed and then takes over for `hold_time` at least; acting, it lets go once the robot shows
the target or, where the robot shows nothing, once the robot's own motion would serve."""

import numpy as np
import pytest

from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_serving import (
    NO_INTENT, ServingMemory, preferred_speed, robot_pulls, robot_serves, serving_step,
    update_own_motion)

# The calibrated rule: serve_speed_fraction 0.5, serve_patience 0.25 s, hold_time 0.5 s,
# slow_radius 0.15 m; at 50 ms a tick it watches 5 ticks and holds 10.
PARAMS = VirtualParticipantParams()
PERIOD = 0.05
PATIENCE, HOLD = 5, 10
SPEED = 0.12
TARGET, OTHER = 0, 1
# The target 0.3 m ahead (+x): beyond slow_radius, so the preferred speed there is SPEED
# and the robot serves from 0.06 m/s toward it.
OFFSET = np.array([0.3, 0.0])
STILL = np.zeros(2)
SERVING = np.array([0.0601, 0.0])


def test_the_calibration_is_the_one_these_expectations_use():
    assert (PARAMS.serve_speed_fraction, PARAMS.serve_patience, PARAMS.hold_time,
            PARAMS.slow_radius) == (0.5, 0.25, 0.5, 0.15)


def watch(ticks, memory=ServingMemory(), shown=NO_INTENT, velocity=STILL, own_motion=STILL,
          offset=OFFSET, period=PERIOD):
    """`(acts, memories)` of `ticks` ticks with the inputs held."""
    acts, memories = [], []
    for _ in range(ticks):
        act, memory = serving_step(PARAMS, SPEED, period, memory, shown, TARGET, offset,
                                   velocity, own_motion)
        acts.append(act)
        memories.append(memory)
    return acts, memories


@pytest.mark.parametrize("memory", [
    ServingMemory(),
    ServingMemory(unserved_ticks=3),
    ServingMemory(acting=True, took_over=True, hold_ticks=4)])
def test_it_acts_at_once_when_the_robot_shows_another_object(memory):
    # However well the hand moves toward the target: the robot says it is going elsewhere.
    act, after = serving_step(PARAMS, SPEED, PERIOD, memory, OTHER, TARGET, OFFSET,
                              np.array([SPEED, 0.0]), np.array([SPEED, 0.0]))
    assert act and after == ServingMemory(acting=True)


def test_it_lets_go_at_once_when_the_robot_then_shows_the_target():
    # Acting because the robot meant another object (no hold): the hand still, it lets go
    # as soon as the robot shows the target, and starts watching afresh.
    acts, memories = watch(1, ServingMemory(acting=True), shown=TARGET)
    assert acts == [False] and memories == [ServingMemory()]


@pytest.mark.parametrize("velocity", [
    STILL,                      # the robot does nothing
    np.array([-0.06, 0.0]),     # it moves the hand away from the target
    np.array([0.0, SPEED]),     # across, at full speed: no closer
    np.array([0.0599, 0.05]),   # toward it, a hair slower than half the preferred speed
], ids=["still", "away", "across", "too-slow"])
@pytest.mark.parametrize("shown", [NO_INTENT, TARGET])
def test_hands_off_it_waits_its_patience_then_takes_over(velocity, shown):
    acts, memories = watch(PATIENCE + 1, shown=shown, velocity=velocity)
    assert acts == [False] * PATIENCE + [True]
    assert [memory.unserved_ticks for memory in memories[:PATIENCE]] == [1, 2, 3, 4, 5]
    assert memories[-1] == ServingMemory(acting=True, took_over=True, hold_ticks=HOLD)


def test_its_patience_is_rounded_to_whole_ticks():
    # 0.25 s at 30 ms a tick: 8.33 ticks, so it takes over on the 9th.
    acts, _ = watch(9, period=0.03)
    assert acts == [False] * 8 + [True]


@pytest.mark.parametrize("velocity, offset", [
    (SERVING, OFFSET),                          # 0.0601 >= 0.5 * 0.12
    (np.array([0.0601, -0.3]), OFFSET),         # its part toward the target is what counts
    (np.array([0.0301, 0.0]), np.array([0.075, 0.0])),  # half slow_radius: 0.5 * 0.06
    (np.array([0.0, 0.0, 0.0601]), np.array([0.0, 0.0, 0.3])),  # straight up, in 3-D
], ids=["ahead", "with-a-side-part", "slowing-near", "up"])
def test_it_never_acts_while_the_hand_closes_in_fast_enough(velocity, offset):
    for shown in (NO_INTENT, TARGET):
        acts, memories = watch(4 * PATIENCE, shown=shown, velocity=velocity, offset=offset)
        assert not any(acts)
        assert all(memory == ServingMemory() for memory in memories)


def test_the_speed_it_needs_slows_within_slow_radius():
    assert preferred_speed(PARAMS, SPEED, 0.3) == SPEED
    assert preferred_speed(PARAMS, SPEED, 0.075) == pytest.approx(0.06)
    # Near the target half its slowed speed serves, a little less does not.
    near = np.array([0.075, 0.0])
    assert robot_serves(PARAMS, SPEED, [0.0301, 0.0], near)
    assert not robot_serves(PARAMS, SPEED, [0.0299, 0.0], near)
    # On the target, anything serves.
    assert robot_serves(PARAMS, SPEED, [-1.0, 0.0], [0.0, 0.0])


def test_a_tick_that_serves_starts_the_watch_again():
    acts, memories = watch(3)
    acts2, memories2 = watch(1, memories[-1], velocity=SERVING)
    assert memories2 == [ServingMemory()] and acts2 == [False]
    acts3, _ = watch(PATIENCE + 1, memories2[-1])
    assert not any(acts + acts2) and acts3 == [False] * PATIENCE + [True]


@pytest.mark.parametrize("shown, own_motion", [(TARGET, STILL), (NO_INTENT, SERVING)])
def test_once_it_has_taken_over_it_keeps_control_its_hold_time(shown, own_motion):
    # Though the robot then shows the target, or its own motion would serve it.
    taken = ServingMemory(acting=True, took_over=True, hold_ticks=HOLD)
    acts, memories = watch(HOLD + 1, taken, shown=shown, own_motion=own_motion)
    assert acts == [True] * HOLD + [False]
    assert [memory.hold_ticks for memory in memories[:HOLD]] == list(range(HOLD - 1, -1, -1))
    assert memories[-1] == ServingMemory()


@pytest.mark.parametrize("own_motion", [STILL, np.array([0.0599, 0.0]),
                                        np.array([-SPEED, 0.0])])
def test_with_no_intent_shown_it_keeps_on_while_the_robots_own_motion_does_not_serve(
        own_motion):
    # The hand closes in at full speed, but that is its own driving: the robot adds too
    # little (or pulls back), so it keeps control.
    acting = ServingMemory(acting=True, took_over=True)
    acts, memories = watch(3 * PATIENCE, acting, velocity=np.array([SPEED, 0.0]),
                           own_motion=own_motion)
    assert all(acts) and all(memory == acting for memory in memories)


def test_with_no_intent_shown_it_lets_go_once_the_robots_own_motion_serves():
    acting = ServingMemory(acting=True, took_over=True)
    acts, memories = watch(1, acting, velocity=STILL, own_motion=SERVING)
    assert acts == [False] and memories == [ServingMemory()]


def test_its_memory_survives_a_systems_discrete_state():
    for memory in (ServingMemory(), ServingMemory(unserved_ticks=4),
                   ServingMemory(acting=True, took_over=True, hold_ticks=7)):
        assert ServingMemory.from_vector(memory.as_vector()) == memory


def test_its_sense_of_the_robots_own_motion_averages_over_its_patience():
    # Each tick weighs period / serve_patience = 0.2 of what the hand does beyond the
    # command it sent.
    velocity = np.array([0.1, 0.0, -0.05])
    own = np.zeros(3)
    for tick in range(1, 6):
        own = update_own_motion(PARAMS, PERIOD, own, velocity, np.zeros(3))
        np.testing.assert_allclose(own, (1.0 - 0.8 ** tick) * velocity)
    # The hand doing just what it was asked: what it sensed fades by 0.8 a tick.
    faded = update_own_motion(PARAMS, PERIOD, own, velocity, velocity)
    np.testing.assert_allclose(faded, 0.8 * own)
    # A hand that lags its new command (asked 0.12, does 0.02): a pull of -0.1, at 0.2.
    lag = update_own_motion(PARAMS, PERIOD, np.zeros(3), [0.02, 0.0, 0.0], [0.12, 0.0, 0.0])
    np.testing.assert_allclose(lag, [-0.02, 0.0, 0.0])
    # A tick longer than its patience: what the hand does now, alone.
    np.testing.assert_allclose(
        update_own_motion(PARAMS, 0.5, own, velocity, [0.03, 0.0, 0.0]),
        velocity - [0.03, 0.0, 0.0])


def test_it_sees_the_robot_pull_from_half_its_own_speed():
    assert not robot_pulls(PARAMS, SPEED, [0.0599, 0.0, 0.0])
    assert robot_pulls(PARAMS, SPEED, [0.0, 0.0601, 0.0])
    # Whatever the direction: |(-0.04, -0.05)| = 0.064.
    assert robot_pulls(PARAMS, SPEED, [-0.04, -0.05, 0.0])
    assert not robot_pulls(PARAMS, SPEED, [0.03, 0.04, 0.0])  # |.| = 0.05
