"""The virtual participant's optional vertical axis (objects at different heights), in the
core (`participant_reach`) and in its system (`VirtualOperator`): driving it heads for the
target in 3-D, assisting it leaves the height to the DMP unless it insists, never faster
than `speed`; and with `vertical` off every command is what it was."""

import dataclasses

import numpy as np
import pytest

from pbp_drake.core.participant_impairment import ParticipantImpairment
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_reach import assist_motion, drive_motion, facing
from pbp_drake.core.participant_serving import NO_INTENT
from pbp_drake.systems import VirtualOperator

import participant_harness

PERIOD = 0.03
SPEED = 0.12
PARAMS = VirtualParticipantParams()
START = np.array([0.5, 0.0, 0.35])
ABOVE = np.array([1.1, -0.3, 0.5])
BELOW = np.array([1.1, 0.3, 0.2])
# Seen from START facing +x: the picked object ahead-left, the target ahead-right and higher.
PICKED = np.array([1.6, 0.5, 0.3])
TARGET = np.array([1.6, -0.5, 0.5])


def random_cases(count=40, seed=3):
    """Hands, headings, targets and picked objects at heights in [0.2, 0.5] m."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        position = np.array([*rng.uniform(-0.5, 0.5, 2), rng.uniform(0.2, 0.5)])
        target = np.array([*rng.uniform(-1.0, 1.0, 2), rng.uniform(0.2, 0.5)])
        picked = np.array([*rng.uniform(-1.0, 1.0, 2), rng.uniform(0.2, 0.5)])
        yield position, float(rng.uniform(-np.pi, np.pi)), target, picked


def drive_path(target, ticks=400):
    """The hand's path when it follows `drive_motion` with vertical motion from START."""
    position, heading = START.copy(), 0.0
    speeds = []
    for _ in range(ticks):
        velocity, yaw_rate = drive_motion(PARAMS, SPEED, position, heading, target,
                                          vertical=True)
        speeds.append(np.linalg.norm(velocity))
        position, heading = position + PERIOD * velocity, heading + PERIOD * yaw_rate
    return position, np.array(speeds)


@pytest.mark.parametrize("target", [ABOVE, BELOW])
def test_driving_with_vertical_motion_reaches_a_target_above_or_below(target):
    velocity, _ = drive_motion(PARAMS, SPEED, START, 0.0, target, vertical=True)
    assert velocity.shape == (3,)
    assert np.sign(velocity[2]) == np.sign(target[2] - START[2])
    offset = target - START
    np.testing.assert_allclose(velocity, SPEED * offset / np.linalg.norm(offset))
    position, speeds = drive_path(target)
    assert np.linalg.norm(position - target) < 0.01
    assert speeds.max() <= SPEED * (1 + 1e-12)  # one speed for all three axes


def test_driving_straight_up_does_not_turn():
    velocity, yaw_rate = drive_motion(PARAMS, SPEED, START, 0.3, START + [0, 0, 0.1],
                                      vertical=True)
    np.testing.assert_allclose(velocity, [0.0, 0.0, SPEED * min(1.0, 0.1 / 0.15)])
    assert yaw_rate == 0.0
    velocity, yaw_rate = drive_motion(PARAMS, SPEED, START, 0.3, START, vertical=True)
    assert np.array_equal(velocity, np.zeros(3)) and yaw_rate == 0.0


def test_insisting_on_a_target_straight_above_does_not_turn():
    velocity, yaw_rate = assist_motion(PARAMS, SPEED, START, 0.3, START + [0, 0, 0.3], PICKED,
                                       insisting=True, vertical=True)
    np.testing.assert_allclose(velocity, [0.0, 0.0, SPEED])
    assert yaw_rate == 0.0


def test_assisting_without_insisting_leaves_the_height_to_the_dmp():
    for position, heading, target, picked in random_cases():
        velocity, yaw_rate = assist_motion(PARAMS, SPEED, position, heading, target, picked,
                                           insisting=False, vertical=True)
        planar, planar_yaw = assist_motion(PARAMS, SPEED, position, heading, target, picked,
                                           insisting=False)
        assert velocity.shape == (3,) and velocity[2] == 0.0
        assert np.array_equal(velocity[:2], planar) and yaw_rate == planar_yaw


