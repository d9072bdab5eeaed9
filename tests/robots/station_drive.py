"""Drives an HSR station the way the PBP control loop does (a test helper).

Every control period the driver samples the hand's position y at the tick and commands
``[y + v dt, v, heading0]``: the state to be in at the next tick, re-integrated from the
measured hand, so any tracking lag directly slows the hand.
"""

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput

from pbp_drake.robots import HsrStationConfig, hsr_initial_ee_state, make_hsr_station
from pbp_drake.systems import SampleHold
from pbp_drake.systems.layouts import EeCommand, EeState
from pbp_drake.systems.tick import decide_offset

CONTROL_PERIOD = 0.03


class TickDriver(LeafSystem):
    """Commands ``[y + v dt, v, heading0]`` each tick, with ``y`` the hand's position
    sampled at the tick (a ``SampleHold`` in front, as in the PBP diagram) and ``v =
    velocity(t_k)``; it decides at the decide stage of the tick
    (``pbp_drake.systems.tick``), as the PBP controller does."""

    def __init__(self, period, start, velocity):
        super().__init__()
        self._period = period
        self._velocity = velocity
        self._heading = EeState(start).heading
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        command = np.concatenate([start[:3], np.zeros(3), [self._heading]])
        state = self.DeclareDiscreteState(command)
        self.DeclarePeriodicDiscreteUpdateEvent(period, decide_offset(period), self._decide)
        self.DeclareStateOutputPort("ee_command", state)

    def _decide(self, context, discrete_state):
        y = self._ee_state_port.Eval(context)[:3]
        v = np.asarray(self._velocity(context.get_time()), float)
        discrete_state.set_value(np.concatenate([y + v * self._period, v, [self._heading]]))


def drive(velocity, duration, config=None, state_period=None):
    """Runs a station (``config``, ``command_period`` set to the tick) under the driver.

    Returns (tick times, hand positions at the ticks (3, N), plant state times, plant
    states (2 nq... as logged every ``state_period``, the plant step when None)).
    """
    config = config if config is not None else HsrStationConfig()
    config.command_period = CONTROL_PERIOD
    station = make_hsr_station(config)
    builder = DiagramBuilder()
    builder.AddNamedSystem("hsr_station", station)
    start = hsr_initial_ee_state(station)
    sample = builder.AddNamedSystem("ee_state_sample", SampleHold(CONTROL_PERIOD, start))
    builder.Connect(station.GetOutputPort("ee_state"), sample.get_input_port())
    driver = builder.AddNamedSystem("driver", TickDriver(CONTROL_PERIOD, start, velocity))
    builder.Connect(sample.get_output_port(), driver.get_input_port())
    builder.Connect(driver.get_output_port(), station.GetInputPort("ee_command"))
    ee_log = LogVectorOutput(station.GetOutputPort("ee_state"), builder, CONTROL_PERIOD)
    state_log = LogVectorOutput(station.GetOutputPort("state"), builder,
                                state_period or config.plant.time_step)
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(duration)
    context = simulator.get_context()
    ee, state = ee_log.FindLog(context), state_log.FindLog(context)
    return ee.sample_times(), ee.data()[:3], state.sample_times(), state.data()


def tick_speeds(positions, direction):
    """Per-tick speed along ``direction`` (unit): one-tick differences / the period."""
    return np.asarray(direction) @ np.diff(positions, axis=1) / CONTROL_PERIOD
