"""The grasping task's virtual participant (`pbp_drake.core.participant_grasp`), in a plain
kinematic loop: the hand's pose integrated from the commanded twist. It is built from the
same arguments under every method; the keys (`forward_key`) and the robot's shown intent
(`shown`, -1: none) are what it sees of the method."""

import dataclasses

import numpy as np
import pytest

from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.core.grasp_estimation import estimate_pose
from pbp_drake.core.grasp_task import (
    approach_direction, grasp_errors, grasp_success, sample_grasp_scene,
    side_grasp_orientation, top_grasp_orientation)
from pbp_drake.core.participant_grasp import (
    SHARED_WITH_REACH, GraspParticipant, GraspParticipantParams, ParticipantMemory,
    drive_twist, notice_target)
from pbp_drake.core.participant_impairment import ParticipantImpairment
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_serving import NO_INTENT, ServingMemory, update_own_motion
from pbp_drake.core.quaternion import angle_between, exp_map, multiply

PERIOD = 0.03
SPEED = 0.12
HAND = np.array([0.53, 0.08, 0.7])
LEVEL = side_grasp_orientation(0.0)
SUCCESS_DISTANCE, SUCCESS_ANGLE = 0.03, np.radians(10.0)


def integrate(position, orientation, twist):
    """The hand's pose one tick later under the world-frame twist `[v, omega]`."""
    return (position + PERIOD * twist[:3],
            multiply(exp_map(PERIOD * twist[3:]), orientation))


ZERO = np.zeros(3)


def drive(scene, target, seed, seconds=60.0):
    """Teleop (the forward key enabled, no intent shown, a robot that adds nothing) from the
    ready hand to `target`: the tick it succeeded at (None if not), and the first tick it
    acted at."""
    params = GraspParticipantParams()
    participant = GraspParticipant.create(params, SPEED, scene.grasp_positions,
                                          scene.grasp_orientations, seed)
    position, orientation, memory = HAND.copy(), LEVEL.copy(), ParticipantMemory()
    serving, velocity, own_motion, first_active = ServingMemory(), ZERO, ZERO, None
    for tick in range(int(seconds / PERIOD)):
        if grasp_success(position, orientation, scene.grasp_positions[target],
                         scene.grasp_orientations[target], SUCCESS_DISTANCE, SUCCESS_ANGLE):
            return tick, first_active
        twist, active, memory, serving = participant.step(
            memory, serving, tick * PERIOD, tick, position, orientation, velocity,
            own_motion, target, NO_INTENT, True, PERIOD)
        if active and first_active is None:
            first_active = tick
        # Once it has taken over it keeps on: teleop's robot never moves by itself.
        assert active == (first_active is not None)
        # The hand moves as commanded: the robot's own motion stays nil.
        velocity = twist[:3]
        own_motion = update_own_motion(params, PERIOD, own_motion, velocity, velocity)
        position, orientation = integrate(position, orientation, twist)
    return None, first_active


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(8))
def test_driving_it_reaches_the_targets_grasp_pose(seed):
    scene = sample_grasp_scene(seed)
    tick, first_active = drive(scene, scene.targets[0], seed)
    assert tick is not None, "did not reach the grasp pose within 60 s"
    # It takes over once it has noticed the target (`reaction_delay`) and watched the still
    # hand not serve it for `serve_patience`.
    params = GraspParticipantParams()
    assert first_active == (int(np.ceil(params.reaction_delay / PERIOD - 1e-9))
                            + round(params.serve_patience / PERIOD))
    # Not before the straight-line time at the nominal speed plus its reaction.
    distance = np.linalg.norm(scene.grasp_positions[scene.targets[0]] - HAND)
    assert tick * PERIOD > distance / SPEED


