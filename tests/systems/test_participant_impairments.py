"""The impaired virtual participant as a Drake system (`VirtualOperator` in the reaching
task, `PoseVirtualOperator` in the grasping task), alone in a small diagram with its inputs
given: the noisy one's commands carry noise of the documented spread, the same for one
seed whatever it does; the late one sends the very commands of the unimpaired one, d
seconds later; the mistaken one heads for another object first, then for the target."""

import dataclasses

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.core.grasp_task import side_grasp_orientation
from pbp_drake.core.participant_grasp import GraspParticipant, GraspParticipantParams
from pbp_drake.core.participant_impairment import ParticipantImpairment
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_reach import facing
from pbp_drake.core.participant_serving import NO_INTENT
from pbp_drake.systems import PoseVirtualOperator, VirtualOperator

PERIOD = 0.03
SPEED = 0.12
HAND = np.array([0.5, 0.0, 0.7])
# Seen from the hand facing +x: one object ahead-left, one ahead-right, one far ahead.
OBJECTS = np.array([[1.6, 0.6, 0.7], [1.6, -0.6, 0.7], [2.4, 0.0, 0.7]])
QUIET = dict(direction_noise=0.0, speed_noise=0.0)
# The ticks it watches a robot that does not serve its target before it takes over.
PATIENCE = round(VirtualParticipantParams().serve_patience / PERIOD)


def params(**impairment):
    """The calibrated participant without its own noise, impaired as given."""
    return VirtualParticipantParams(**QUIET, impairment=ParticipantImpairment(**impairment))


def target_source(schedule):
    """A source of the task monitor's `target` [p (3), index]: `schedule` is a list of
    (time, object index), each held until the next."""
    times = [time for time, _ in schedule] + [1e3]
    values = np.array([[*OBJECTS[index], index] for _, index in schedule]
                      + [[*OBJECTS[schedule[-1][1]], schedule[-1][1]]]).T
    return TrajectorySource(PiecewisePolynomial.ZeroOrderHold(times, values))


def hand_source(heading, velocity, seconds):
    """A source of `ee_state`: the hand from HAND at `velocity` (3; zero: held there),
    facing `heading`."""
    velocity = np.asarray(velocity, float)
    if not velocity.any():
        return ConstantVectorSource(np.array([*HAND, 0.0, 0.0, 0.0, heading, 0.0]))
    values = np.array([[*(HAND + time * velocity), *velocity, heading, 0.0]
                       for time in (0.0, seconds)]).T
    return TrajectorySource(PiecewisePolynomial.FirstOrderHold([0.0, seconds], values))


def reach_commands(participant_params, schedule, ticks, forward_key=True, selected=NO_INTENT,
                   seed=4, heading=0.0, hand_velocity=(0.0, 0.0, 0.0)):
    """`(commands (ticks, 4), active (ticks,))` of a lone reach participant, the hand held
    at HAND with `heading` (or moving from there at `hand_velocity`), the robot showing
    `selected` (by default none, and the forward key enabled: as under teleop)."""
    builder = DiagramBuilder()
    participant = builder.AddSystem(VirtualOperator(
        PERIOD, OBJECTS, params=participant_params, nominal_speed=SPEED, seed=seed))
    for port, source in (
            (participant.get_ee_state_input_port(),
             hand_source(heading, hand_velocity, ticks * PERIOD + 1.0)),
            (participant.get_target_input_port(), target_source(schedule)),
            (participant.get_selected_goal_input_port(),
             ConstantVectorSource(np.array([float(selected)]))),
            (participant.get_forward_key_input_port(),
             ConstantVectorSource(np.array([1.0 if forward_key else 0.0])))):
        builder.Connect(builder.AddSystem(source).get_output_port(), port)
    return _sampled(builder, participant, ticks)


def _sampled(builder, participant, ticks):
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = participant.GetMyContextFromRoot(simulator.get_context())
    commands, active = [], []
    for tick in range(ticks):
        simulator.AdvanceTo((tick + 0.5) * PERIOD)  # the sample of tick `tick`
        commands.append(participant.get_operator_command_output_port().Eval(context).copy())
        active.append(participant.get_operator_active_output_port().Eval(context)[0])
    return np.array(commands), np.array(active) > 0.5


