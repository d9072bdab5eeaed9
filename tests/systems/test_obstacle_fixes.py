"""The two causes of the obstacle task's failures, each checked on its own: a DMP held off
its path by the operator in PBP-Cont must not wind its velocity up past the hand's speed
limit (it then overrode the operator and dragged the robot through the cylinders), and a
participant whose way round has stalled must push on instead of waiting for ever."""

import dataclasses

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.core.dmp import DmpBankModel as DmpBankMath
from pbp_drake.core.dmp import DmpSettings, fit_weights
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_serving import NO_INTENT
from pbp_drake.systems import VirtualOperator
from pbp_drake.systems.pbp.dmp_bank import DmpBank
from pbp_drake.core.avoidance import (
    is_pushing_through, robot_closes_in, start_watch, update_watch)

PERIOD = 0.03
PARAMS = VirtualParticipantParams()
STALL_TIME = PARAMS.stall_time
HAND_SPEED_LIMIT = 0.2


def straight_reach_bank():
    """One DMP of a 1 m straight reach along x, 8 s long (0.125 m/s on average)."""
    settings = DmpSettings(basis_count=20)
    times = np.linspace(0.0, 8.0, 200)
    s = times / times[-1]
    path = np.stack([10 * s**3 - 15 * s**4 + 6 * s**5, 0 * s, 0 * s], 1)
    weights, scaling = fit_weights(times, path, settings)
    return DmpBankMath(weights, np.zeros(3), 8.0, settings, scaling, goal_count=1)


def peak_reference_speed_while_held(max_speed):
    """The fastest reference velocity over 12 s of a DMP whose robot the operator holds
    at its start, a metre from the goal (PBP-Cont: the phase runs on)."""
    system = DmpBank(straight_reach_bank(), PERIOD, max_speed=max_speed)
    context = system.CreateDefaultContext()
    system.get_robot_state_input_port().FixValue(context, np.zeros(6))
    system.get_goals_input_port().FixValue(context, [1.0, 0.0, 0.0])
    system.get_operator_active_input_port().FixValue(context, [1.0])
    simulator = Simulator(system, context)
    peak = 0.0
    for tick in range(int(12.0 / PERIOD)):
        simulator.AdvanceTo((tick + 0.9) * PERIOD)
        velocity = system.get_references_output_port().Eval(context).reshape(2, 3)[1]
        peak = max(peak, np.linalg.norm(velocity))
    return peak


@pytest.mark.slow
def test_a_held_dmp_winds_up_past_the_hand_speed_limit_without_the_limit():
    assert peak_reference_speed_while_held(None) > 2 * HAND_SPEED_LIMIT


@pytest.mark.slow
def test_a_held_dmp_stays_near_the_hand_speed_limit_with_it():
    # One step of the attractor on top of the limited velocity exceeds it a little (the
    # hand-over law caps that); without the limit this DMP reaches 0.79 m/s.
    assert peak_reference_speed_while_held(HAND_SPEED_LIMIT) < 1.3 * HAND_SPEED_LIMIT


def watch_after(distances):
    watch = start_watch(distances[0])
    for distance in distances[1:]:
        watch = update_watch(PARAMS, watch, distance, PERIOD)
    return watch


def test_a_participant_parked_before_a_wall_pushes_through_once_it_has_waited():
    ticks = int(STALL_TIME / PERIOD)
    parked = [0.62] * (ticks + 2)
    assert not is_pushing_through(watch_after(parked[: ticks - 5]))
    assert is_pushing_through(watch_after(parked))


def test_a_participant_that_keeps_getting_closer_never_pushes_through():
    # 1 cm a second, slower than any real run: every progress_step resets the wait.
    distances = 1.0 - 0.01 * PERIOD * np.arange(int(10 * STALL_TIME / PERIOD))
    assert PARAMS.progress_step / 0.01 < STALL_TIME
    assert not is_pushing_through(watch_after(distances))


def test_once_pushing_a_participant_keeps_pushing_until_it_arrives():
    ticks = int(STALL_TIME / PERIOD) + 2
    watch = watch_after([0.62] * ticks + list(np.linspace(0.6, 0.1, 50)))
    assert is_pushing_through(watch)


def test_near_the_target_a_participant_lets_a_robot_that_closes_in_finish_alone():
    assert robot_closes_in(PARAMS, [0.05, 0.0], [0.07, 0.0], nominal_speed=0.12)
    # On the target itself: nothing left to close in on.
    assert robot_closes_in(PARAMS, [0.0, 0.0], [0.0, 0.0], nominal_speed=0.12)


def test_near_the_target_a_participant_drives_a_robot_that_has_parked():
    # The PBP-Alt DMP, its phase frozen early, balanced 8 cm short of the target.
    assert not robot_closes_in(PARAMS, [0.004, 0.003], [0.07, 0.04], nominal_speed=0.12)
    assert not robot_closes_in(PARAMS, [-0.03, 0.0], [0.07, 0.0], nominal_speed=0.12)