def test_it_notices_a_target_only_after_its_reaction_delay():
    memory = ParticipantMemory()
    for time, true_target, known in [(0.0, 2, -1), (0.3, 2, -1), (0.5, 2, 2), (0.6, 0, 2),
                                     (1.05, 0, 2), (1.1, 0, 0), (1.2, 1, 0)]:
        memory = notice_target(memory, true_target, time, 0.5)
        assert memory.known_target == known, time


@pytest.mark.parametrize("forward_key", [False, True])
def test_it_does_nothing_while_the_robot_shows_the_target_and_brings_the_hand_there(
        forward_key):
    scene = sample_grasp_scene(5)
    participant = GraspParticipant.create(GraspParticipantParams(), SPEED,
                                          scene.grasp_positions, scene.grasp_orientations, 5)
    memory, serving = ParticipantMemory(), ServingMemory()
    target = scene.targets[0]
    offset = scene.grasp_positions[target] - HAND
    # The robot moves the hand straight to the grasp at the participant's own speed.
    robot = SPEED * offset / np.linalg.norm(offset)
    for tick in range(60):
        twist, active, memory, serving = participant.step(
            memory, serving, tick * PERIOD, tick, HAND, LEVEL, robot, robot, target, target,
            forward_key, PERIOD)
        assert not active and not twist.any()


def test_with_the_target_shown_but_the_hand_still_it_helps_after_its_patience():
    # The robot shows the target (to the hand's left, off its approach axis) and does not
    # move: after `serve_patience` the participant takes over with the keys it has (no
    # forward), keeps control `hold_time`, lets go (the robot shows the target) and watches
    # again.
    positions = np.array([[1.0, 0.0, 0.675], [0.6, 0.5, 0.7]])
    params = GraspParticipantParams(direction_noise=0.0, speed_noise=0.0)
    participant = GraspParticipant.create(params, SPEED, positions, np.array([LEVEL, LEVEL]))
    memory, serving = notice_target(ParticipantMemory(), 1, 0.0, 0.0), ServingMemory()
    patience = round(params.serve_patience / PERIOD)
    hold = round(params.hold_time / PERIOD)
    activity = []
    for tick in range(2 * (patience + 1) + hold + 1):
        twist, active, memory, serving = participant.step(
            memory, serving, tick * PERIOD, tick, HAND, LEVEL, ZERO, ZERO, 1, 1, False,
            PERIOD)
        activity.append(active)
        if active:
            assert twist[:3] @ approach_direction(LEVEL) <= 1e-12  # never forward
            assert twist[:3] @ (positions[1] - HAND) > 0.0
    # It takes over on the tick past its patience and keeps control `hold` ticks more; the
    # tick it lets go it starts watching afresh.
    expected = ([False] * patience + [True] * (hold + 1) + [False] * (patience + 1)
                + [True])
    assert activity == expected


def test_with_the_forward_key_it_drives_at_once_to_the_target_the_robot_does_not_mean():
    # The keys, not the intent, decide what it presses: the robot showing another object,
    # with the forward key it drives straight to the target's grasp pose from the first tick.
    scene = sample_grasp_scene(3)
    params = GraspParticipantParams(direction_noise=0.0, speed_noise=0.0)
    participant = GraspParticipant.create(params, SPEED, scene.grasp_positions,
                                          scene.grasp_orientations)
    target, picked = scene.targets[0], scene.targets[1]
    memory = notice_target(ParticipantMemory(), target, 0.0, 0.0)
    twist, active, _, serving = participant.step(
        memory, ServingMemory(), 0.0, 0, HAND, LEVEL, ZERO, ZERO, target, picked, True,
        PERIOD)
    assert active and serving.acting and not serving.took_over
    np.testing.assert_allclose(twist, np.concatenate(drive_twist(
        params, SPEED, HAND, LEVEL, scene.grasp_positions[target],
        scene.grasp_orientations[target])))