def toward(command, point):
    """The cosine between the command's floor velocity and the direction to `point` (NaN
    for no velocity)."""
    if not command[:2].any():
        return np.nan
    offset = point[:2] - HAND[:2]
    return command[:2] @ offset / (np.linalg.norm(command[:2]) * np.linalg.norm(offset))


# ---------------------------------------------------------------------------------------------
# Noisy


@pytest.mark.slow
def test_the_noisy_participants_commands_spread_as_documented():
    ticks = 2500
    clean, _ = reach_commands(params(), [(0.0, 2)], ticks)
    noisy, active = reach_commands(params(command_noise=0.3, command_noise_time=0.0),
                                   [(0.0, 2)], ticks)
    # Teleop's robot does not move the hand: it takes over after its patience, for good.
    assert not active[:PATIENCE].any() and active[PATIENCE:].all()
    assert not noisy[:PATIENCE].any()
    noise = (noisy - clean)[PATIENCE:, [0, 1, 3]]
    rotation_speed = VirtualParticipantParams().rotation_speed
    expected = 0.3 * np.array([SPEED, SPEED, rotation_speed])
    assert np.allclose(noise.std(axis=0), expected, rtol=0.06)
    assert np.allclose(noise.mean(axis=0), 0.0, atol=0.1 * expected)
    assert np.all(noisy[:, 2] == 0.0)  # the hand's height is never commanded


@pytest.mark.slow
def test_one_seed_gives_the_same_noise_whatever_the_participant_does():
    impairment = dict(command_noise=0.3, command_noise_time=0.5)
    noise = []
    for target in (0, 1):  # two tasks: different commands, one seed
        clean, _ = reach_commands(params(), [(0.0, target)], 150)
        noisy, _ = reach_commands(params(**impairment), [(0.0, target)], 150)
        noise.append(noisy - clean)
    assert np.allclose(noise[0], noise[1], rtol=0.0, atol=1e-15)
    assert np.abs(noise[0]).max() > 0.01
    assert not noise[0][:PATIENCE].any()  # nothing added before it acts
    again, _ = reach_commands(params(**impairment), [(0.0, 1)], 150)
    other_seed, _ = reach_commands(params(**impairment), [(0.0, 1)], 150, seed=5)
    assert np.array_equal(again, noise[1] + reach_commands(params(), [(0.0, 1)], 150)[0])
    assert not np.allclose(again, other_seed)


@pytest.mark.slow
def test_the_noisy_participant_acts_no_more_often_and_never_pushes_forward():
    # Without the forward key, the robot showing the left object, the target right: it
    # sidesteps.
    clean, clean_active = reach_commands(params(), [(0.0, 1)], 300, forward_key=False,
                                         selected=0)
    noisy, active = reach_commands(params(command_noise=0.5), [(0.0, 1)], 300,
                                   forward_key=False, selected=0)
    assert active.all()
    assert np.array_equal(active, clean_active)
    assert not np.allclose(noisy, clean)
    # Its heading drifts with the noise only as far as its turns take it; here it is
    # held, and no command has a forward part along it.
    assert np.all(noisy[:, :2] @ facing(0.0) <= 1e-12)
    # Where it does not act (the robot shows the target and brings the hand there), it
    # adds nothing.
    offset = OBJECTS[0] - HAND
    idle, idle_active = reach_commands(params(command_noise=0.5), [(0.0, 0)], 50,
                                       forward_key=False, selected=0,
                                       hand_velocity=SPEED * offset / np.linalg.norm(offset))
    assert not idle_active.any() and not idle.any()


# ---------------------------------------------------------------------------------------------
# Late


