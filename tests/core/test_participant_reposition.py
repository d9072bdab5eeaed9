"""Where the tool cannot point at the target (beyond an arm's wrist turn, or more above or
below the hand than beside it), the virtual participant first moves the hand to where it
can (`participant_reach.can_point_at`, `reposition_motion`), never forward, and then points
at it; in its system (`VirtualOperator`), for at most `reposition_time`, after which it goes
to the target itself. With no bound on the turn and no vertical motion (the HSR's floor
tasks) it never does."""

import dataclasses

import numpy as np
import pytest

from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_reach import (
    assist_motion, can_point_at, faces_target, facing, reposition_motion)

import participant_harness

PERIOD = 0.03
SPEED = 0.08
PARAMS = dataclasses.replace(VirtualParticipantParams(), direction_noise=0.0,
                             speed_noise=0.0)
WRIST = (-1.2, 1.2)
HAND = np.array([0.55, 0.0, 0.35])
AHEAD = np.array([0.7, -0.15, 0.35])
BEHIND_LEFT = np.array([0.45, 0.15, 0.35])  # its floor direction 2.16 rad from +x
BEHIND_RIGHT = BEHIND_LEFT * [1, -1, 1]
ABOVE = HAND + [0.02, 0.05, 0.15]  # 0.054 m beside the hand, 0.15 m above it


def test_the_tool_points_within_the_wrists_turn_and_not_beyond_it():
    assert can_point_at(PARAMS, HAND, AHEAD, WRIST)
    assert not can_point_at(PARAMS, HAND, BEHIND_LEFT, WRIST)
    assert not can_point_at(PARAMS, HAND, BEHIND_RIGHT, WRIST)
    # Just past the bound, within `aligned_angle`, it counts as pointable.
    edge = 1.2 + 0.5 * PARAMS.aligned_angle
    assert can_point_at(PARAMS, HAND, HAND + 0.2 * np.array([np.cos(edge), np.sin(edge), 0]),
                        WRIST)
    # A base that turns all the way round points anywhere on the floor.
    assert can_point_at(PARAMS, HAND, BEHIND_LEFT, None)


def test_a_target_more_above_the_hand_than_beside_it_has_no_direction_to_point_along():
    assert not can_point_at(PARAMS, HAND, ABOVE, WRIST, vertical=True)
    assert not can_point_at(PARAMS, HAND, ABOVE, None, vertical=True)
    # Without vertical motion its height is not the participant's to change.
    assert can_point_at(PARAMS, HAND, ABOVE, WRIST)
    assert can_point_at(PARAMS, HAND, HAND + [0.2, 0.05, 0.15], WRIST, vertical=True)


@pytest.mark.parametrize("target, turn", [(BEHIND_LEFT, 1.0), (BEHIND_RIGHT, -1.0)])
def test_it_backs_away_and_turns_toward_the_nearer_bound(target, turn):
    for heading in np.linspace(*WRIST, 9):
        velocity, yaw_rate = reposition_motion(PARAMS, SPEED, HAND, heading, target, WRIST)
        np.testing.assert_allclose(velocity, [-SPEED, 0.0])
        assert velocity @ facing(heading) < 0.0  # never forward, wherever the tool points
        if abs(heading - turn * WRIST[1]) > PARAMS.aligned_angle:
            assert np.sign(yaw_rate) == turn
        else:
            assert yaw_rate == 0.0  # at the bound nearest the target: turned as far as it goes


def test_it_moves_to_the_height_of_a_target_above_and_backs_from_one_behind_at_once():
    velocity, _ = reposition_motion(PARAMS, SPEED, HAND, 0.0, ABOVE, WRIST, vertical=True)
    np.testing.assert_allclose(velocity, [0.0, 0.0, SPEED])
    below_behind = HAND + [-0.05, 0.02, -0.2]
    velocity, _ = reposition_motion(PARAMS, SPEED, HAND, 0.0, below_behind, WRIST,
                                    vertical=True)
    np.testing.assert_allclose(velocity, SPEED * np.array([-1.0, 0.0, -1.0]) / np.sqrt(2))


def Participant(objects, target_index, selected=0, params=PARAMS, **kwargs):
    return participant_harness.Participant(objects, target_index, selected, period=PERIOD,
                                           speed=SPEED, start=HAND, params=params, **kwargs)


def test_the_participant_backs_until_the_tool_can_point_at_the_target_then_faces_it():
    participant = Participant([AHEAD, BEHIND_LEFT], 1, heading_range=WRIST, vertical=True)
    repositioning = 0
    while not can_point_at(PARAMS, participant.position, BEHIND_LEFT, WRIST, True):
        heading = participant.heading
        command = participant.follow(1)[0]
        assert command[:2] @ facing(heading) < 0.0 and command[2] == 0.0
        repositioning += 1
        assert repositioning * PERIOD < PARAMS.reposition_time
    # About 0.15 m back at 0.08 m/s.
    assert 1.0 < repositioning * PERIOD < 2.5
    facing_ticks = 0
    while not faces_target(PARAMS, participant.position, participant.heading, BEHIND_LEFT):
        participant.follow(1)
        facing_ticks += 1
        assert facing_ticks * PERIOD < 2.0


