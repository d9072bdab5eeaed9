"""Drives an HSR station the way the PBP control loop does (a test helper).

Every control period the hand's state is sampled at the tick (a ``SampleHold``, as in the
PBP diagram) and, at the tick's decide stage, the driver commands ``[y + v dt, v,
heading0]``: the state to be in at the next tick, re-integrated from the measured hand, so
any tracking lag directly slows the hand.
"""

import dataclasses

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput

from pbp_drake.robots import HsrStationConfig, make_hsr_station
from pbp_drake.systems import SampleHold
from pbp_drake.systems.ports import EeState
from pbp_drake.systems.tick import decide_offset

CONTROL_PERIOD = 0.03


class TickDriver(LeafSystem):
    """Commands ``[y + v dt, v, heading]`` at each tick's decide stage
    (``pbp_drake.systems.tick``), with ``y`` the hand's position sampled at the tick,
    ``v = velocity(t_k)`` and ``heading = heading0 + turn(t_k)`` (``turn`` 0 when
    None)."""

    def __init__(self, period, start, velocity, turn=None):
        super().__init__()
        self._period = period
        self._velocity = velocity
        self._heading = EeState(start).heading
        self._turn = turn
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        command = np.concatenate([start[:3], np.zeros(3), [self._heading]])
        state = self.DeclareDiscreteState(command)
        self.DeclarePeriodicDiscreteUpdateEvent(period, decide_offset(period), self._decide)
        self.DeclareStateOutputPort("ee_command", state)

    def _decide(self, context, discrete_state):
        y = self._ee_state_port.Eval(context)[:3]
        time = context.get_time()
        v = np.asarray(self._velocity(time), float)
        heading = self._heading + (self._turn(time) if self._turn else 0.0)
        discrete_state.set_value(np.concatenate([y + v * self._period, v, [heading]]))


@dataclasses.dataclass
class Drive:
    """What a drive logged. At a tick the loggers hold the state at that tick and the
    command decided at the tick before."""

    tick_times: np.ndarray
    hands: np.ndarray  # (3, ticks): the hand's position at each tick
    headings: np.ndarray  # (ticks,): the hand's heading at each tick
    commands: np.ndarray  # (7, ticks): the command in force up to each tick
    state_times: np.ndarray
    states: np.ndarray  # the plant's state every state_period
    desired_states: np.ndarray  # the station's desired_state every state_period

    def speeds(self, direction):
        """The hand's per-tick speed along ``direction`` (unit): one-tick differences of
        its positions at the ticks, over the period."""
        return np.asarray(direction) @ np.diff(self.hands, axis=1) / CONTROL_PERIOD


def drive(velocity, duration, config=None, state_period=None, turn=None, station=None):
    """Runs a station of ``config`` (its ``control_period`` set to the tick; or `station`,
    any station with those ports, built with that period) under the driver (``velocity``,
    ``turn``) for ``duration`` seconds; the plant's state and the desired state are logged
    every ``state_period`` (the plant's step when None)."""
    config = dataclasses.replace(config or HsrStationConfig(), control_period=CONTROL_PERIOD)
    station = station or make_hsr_station(config)
    builder = DiagramBuilder()
    builder.AddNamedSystem(station.get_name(), station)
    start = np.array(station.GetOutputPort("ee_state").Eval(station.CreateDefaultContext()))
    sample = builder.AddNamedSystem("ee_state_sample", SampleHold(CONTROL_PERIOD, start))
    builder.Connect(station.GetOutputPort("ee_state"), sample.get_input_port())
    driver = builder.AddNamedSystem("driver", TickDriver(CONTROL_PERIOD, start, velocity, turn))
    builder.Connect(sample.get_output_port(), driver.get_input_port())
    builder.Connect(driver.get_output_port(), station.GetInputPort("ee_command"))
    period = state_period or config.plant.time_step
    logs = [LogVectorOutput(station.GetOutputPort("ee_state"), builder, CONTROL_PERIOD),
            LogVectorOutput(driver.get_output_port(), builder, CONTROL_PERIOD),
            LogVectorOutput(station.GetOutputPort("state"), builder, period),
            LogVectorOutput(station.GetOutputPort("desired_state"), builder, period)]
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(duration)
    ee, commands, states, desired = (log.FindLog(simulator.get_context()) for log in logs)
    return Drive(ee.sample_times(), ee.data()[:3], ee.data()[6], commands.data(),
                 states.sample_times(), states.data(), desired.data())