@pytest.mark.slow
def test_the_late_participant_sends_the_same_commands_the_delay_later():
    # The target switches from the left object to the right one at 1.2 s.
    schedule = [(0.0, 0), (1.2, 1)]
    calibrated = VirtualParticipantParams()  # its own noise on: the same draws, later
    late = dataclasses.replace(calibrated,
                               impairment=ParticipantImpairment(command_delay=0.3))
    on_time, on_time_active = reach_commands(calibrated, schedule, 150)
    delayed, delayed_active = reach_commands(late, schedule, 150)
    shift = 10  # 0.3 s at 30 ms
    assert np.array_equal(delayed[shift:], on_time[:-shift])
    assert np.array_equal(delayed_active[shift:], on_time_active[:-shift])
    # Before its first commands arrive, the robot gets nothing.
    assert not delayed[:shift].any() and not delayed_active[:shift].any()
    # It reacts to the switch its reaction_delay, its patience with the still hand and the
    # delay after it.
    turned = np.flatnonzero([toward(command, OBJECTS[1]) > 0.9 for command in delayed])
    assert turned[0] * PERIOD == pytest.approx(
        1.2 + calibrated.reaction_delay + calibrated.serve_patience + 0.3, abs=1.5 * PERIOD)


def grasp_twists(ticks=120, **impairment):
    """`(twists (ticks, 6), active (ticks,))` of a lone grasp participant (seed 2), impaired
    as given, the hand held at HAND, under teleop (no intent shown, the forward key on),
    its target object 0, then object 1 from 1 s."""
    orientations = np.array([side_grasp_orientation(0.4), side_grasp_orientation(-0.4)])
    participant = GraspParticipant.create(
        GraspParticipantParams(impairment=ParticipantImpairment(**impairment)),
        SPEED, OBJECTS[:2], orientations, seed=2)
    builder = DiagramBuilder()
    system = builder.AddSystem(PoseVirtualOperator(participant, PERIOD))
    hand = np.concatenate([HAND, side_grasp_orientation(0.0), np.zeros(6)])
    for port, source in ((system.get_hand_pose_input_port(), ConstantVectorSource(hand)),
                         (system.get_target_input_port(), target_source([(0.0, 0),
                                                                         (1.0, 1)])),
                         (system.get_selected_goal_input_port(),
                          ConstantVectorSource(np.array([float(NO_INTENT)]))),
                         (system.get_forward_key_input_port(),
                          ConstantVectorSource(np.ones(1)))):
        builder.Connect(builder.AddSystem(source).get_output_port(), port)
    return _sampled(builder, system, ticks)


def test_the_noisy_grasp_participant_adds_its_seeds_noise_to_its_twists_while_it_acts():
    (clean, clean_active), (noisy, active) = grasp_twists(), grasp_twists(
        command_noise=0.3, command_noise_time=0.0)
    assert np.array_equal(active, clean_active) and active.sum() > 40
    assert not noisy[~active].any()
    noise = (noisy - clean)[active]
    # Each axis's noise a fresh draw a tick (no correlation time), of standard deviation
    # 0.3 times its speed: m/s for the velocity, rad/s for the turn rate.
    scales = 0.3 * np.repeat([SPEED, GraspParticipantParams().rotation_speed], 3)
    assert np.all((noise.std(axis=0) > 0.5 * scales) & (noise.std(axis=0) < 1.5 * scales))
    assert np.array_equal(grasp_twists(command_noise=0.3, command_noise_time=0.0)[0], noisy)


@pytest.mark.slow
def test_the_late_grasp_participant_sends_the_same_twists_the_delay_later():
    (on_time, on_time_active), (delayed, delayed_active) = (
        grasp_twists(command_delay=0.0), grasp_twists(command_delay=0.45))
    shift = 15
    # Under teleop it takes over once it has noticed a target and watched the still hand
    # for its patience, and keeps on until it notices the next (at 1 s), when it watches
    # afresh.
    defaults = GraspParticipantParams()
    reacts = int(np.ceil(defaults.reaction_delay / PERIOD - 1e-9))
    patience = round(defaults.serve_patience / PERIOD)
    noticed = int(np.ceil((1.0 + defaults.reaction_delay) / PERIOD - 1e-9))
    assert not on_time_active[:reacts + patience].any()
    assert on_time_active[reacts + patience:noticed].all()
    assert not on_time_active[noticed:noticed + patience].any()
    assert on_time_active[noticed + patience + 1:].all()
    assert np.array_equal(delayed[shift:], on_time[:-shift])
    assert np.array_equal(delayed_active[shift:], on_time_active[:-shift])
    assert not delayed[:shift].any()