@pytest.mark.parametrize("heading", [1.4, -1.4, 0.3])
def test_insisting_it_also_heads_for_the_targets_height(heading):
    for target in (TARGET, TARGET * [1, 1, 0] + [0, 0, 0.2]):
        velocity, yaw_rate = assist_motion(PARAMS, SPEED, START, heading, target, PICKED,
                                           insisting=True, vertical=True)
        _, planar_yaw = assist_motion(PARAMS, SPEED, START, heading, target, PICKED,
                                      insisting=True)
        assert np.sign(velocity[2]) == np.sign(target[2] - START[2])
        assert np.linalg.norm(velocity) <= SPEED * (1 + 1e-12)
        assert velocity[:2] @ facing(heading) <= 1e-12  # the forward key stays disabled
        assert yaw_rate == planar_yaw  # it turns the target to its side as before
    # Near the target it slows, as when driving: within slow_radius of the 3-D distance.
    near = START + [0.0, -0.03, 0.04]
    velocity, _ = assist_motion(PARAMS, SPEED, START, 1.4, near, PICKED, insisting=True,
                                vertical=True)
    assert np.linalg.norm(velocity) <= SPEED * 0.05 / PARAMS.slow_radius + 1e-12


def test_insisting_at_the_targets_height_moves_as_on_the_floor():
    level = TARGET * [1, 1, 0] + [0, 0, START[2]]
    for heading in (1.4, -1.4, 0.3):
        velocity, yaw_rate = assist_motion(PARAMS, SPEED, START, heading, level, PICKED,
                                           insisting=True, vertical=True)
        planar, planar_yaw = assist_motion(PARAMS, SPEED, START, heading, level, PICKED,
                                           insisting=True)
        np.testing.assert_allclose(velocity, [*planar, 0.0], atol=1e-15)
        assert yaw_rate == planar_yaw


def test_vertical_off_is_the_planar_motion_exactly():
    for position, heading, target, picked in random_cases():
        expected = drive_motion(PARAMS, SPEED, position, heading, target)
        got = drive_motion(PARAMS, SPEED, position, heading, target, vertical=False)
        assert expected[0].shape == (2,)
        assert np.array_equal(expected[0], got[0]) and expected[1] == got[1]
        for insisting in (False, True):
            expected = assist_motion(PARAMS, SPEED, position, heading, target, picked,
                                     insisting)
            got = assist_motion(PARAMS, SPEED, position, heading, target, picked, insisting,
                                vertical=False)
            assert expected[0].shape == (2,)
            assert np.array_equal(expected[0], got[0]) and expected[1] == got[1]


# The system.

def Participant(objects, target_index, selected=0, **kwargs):
    return participant_harness.Participant(objects, target_index, selected, period=PERIOD,
                                           speed=SPEED, start=START, **kwargs)


QUIET = dataclasses.replace(PARAMS, direction_noise=0.0, speed_noise=0.0)
OBJECTS = np.array([PICKED, TARGET, ABOVE, BELOW])
# The ticks a participant watches a robot that does not serve its target before it acts.
PATIENCE_TICKS = round(PARAMS.serve_patience / PERIOD)


def TeleopParticipant(objects, target_index, **kwargs):
    """A participant as under teleop (the forward key enabled, no intent shown), past the
    `serve_patience` it watches the still hand before it takes over."""
    participant = Participant(objects, target_index, NO_INTENT, forward_key=True, **kwargs)
    waiting = np.array([participant.tick() for _ in range(PATIENCE_TICKS)])
    assert not waiting.any()
    return participant


