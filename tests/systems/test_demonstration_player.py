"""DemonstrationPlayer: its references follow the demonstration one control period ahead."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from pbp_drake.systems.pbp.demonstration_player import DemonstrationPlayer

PERIOD = 0.1
VELOCITY = np.array([0.5, -0.2])
# Recorded from 3 s to 5 s: the player plays it from its own 0 s.
RECORDED_START = 3.0
DURATION = 2.0


def demonstration_at(time):
    """The demonstration's position `time` seconds after it starts (a straight line)."""
    return np.array([0.0, 1.0]) + VELOCITY * np.clip(time, 0.0, DURATION)


def player():
    times = np.linspace(0.0, DURATION, 21)
    positions = np.array([demonstration_at(t) for t in times])
    return DemonstrationPlayer(RECORDED_START + times, positions, PERIOD)


def references_at(simulator, system, time):
    simulator.AdvanceTo(time)
    return system.get_references_output_port().Eval(simulator.get_context())


def test_before_the_first_tick_it_holds_the_demonstration_one_period_in():
    system = player()
    simulator = Simulator(system)
    simulator.Initialize()
    references = system.get_references_output_port().Eval(simulator.get_context())
    np.testing.assert_allclose(references, np.concatenate([demonstration_at(PERIOD), VELOCITY]))


@pytest.mark.parametrize("time, tick", [(0.05, 0.0), (0.55, 0.5), (1.25, 1.2), (1.85, 1.8)])
def test_between_ticks_it_holds_the_demonstration_a_period_after_the_last_tick(time, tick):
    system = player()
    simulator = Simulator(system)
    references = references_at(simulator, system, time)
    np.testing.assert_allclose(references[:2], demonstration_at(tick + PERIOD), atol=1e-12)
    np.testing.assert_allclose(references[2:], VELOCITY, atol=1e-12)


def test_after_the_end_it_holds_the_last_sample_at_rest():
    system = player()
    simulator = Simulator(system)
    references = references_at(simulator, system, DURATION + 0.55)
    np.testing.assert_allclose(references, np.concatenate([demonstration_at(DURATION),
                                                           np.zeros(2)]), atol=1e-12)


def test_the_player_plays_the_same_whatever_the_robot_does():
    # No inputs at all: an open-loop, time-indexed policy.
    assert player().num_input_ports() == 0
