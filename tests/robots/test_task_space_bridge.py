"""The task-space bridge over Drake's LCM in one process (memq:// only): a controller drives
the HSR station through the bridge and a relay as it drives the station itself, a period
later; no relay and a bad state each end the run with one clear error."""

import numpy as np
import pytest
from pydrake.lcm import DrakeLcm, DrakeLcmParams
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake import EeCommand, EeState, HsrStationConfig, hsr_initial_ee_state, make_hsr_station
from pbp_drake.robots import DriverError
from pbp_drake.robots.task_space_bridge import (
    TaskSpaceBridgeConfig, make_station_relay, make_task_space_bridge, signal)

PERIOD = 0.1


class Sideways(LeafSystem):
    """The README's controller: the hand to its left at 5 cm/s, from where it is."""

    def __init__(self, start):
        super().__init__()
        self._ee_state = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._heading = start[6]
        command = self.DeclareDiscreteState(start[:EeCommand.size])
        self.DeclareStateOutputPort("ee_command", command)
        self.DeclarePeriodicDiscreteUpdateEvent(PERIOD, 0.0, self._update)

    def _update(self, context, state):
        hand, v = self._ee_state.Eval(context)[:3], np.array([0.0, 0.05, 0.0])
        state.set_value(np.concatenate([hand + v * PERIOD, v, [self._heading]]))


def hand_path(bridged, seconds=2.0):
    station = make_hsr_station(HsrStationConfig(control_period=PERIOD))
    start = hsr_initial_ee_state(station)
    builder = DiagramBuilder()
    if bridged:
        lcm, config = DrakeLcm("memq://"), TaskSpaceBridgeConfig()
        builder.AddSystem(make_station_relay(station, lcm, config, start))
        station = builder.AddSystem(make_task_space_bridge(config, start, PERIOD, lcm))
    else:
        station = builder.AddSystem(station)
    controller = builder.AddSystem(Sideways(start))
    builder.Connect(station.GetOutputPort("ee_state"), controller.get_input_port())
    builder.Connect(controller.get_output_port(), station.GetInputPort("ee_command"))
    simulator = Simulator(builder.Build())
    context = station.GetMyContextFromRoot(simulator.get_context())
    path = []
    for tick in range(1, int(round(seconds / PERIOD)) + 1):
        simulator.AdvanceTo(tick * PERIOD)
        path.append(np.array(station.GetOutputPort("ee_state").Eval(context))[:3])
    return np.array(path), start


@pytest.mark.slow
def test_a_controller_drives_the_station_through_the_bridge_a_period_later():
    direct, start = hand_path(bridged=False)
    bridged, _ = hand_path(bridged=True)
    assert direct[-1][1] - start[1] > 0.06  # the hand went left
    # Across the bus the state the controller reads is at most the relay's state period
    # (5 ms) old: the hand moves the same way, at nearly the same speed; it starts at most
    # two ticks later (nothing is sent before the relay's first state has come).
    speed = np.linalg.norm(np.diff(bridged, axis=0), axis=1)[5:] / PERIOD
    np.testing.assert_allclose(speed, 0.05, atol=0.005)
    assert np.abs(bridged[-1] - direct[-1]).max() < 2 * PERIOD * 0.05 + 1e-3


def bridge_alone(messages, seconds, **config):
    """The bridge with a constant command, fed `messages(t)` on the state channel."""
    lcm = DrakeLcm("memq://")
    config = TaskSpaceBridgeConfig(**config)
    builder = DiagramBuilder()
    bridge = builder.AddSystem(make_task_space_bridge(config, np.zeros(8), PERIOD, lcm))
    command = builder.AddSystem(ConstantVectorSource(np.zeros(7)))
    builder.Connect(command.get_output_port(), bridge.GetInputPort("ee_command"))
    sent = []
    lcm.Subscribe(config.command_channel, lambda data: sent.append(data))
    simulator = Simulator(builder.Build())
    for tick in range(1, int(round(seconds / PERIOD)) + 1):
        message = messages(tick * PERIOD)
        if message is not None:
            lcm.Publish(config.state_channel, message.encode())
        simulator.AdvanceTo(tick * PERIOD)
    return sent


def test_no_relay_ends_the_run_within_its_connect_timeout():
    with pytest.raises(DriverError, match=r"no state from the robot's relay on PBP_EE_STATE "
                                          r"\(bus memq://\) within 0.5 s"):
        bridge_alone(lambda t: None, 2.0, connect_timeout=0.5,
                     lcm_bus=DrakeLcmParams(lcm_url="memq://"))


def test_a_state_of_the_wrong_size_ends_the_run_and_nothing_is_sent():
    sent = []
    with pytest.raises(DriverError, match="holds 7 values"):
        sent = bridge_alone(lambda t: signal(np.zeros(7), list("abcdefg"), t), 1.0)
    assert sent == []


@pytest.mark.parametrize("field, value, message", [
    ("status_timeout", 0.0, "status_timeout must be finite and positive"),
    ("state_channel", "", "state_channel must be a channel name"),
    ("lcm_bus", DrakeLcmParams(lcm_url="udpm://10.0.0.1:7667"),
     "lcm_bus.lcm_url 'udpm://10.0.0.1:7667' is not an LCM URL"),
])
def test_a_bad_bridge_config_is_refused_naming_the_field(field, value, message):
    with pytest.raises(ValueError, match=f"^TaskSpaceBridgeConfig.{message}"):
        make_task_space_bridge(TaskSpaceBridgeConfig(**{field: value}), np.zeros(8), PERIOD,
                               DrakeLcm("memq://"))