def test_a_participant_the_systems_cannot_run_is_refused():
    # The scenario checks the impairment first; a Python caller meets the system's check.
    with pytest.raises(ValueError, match="params.impairment.command_delay must be finite and "
                       "not negative, got -0.3"):
        VirtualOperator(PERIOD, OBJECTS, params=params(command_delay=-0.3), nominal_speed=SPEED)
    with pytest.raises(ValueError, match=r"participant must be a GraspParticipant \("):
        PoseVirtualOperator(GraspParticipantParams(), PERIOD)


# ---------------------------------------------------------------------------------------------
# Mistaken


def test_the_mistaken_participant_heads_for_another_object_then_for_the_target():
    mistaken = params(mistake_probability=1.0, mistake_time=0.9)
    commands, active = reach_commands(mistaken, [(0.0, 1)], 80)
    # Teleop's still hand: it takes over after its patience.
    assert not active[:PATIENCE].any() and active[PATIENCE:].all()
    wrong_ticks = 30  # 0.9 s
    # With the target the right object, it first heads for one of the others ...
    first = max(range(3), key=lambda index: toward(commands[PATIENCE], OBJECTS[index]))
    assert first != 1
    assert all(toward(command, OBJECTS[first]) > 0.999
               for command in commands[PATIENCE:wrong_ticks])
    # ... then sees its mistake and heads for the target.
    assert all(toward(command, OBJECTS[1]) > 0.999 for command in commands[wrong_ticks:])
    # The unimpaired one heads for the target from the first tick it acts.
    right, _ = reach_commands(params(), [(0.0, 1)], PATIENCE + 5)
    assert all(toward(command, OBJECTS[1]) > 0.999 for command in right[PATIENCE:])


def test_a_mistaken_participant_assisting_leaves_the_robot_to_the_wrong_object():
    # The robot shows the object it mistook the target for and brings the hand there: it is
    # content, and acts only once it sees its mistake. Which object it mistakes comes from
    # the seed.
    mistaken = params(mistake_probability=1.0, mistake_time=0.9)
    commands, _ = reach_commands(mistaken, [(0.0, 1)], PATIENCE + 1)
    wrong = max(range(3), key=lambda index: toward(commands[PATIENCE], OBJECTS[index]))
    offset = OBJECTS[wrong] - HAND
    robot = SPEED * offset / np.linalg.norm(offset)
    _, active = reach_commands(mistaken, [(0.0, 1)], 60, forward_key=False, selected=wrong,
                               hand_velocity=robot)
    assert not active[:30].any()
    assert active[30:].all()
    _, unimpaired = reach_commands(params(), [(0.0, 1)], 5, forward_key=False,
                                   selected=wrong, hand_velocity=robot)
    assert unimpaired.all()


def test_each_new_target_may_be_mistaken_again():
    mistaken = params(mistake_probability=1.0, mistake_time=0.6)
    commands, active = reach_commands(mistaken, [(0.0, 0), (1.5, 2)], 120)
    wrong_ticks, switch = 20, 50  # 0.6 s; the switch at 1.5 s
    # The first target, known from the start (acting once its patience with teleop's
    # still hand has passed) ...
    assert all(toward(command, OBJECTS[0]) < 0.99
               for command in commands[PATIENCE:wrong_ticks])
    assert all(toward(command, OBJECTS[0]) > 0.999 for command in commands[wrong_ticks:switch])
    # ... and the second once it has noticed it, its reaction_delay after the switch (and
    # acts its patience later).
    acting = switch + np.flatnonzero(active[switch:])[0]
    defaults = VirtualParticipantParams()
    assert (acting - switch) * PERIOD == pytest.approx(
        defaults.reaction_delay + defaults.serve_patience, abs=1.5 * PERIOD)
    after = commands[acting:]
    assert all(toward(command, OBJECTS[2]) < 0.99
               for command in after[:wrong_ticks - PATIENCE])
    assert all(toward(command, OBJECTS[2]) > 0.999
               for command in after[wrong_ticks - PATIENCE:])