def test_on_its_targets_grasp_pose_it_presses_nothing():
    scene = sample_grasp_scene(3)
    participant = GraspParticipant.create(GraspParticipantParams(), SPEED,
                                          scene.grasp_positions, scene.grasp_orientations)
    target = scene.targets[0]
    twist, active, _, _ = participant.step(
        notice_target(ParticipantMemory(), target, 0.0, 0.0), ServingMemory(), 0.0, 0,
        scene.grasp_positions[target], scene.grasp_orientations[target], ZERO, ZERO, target,
        scene.targets[1], True, PERIOD)
    assert not active and not twist.any()


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(12))
def test_assisting_while_wrong_it_turns_toward_the_target_and_never_pushes_forward(seed):
    scene = sample_grasp_scene(seed)
    noisy, quiet = [GraspParticipant.create(
        params, SPEED, scene.grasp_positions, scene.grasp_orientations, seed)
        for params in (GraspParticipantParams(),
                       GraspParticipantParams(direction_noise=0.0, speed_noise=0.0))]
    target = scene.targets[0]
    picked = scene.targets[1]
    memory, serving = notice_target(ParticipantMemory(), target, 0.0, 0.5), ServingMemory()
    rng = np.random.default_rng(seed)
    for tick in range(17, 60):  # past its reaction delay
        position = HAND + rng.uniform(-0.2, 0.2, 3)
        orientation = multiply(exp_map(rng.normal(0.0, 0.5, 3)), LEVEL)
        # The robot means another object: it acts at once, however the hand moves.
        velocity = rng.uniform(-0.1, 0.1, 3)
        twist, active, _, _ = noisy.step(memory, serving, tick * PERIOD, tick, position,
                                         orientation, velocity, velocity, target, picked,
                                         False, PERIOD)
        assert active
        # Noise or not, the forward key stays disabled.
        assert twist[:3] @ approach_direction(orientation) <= 1e-12
        twist, active, memory, serving = quiet.step(
            memory, serving, tick * PERIOD, tick, position, orientation, velocity, velocity,
            target, picked, False, PERIOD)
        assert twist[:3] @ approach_direction(orientation) <= 1e-12
        # Its turn shrinks the angle to the target's grasp orientation.
        later = multiply(exp_map(1e-4 * twist[3:]), orientation)
        goal = scene.grasp_orientations[target]
        assert angle_between(later, goal) < angle_between(orientation, goal)
        # Its motion gains on the target against the object picked instead.
        moved = position + 1e-4 * twist[:3]
        gap_now = np.subtract(*grasp_errors(position, orientation,
                                            scene.grasp_positions[[target, picked]],
                                            scene.grasp_orientations[[target, picked]])[0])
        gap_then = np.subtract(*grasp_errors(moved, orientation,
                                             scene.grasp_positions[[target, picked]],
                                             scene.grasp_orientations[[target, picked]])[0])
        assert gap_then <= gap_now + 1e-12


def blend_loop(positions, orientations, target, start_picked, seconds=30.0, seed=0):
    """PBP-Alt in a kinematic loop: the policy drives the hand to the selected grasp pose
    (as the teleop participant would), the participant takes over while it acts; the pose
    estimator selects. Returns the selections and the participant's activity per tick."""
    policy_params = GraspParticipantParams()
    participant = GraspParticipant.create(GraspParticipantParams(), SPEED, positions,
                                          orientations, seed)
    settings = GoalEstimatorSettings(method="pose")
    position, orientation, memory = HAND.copy(), LEVEL.copy(), ParticipantMemory()
    serving, own_motion = ServingMemory(), np.zeros(3)
    velocity, angular = np.zeros(3), np.zeros(3)
    estimate = None
    selected = start_picked
    selections, activity = [], []
    for tick in range(int(seconds / PERIOD)):
        if tick:
            selected, _, estimate = estimate_pose(settings, positions, orientations, position,
                                                  orientation, velocity, angular, estimate)
        twist, active, memory, serving = participant.step(
            memory, serving, tick * PERIOD, tick, position, orientation, velocity,
            own_motion, target, selected, False, PERIOD)
        sent = twist[:3] if active else np.zeros(3)
        if not active:
            twist = np.concatenate(drive_twist(policy_params, SPEED, position, orientation,
                                               positions[selected], orientations[selected]))
        velocity, angular = twist[:3], twist[3:]
        own_motion = update_own_motion(policy_params, PERIOD, own_motion, velocity, sent)
        position, orientation = integrate(position, orientation, twist)
        selections.append(selected)
        activity.append(active)
    return np.array(selections), np.array(activity)