@pytest.mark.slow
@pytest.mark.parametrize("target_index", [2, 3])
def test_a_teleop_participant_drives_the_hand_to_a_target_above_or_below(target_index):
    participant = TeleopParticipant(OBJECTS, target_index, params=QUIET, vertical=True)
    commands = participant.follow(400)
    target = OBJECTS[target_index]
    assert np.sign(commands[0, 2]) == np.sign(target[2] - START[2])
    assert np.linalg.norm(commands[:, :3], axis=1).max() <= SPEED * (1 + 1e-12)
    assert np.linalg.norm(participant.position - target) < 0.01


def test_assisting_its_vz_is_zero_until_it_insists():
    patient = Participant(OBJECTS, 1, selected=0, params=PARAMS, vertical=True)
    commands = np.array([patient.tick() for _ in range(5)])
    assert np.all(commands[:, 2] == 0.0) and np.any(commands[:, :2] != 0.0)
    impatient = Participant(OBJECTS, 1, selected=0, vertical=True,
                            params=dataclasses.replace(QUIET, insist_time=0.0))
    impatient.move_to(START, heading=1.4)
    command = impatient.tick()
    assert command[2] > 0.0  # toward the target, above the hand
    assert np.linalg.norm(command[:3]) <= SPEED * (1 + 1e-12)


def test_its_noise_turns_the_floor_part_and_scales_vz():
    # Noisy (the calibrated noise) toward a target at the hand's height, with and without
    # vertical motion: the same floor command; toward one above, the same speed factor.
    level = np.array([[1.2, 0.4, START[2]], [1.2, 0.4, START[2] + 0.3]])
    planar = TeleopParticipant(level, 0, params=PARAMS)
    vertical = TeleopParticipant(level, 0, params=PARAMS, vertical=True)
    for _ in range(5):
        expected, got = planar.tick(), vertical.tick()
        np.testing.assert_allclose(got, expected, atol=1e-15)
    above = TeleopParticipant(level, 1, params=PARAMS, vertical=True)
    quiet = TeleopParticipant(level, 1, params=QUIET, vertical=True)
    noisy, exact = above.tick(), quiet.tick()
    factor = np.linalg.norm(noisy[:2]) / np.linalg.norm(exact[:2])
    assert factor != 1.0
    assert noisy[2] == pytest.approx(factor * exact[2])


def test_its_motor_noise_shakes_vz_and_keeps_the_rest_as_without_it():
    shaky = dataclasses.replace(
        PARAMS, impairment=ParticipantImpairment(command_noise=0.3))
    level = np.array([[1.2, 0.4, START[2]]])
    planar = TeleopParticipant(level, 0, params=shaky)
    vertical = TeleopParticipant(level, 0, params=shaky, vertical=True)
    commands = np.array([(planar.tick(), vertical.tick()) for _ in range(5)])
    np.testing.assert_allclose(commands[:, 1, [0, 1, 3]], commands[:, 0, [0, 1, 3]],
                               atol=1e-15)
    assert np.all(commands[:, 0, 2] == 0.0) and np.all(commands[:, 1, 2] != 0.0)


@pytest.mark.parametrize("forward_key", [True, False])
def test_vertical_off_sends_the_same_commands_as_before(forward_key):
    # The keyword omitted (as every existing scenario builds it) and vertical=False: the
    # same commands bit for bit, and vz = 0, with the calibrated noise and an impairment.
    params = dataclasses.replace(PARAMS, impairment=ParticipantImpairment(
        command_noise=0.3, command_delay=0.06, mistake_probability=0.5))
    runs = []
    for kwargs in ({}, {"vertical": False}):
        participant = Participant(OBJECTS, 2, selected=0, forward_key=forward_key,
                                  params=params, **kwargs)
        runs.append(participant.follow(60))
    assert np.array_equal(runs[0], runs[1])
    assert np.all(runs[0][:, 2] == 0.0) and np.any(runs[0][:, :2] != 0.0)


def test_vertical_motion_with_obstacles_is_refused():
    with pytest.raises(ValueError, match="vertical=True.*obstacle"):
        VirtualOperator(PERIOD, OBJECTS[:1], nominal_speed=SPEED,
                        obstacle_count=2, obstacle_radius=0.1, vertical=True)