def test_a_lower_closing_fraction_lets_a_slow_robot_finish_alone():
    # 0.02 m/s toward the target is under a quarter of 0.12 m/s, over a tenth of it.
    slow = ([0.02, 0.0], [0.07, 0.0])
    assert not robot_closes_in(PARAMS, *slow, nominal_speed=0.12)
    patient = dataclasses.replace(PARAMS, min_closing_fraction=0.1)
    assert robot_closes_in(patient, *slow, nominal_speed=0.12)


# A wall of three cylinders 0.35 m ahead of a parked hand, the target 1.5 m beyond: no
# way round gets it closer, so it stalls.
HAND = np.array([0.0, 0.0])
TARGET = np.array([1.5, 0.0])
WALL = np.array([[0.35, -0.3], [0.35, 0.0], [0.35, 0.3]])


def first_push_time(params, seconds):
    """When (s) a participant whose hand stays parked before WALL first commands the
    push-through (straight at the target, no turning); None if not within `seconds`. As
    under teleop: the forward key enabled, no intent shown. The hand reports moving as
    commanded (it makes no progress, the stall this measures): a hand that does not follow
    the keys at all reads as a pull, against which the participant presses harder."""
    params = dataclasses.replace(params, direction_noise=0.0, speed_noise=0.0,
                                 reaction_delay=0.0)
    builder = DiagramBuilder()
    participant = builder.AddSystem(VirtualOperator(
        PERIOD, [[*TARGET, 0.7]], params=params, nominal_speed=0.12,
        obstacle_count=len(WALL), obstacle_radius=0.15))
    for port, value in ((participant.get_target_input_port(), [*TARGET, 0.7, 0]),
                        (participant.get_selected_goal_input_port(), [NO_INTENT]),
                        (participant.get_forward_key_input_port(), [1.0]),
                        (participant.get_obstacle_positions_input_port(), WALL.ravel())):
        source = builder.AddSystem(ConstantVectorSource(np.asarray(value, dtype=float)))
        builder.Connect(source.get_output_port(), port)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = participant.GetMyContextFromRoot(simulator.get_context())
    toward = (TARGET - HAND) / np.linalg.norm(TARGET - HAND)
    ee_state = participant.get_ee_state_input_port()
    command = np.zeros(4)
    for tick in range(1, int(round(seconds / PERIOD))):
        ee_state.FixValue(context, [*HAND, 0.7, command[0], command[1], 0.0, 0.0, 0.0])
        simulator.AdvanceTo((tick + 0.5) * PERIOD)
        command = np.array(participant.get_operator_command_output_port().Eval(context))
        speed = np.linalg.norm(command[:2])
        if speed > 0.1 and command[3] == 0.0 and command[:2] @ toward > 0.999999 * speed:
            return tick * PERIOD
    return None


@pytest.mark.slow
@pytest.mark.parametrize("stall_time", [2.0, 4.0])
def test_the_stall_time_is_how_long_a_parked_participant_waits_before_pushing(stall_time):
    pushed = first_push_time(dataclasses.replace(PARAMS, stall_time=stall_time), 7.0)
    assert pushed is not None and stall_time - 0.1 <= pushed <= stall_time + 0.1


@pytest.mark.slow
def test_a_longer_stall_time_delays_the_push_through():
    assert first_push_time(PARAMS, 5.0) is not None
    assert first_push_time(dataclasses.replace(PARAMS, stall_time=8.0), 5.0) is None


def test_a_participant_among_obstacles_needs_their_radius():
    with pytest.raises(ValueError, match="obstacle_radius must be positive with obstacles, "
                                         "got 0.0"):
        VirtualOperator(PERIOD, [[*TARGET, 0.7]], nominal_speed=0.12, obstacle_count=len(WALL))


@pytest.mark.parametrize("change, message", [
    ({"obstacle_margin": np.nan}, "obstacle_margin must be a finite distance >= 0, got nan"),
    ({"obstacle_margin": -0.1}, "obstacle_margin must be a finite distance >= 0, got -0.1"),
    ({"obstacle_count": 1.5}, "obstacle_count must be a whole number >= 0, got 1.5"),
    ({"obstacle_radius": np.inf}, "obstacle_radius must be positive with obstacles, got inf"),
    ({"fixed_base": [0.5]}, r"fixed_base must be the arm's base \(x, y\), two finite numbers, "
                            r"got \[0.5\]"),
    ({"fixed_base": 0.5}, r"fixed_base must be the arm's base \(x, y\)"),
    ({"fixed_base": [np.nan, 0.0]}, r"fixed_base must be the arm's base \(x, y\)"),
])
def test_a_participant_among_obstacles_names_an_argument_it_cannot_use(change, message):
    # A NaN margin failed every clearance test, a negative one let the hand touch: both
    # were taken without a word.
    arguments = dict(nominal_speed=0.12, obstacle_count=len(WALL), obstacle_radius=0.2)
    with pytest.raises(ValueError, match=message):
        VirtualOperator(PERIOD, [[*TARGET, 0.7]], **{**arguments, **change})