@pytest.mark.slow
def test_in_a_blend_loop_it_brings_the_estimate_round_and_then_lets_go():
    positions = np.array([[1.6, 0.5, 0.675], [1.6, -0.5, 0.675]])
    orientations = np.array([side_grasp_orientation(0.4), side_grasp_orientation(-0.4)])
    selections, activity = blend_loop(positions, orientations, target=1, start_picked=0)
    assert activity.any()
    first_right = int(np.argmax(selections == 1))
    assert selections[first_right:].tolist() == [1] * (len(selections) - first_right)
    assert not activity[first_right + 1:].any()


@pytest.mark.slow
def test_only_its_turn_tells_two_grasps_at_one_place_apart_in_the_loop():
    place = np.array([1.6, 0.0, 0.83])
    positions = np.array([place, place])
    orientations = np.array([top_grasp_orientation(-1.0), top_grasp_orientation(1.0)])
    selections, activity = blend_loop(positions, orientations, target=0, start_picked=1)
    assert activity.any() and selections[-1] == 0
    assert not activity[-10:].any()


def test_its_noise_comes_from_the_seed_and_the_tick():
    # Object 0 known from the start; under teleop, it has taken over.
    seen = notice_target(ParticipantMemory(), 0, 0.0, 0.0)
    driving = ServingMemory(acting=True, took_over=True, hold_ticks=10)
    scene = sample_grasp_scene(2)
    commands = {}
    for seed in (2, 2, 3):
        participant = GraspParticipant.create(GraspParticipantParams(), SPEED,
                                              scene.grasp_positions,
                                              scene.grasp_orientations, seed)
        commands.setdefault(seed, []).append(participant.step(
            seen, driving, 1.0, 33, HAND, LEVEL, ZERO, ZERO, 0, NO_INTENT, True, PERIOD)[0])
    np.testing.assert_array_equal(commands[2][0], commands[2][1])
    assert not np.allclose(commands[2][0], commands[3][0])
    quiet = GraspParticipant.create(
        GraspParticipantParams(direction_noise=0.0, speed_noise=0.0), SPEED,
        scene.grasp_positions, scene.grasp_orientations, 2)
    twist = quiet.step(seen, driving, 1.0, 33, HAND, LEVEL, ZERO, ZERO, 0, NO_INTENT, True,
                       PERIOD)[0]
    offset = scene.grasp_positions[0] - HAND
    np.testing.assert_allclose(twist[:3], SPEED * offset / np.linalg.norm(offset))


def test_it_takes_the_shared_fields_of_the_reach_participant():
    reach = VirtualParticipantParams(speed=0.1, rotation_speed=0.6, reaction_delay=0.3,
                                     turn_slowdown_angle=0.2)
    params = GraspParticipantParams.from_virtual_participant(reach)
    assert (params.speed, params.rotation_speed, params.reaction_delay,
            params.slow_angle) == (0.1, 0.6, 0.3, 0.2)
    assert params.slow_radius == reach.slow_radius



def test_its_shared_defaults_are_the_reach_participants():
    # One home per default: VirtualParticipantParams' calibration.
    grasp, reach = GraspParticipantParams(), VirtualParticipantParams()
    assert set(SHARED_WITH_REACH) == {field.name for field in dataclasses.fields(grasp)}
    for name, reach_name in SHARED_WITH_REACH.items():
        assert getattr(grasp, name) == getattr(reach, reach_name), name
    assert GraspParticipantParams.from_virtual_participant(reach) == grasp