@pytest.mark.slow
def test_unable_to_move_to_where_it_can_point_it_goes_to_the_target_itself():
    # The hand held where it is (the arm at a limit, say): after `reposition_time` of
    # backing in vain it insists, moving toward the target as far as the keys allow. The
    # hand that does not follow its keys reads as the robot pulling against them, so it
    # pushes against that pull (`policy_compensation`): harder, in the same direction.
    participant = Participant([AHEAD, BEHIND_LEFT], 1, heading_range=WRIST, vertical=True)
    ticks = round(PARAMS.reposition_time / PERIOD)
    commands = np.array([participant.tick() for _ in range(ticks + 1)])
    backing, _ = reposition_motion(PARAMS, SPEED, HAND, 0.0, BEHIND_LEFT, WRIST, True)
    np.testing.assert_allclose(commands[0, :3], backing)
    limit = PARAMS.policy_compensation * SPEED
    speeds = np.linalg.norm(commands[:ticks, :3], axis=1)
    np.testing.assert_allclose(commands[:ticks, :3], speeds[:, None] * backing / SPEED)
    assert speeds.max() <= limit * (1 + 1e-12)
    insisting, yaw_rate = assist_motion(PARAMS, SPEED, HAND, 0.0, BEHIND_LEFT, AHEAD,
                                        insisting=True, vertical=True)
    # What it wants minus the robot's own motion (the hand still: minus what it sent).
    pushed = insisting + commands[ticks - 1, :3]
    pushed *= min(1.0, limit / np.linalg.norm(pushed))
    np.testing.assert_allclose(commands[ticks], [*pushed, yaw_rate])
    assert not np.allclose(insisting, backing)


def test_with_the_turn_unbounded_on_the_floor_it_turns_to_face_a_target_behind():
    participant = Participant([AHEAD, BEHIND_LEFT], 1)
    command = participant.tick()
    velocity, yaw_rate = assist_motion(PARAMS, SPEED, HAND, 0.0, BEHIND_LEFT, AHEAD,
                                       insisting=False)
    np.testing.assert_allclose(command, [*velocity, 0.0, yaw_rate])


def test_with_no_reposition_time_it_goes_to_a_target_it_cannot_point_at_at_once():
    params = dataclasses.replace(PARAMS, reposition_time=0.0)
    behind = Participant([AHEAD, BEHIND_LEFT], 1, heading_range=WRIST, vertical=True,
                         params=params)
    insisting, yaw_rate = assist_motion(params, SPEED, HAND, 0.0, BEHIND_LEFT, AHEAD,
                                        insisting=True, vertical=True)
    np.testing.assert_allclose(behind.tick(), [*insisting, yaw_rate])
    # A target it can point at it still shows by turning and sidestepping.
    ahead = Participant([BEHIND_LEFT, AHEAD], 1, heading_range=WRIST, vertical=True,
                        params=params)
    showing, yaw_rate = assist_motion(params, SPEED, HAND, 0.0, AHEAD, BEHIND_LEFT,
                                      insisting=False, vertical=True)
    np.testing.assert_allclose(ahead.tick(), [*showing, yaw_rate])


def test_insisting_at_the_wrists_bound_it_turns_the_target_to_the_side_the_wrist_reaches():
    # The hand turned to the wrist's bound, the target straight ahead: the near side's
    # heading (a quarter turn further) is beyond the bound, where an arm's participant
    # once pushed for ever while no key moved the hand; the far side's is within it.
    heading = WRIST[0]
    target = HAND + 0.2 * np.array([np.cos(heading), np.sin(heading), 0.0])
    for vertical in (False, True):
        velocity, yaw_rate = assist_motion(PARAMS, SPEED, HAND, heading, target, AHEAD,
                                           insisting=True, vertical=vertical,
                                           heading_range=WRIST)
        assert yaw_rate > 0.0
        _, unbounded = assist_motion(PARAMS, SPEED, HAND, heading, target, AHEAD,
                                     insisting=True, vertical=vertical)
        assert unbounded < 0.0  # the HSR's base turns the near way, as before
    # Once turned there, the target is to its side: the sidestep reaches it at full speed.
    turned = heading + np.pi / 2
    velocity, yaw_rate = assist_motion(PARAMS, SPEED, HAND, turned, target, AHEAD,
                                       insisting=True, vertical=True, heading_range=WRIST)
    assert yaw_rate == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(velocity, SPEED * (target - HAND) / 0.2, atol=1e-12)