@pytest.mark.parametrize("arguments, message", [
    (dict(params=GraspParticipantParams(rotation_speed=0.0)),
     "rotation_speed must be finite and positive"),
    (dict(params=GraspParticipantParams(reaction_delay=-1.0)),
     "reaction_delay must be finite and not negative"),
    (dict(params=GraspParticipantParams(
        impairment=ParticipantImpairment(command_delay=-1.0))),
     "impairment.command_delay must be finite and not negative"),
    (dict(nominal_speed=0.0), "nominal_speed must be finite and positive"),
    (dict(grasp_orientations=[[1.0, 0, 0, 0]]), r"grasp_orientations \(M, 4\)"),
])
def test_bad_arguments_say_what_is_wrong(arguments, message):
    values = dict(params=GraspParticipantParams(), nominal_speed=SPEED,
                  grasp_positions=[[1.5, 0.0, 0.7], [1.5, 0.5, 0.7]],
                  grasp_orientations=[LEVEL, LEVEL])
    values.update(arguments)
    with pytest.raises(ValueError, match=message):
        GraspParticipant.create(**values)


def test_after_holding_the_targets_orientation_in_vain_it_goes_to_the_target_itself():
    # The target stands behind the picked object, a little to the right: backing away from
    # the picked object would walk the hand off the scene, as it did before this rule.
    positions = np.array([[1.3, 0.05, 0.675], [2.3, -0.35, 0.675]])
    orientations = np.array([LEVEL, LEVEL])
    params = GraspParticipantParams(direction_noise=0.0, speed_noise=0.0)
    participant = GraspParticipant.create(params, SPEED, positions, orientations)
    memory, serving = notice_target(ParticipantMemory(), 1, 0.0, 0.0), ServingMemory()
    ahead = approach_direction(LEVEL)
    toward_target = positions[1] - HAND
    insist_tick = int(round(params.insist_time / PERIOD))
    for tick in range(insist_tick + 3):
        twist, active, memory, serving = participant.step(
            memory, serving, tick * PERIOD, tick, HAND, LEVEL, ZERO, ZERO, 1, 0, False,
            PERIOD)
        assert active and twist[:3] @ ahead <= 1e-12  # never forward
        if tick < insist_tick:
            assert not memory.insisting
            assert twist[:3] @ ahead < 0.0  # backing away from the picked object
    assert memory.insisting
    assert twist[:3] @ toward_target > 0.0 and twist[:3] @ ahead > -1e-12
    # It insists until a new target appears, and then starts over; the robot showing the
    # target, it lets go at once.
    twist, active, memory, serving = participant.step(
        memory, serving, 5.0, 200, HAND, LEVEL, ZERO, ZERO, 1, 1, False, PERIOD)
    assert not active and memory.insisting
    memory = notice_target(memory, 0, 5.0, 0.0)
    assert not memory.insisting and memory.facing_since < 0.0


def test_it_does_not_insist_before_it_holds_the_targets_orientation():
    positions = np.array([[1.3, 0.05, 0.675], [2.3, -0.35, 0.675]])
    orientations = np.array([LEVEL, side_grasp_orientation(0.8)])  # 46 degrees off
    participant = GraspParticipant.create(GraspParticipantParams(), SPEED, positions,
                                          orientations)
    memory, serving = notice_target(ParticipantMemory(), 1, 0.0, 0.0), ServingMemory()
    for tick in range(100):
        _, _, memory, serving = participant.step(
            memory, serving, tick * PERIOD, tick, HAND, LEVEL, ZERO, ZERO, 1, 0, False,
            PERIOD)
        assert not memory.insisting


def test_the_insisting_time_comes_from_the_scenarios_participant():
    reach = VirtualParticipantParams(insist_time=2.5)
    assert GraspParticipantParams.from_virtual_participant(reach).insist_time == 2.5
    with pytest.raises(ValueError, match="insist_time"):
        GraspParticipantParams(insist_time=-1.0).validate()
