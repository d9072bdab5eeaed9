"""A task-space bridge for robots whose interface is not Drake's (the HSR speaks ROS): a
station's ports as two LCM channels, so that a small relay on the robot's side is all a
user writes (docs/tasks/real-arm.md shows one for a ROS robot)::

    ee_command ─► BridgeLink ─► PBP_EE_COMMAND (lcmt_drake_signal: x y z vx vy vz heading)
    PBP_EE_STATE (lcmt_drake_signal: x y z vx vy vz heading heading_rate)
        ─► LcmSubscriberSystem ─► BridgeLink ─► ee_state

`BridgeLink` keeps the arm drivers' rules (`pbp_drake.robots.arm_driver`) where they
apply to any robot, on the wall clock unless the robot's side is simulated in the same
process (`driver_sim`); messages are stamped (`timestamp`, µs) on the simulation's clock.
"""

import dataclasses

import numpy as np
from drake import lcmt_drake_signal
from pydrake.common.value import Value
from pydrake.lcm import DrakeLcm, DrakeLcmParams
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.lcm import LcmInterfaceSystem, LcmSubscriberSystem

from pbp_drake.robots.arm_driver import (
    SIMULATION_CLOCK, WALL_CLOCK, DriverError, check_heard, check_on_the_wall_clock, clock_now,
    first_message)
from pbp_drake.robots.arm_station_config import DEFAULT_LCM_URL, validate_link
from pbp_drake.robots.hsr_station_config import check_config_type
from pbp_drake.systems.ports import EeCommand, EeState
from pbp_drake.systems.tick import checked_period, report_offset

COMMAND_FIELDS, STATE_FIELDS = list(EeCommand.get_fields()), list(EeState.get_fields())
#: How often (s) `make_station_relay` sends the station's state: a robot's state stream,
#: faster than the control loop.
RELAY_STATE_PERIOD = 0.005


@dataclasses.dataclass
class TaskSpaceBridgeConfig:
    """Where the bridge's two channels are, and how long the robot's state may be silent."""

    #: The LCM bus (Drake's DrakeLcmParams); the default stays on this machine (ttl=0).
    lcm_bus: DrakeLcmParams = dataclasses.field(
        default_factory=lambda: DrakeLcmParams(lcm_url=DEFAULT_LCM_URL))
    #: Where the hand's command goes out (EeCommand's 7 values).
    command_channel: str = "PBP_EE_COMMAND"
    #: Where the hand's state comes in (EeState's 8 values).
    state_channel: str = "PBP_EE_STATE"
    #: The longest the robot's state may be silent (s) once it has come.
    status_timeout: float = 0.2
    #: How long (s) the bridge waits for the first state.
    connect_timeout: float = 5.0
    #: How far (s) the control loop may run behind, or ahead of, the wall clock.
    command_expiry: float = 0.1
    #: How far (m) the hand in the robot's first state may stand from the start the run
    #: was built for (the scenario's).
    start_tolerance: float = 0.05
    #: Whether runs drive the robot through the bridge (`pbp-drake run --hardware`).
    connect: bool = False
    #: With connect: the robot's side simulated in the same process (the relay around the
    #: simulated station), both on one memq:// bus (`pbp-drake run --driver-sim`).
    driver_sim: bool = False


def validate_task_space_bridge(config: TaskSpaceBridgeConfig) -> None:
    """Raises ValueError naming the first field of `config` that cannot work."""
    check_config_type(config, TaskSpaceBridgeConfig)
    for name in ("command_channel", "state_channel"):
        if not isinstance(getattr(config, name), str) or not getattr(config, name):
            raise ValueError(f"TaskSpaceBridgeConfig.{name} must be a channel name, got "
                             f"{getattr(config, name)!r}")
    validate_link(config, "TaskSpaceBridgeConfig",
                  ("status_timeout", "connect_timeout", "command_expiry", "start_tolerance"))


def checked_ee_state(value):
    """`initial_ee_state` as floats; ValueError naming it unless 8 finite numbers (an
    EeState): it is the hand's state until the robot's first one comes."""
    try:
        ee_state = np.asarray(value, float).reshape(-1)
    except (TypeError, ValueError):
        ee_state = np.full(0, np.nan)
    if ee_state.size != EeState.size or not np.all(np.isfinite(ee_state)):
        shown = value.tolist() if isinstance(value, np.ndarray) else value
        raise ValueError(f"initial_ee_state must be {EeState.size} finite numbers (an EeState), "
                         f"got {shown!r}")
    return ee_state


def signal(values, names, time):
    """An lcmt_drake_signal of `values` named `names`, stamped `time` (s)."""
    message = lcmt_drake_signal()
    message.dim, message.val, message.coord = len(values), list(map(float, values)), names
    message.timestamp = int(round(time * 1e6))
    return message


def checked_state(message, config):
    """The EeState a state message of the robot's relay holds; DriverError when it is of
    the wrong size or not finite."""
    values = np.asarray(message.val, float)
    if len(values) != EeState.size or not np.all(np.isfinite(values)):
        raise DriverError(f"the robot's state on {config.state_channel} holds "
                          f"{len(values)} values (EeState's {EeState.size}, finite): "
                          f"{list(message.coord)}")
    return values


def check_hand_start(ee_state, initial_ee_state, tolerance):
    """DriverError when the hand of `ee_state` stands farther than `tolerance` (m) from
    that of `initial_ee_state`, the start the run was built for: its scene and its first
    plans are made for that start, and a hand elsewhere would be steered from where it is
    not."""
    hand, start = np.asarray(ee_state)[:3], np.asarray(initial_ee_state)[:3]
    off = float(np.linalg.norm(hand - start))
    if off > tolerance:
        where = ", ".join(f"{value:.3f}" for value in hand)
        built = ", ".join(f"{value:.3f}" for value in start)
        raise DriverError(
            f"the robot's hand stands at [{where}] m, {off:.3f} m from the start the run "
            f"was built for, [{built}] m (start_tolerance {tolerance:g} m): bring it there "
            "first; nothing was sent")


def read_first_state(config: TaskSpaceBridgeConfig, lcm, initial_ee_state):
    """The robot's first EeState from its relay on `lcm` (`first_message`'s), waiting at
    most `config.connect_timeout`, read before a run is built; DriverError naming the bus
    and the channel when none comes, and as `BridgeLink` for a bad state or a hand away
    from `initial_ee_state`."""
    message = first_message(
        lcm, config.state_channel, lcmt_drake_signal.decode, config.connect_timeout,
        f"no state from the robot's relay on {config.state_channel} (bus "
        f"{config.lcm_bus.lcm_url}) within {config.connect_timeout:g} s: is the relay "
        "running on that bus?")
    values = checked_state(message, config)
    check_hand_start(values, initial_ee_state, config.start_tolerance)
    return values


class BridgeLink(LeafSystem):
    """The station's side of a task-space bridge: nothing is sent before a fresh state; a
    state silent for `status_timeout`, of the wrong size or with a NaN, a first fresh state
    farther than `start_tolerance` from the run's start, or (on the wall clock) a loop
    `command_expiry` off the wall clock ends the run with `DriverError` and sends nothing
    more but `send_hold`'s command.

    .. pydrake_system::

        name: BridgeLink
        input_ports:
        - state_message
        - ee_command
        output_ports:
        - ee_state

    ``state_message`` is the last ``lcmt_drake_signal`` on the state channel (an
    ``LcmSubscriberSystem``'s output); ``ee_state`` the robot's ``EeState`` as the relay
    last sent it (``initial_ee_state`` before its first fresh state). The command is sent
    in a publish event after each control period's check.
    """

    def __init__(self, config, lcm, initial_ee_state, control_period):
        super().__init__()
        self._config, self._lcm = config, lcm
        self._clock = SIMULATION_CLOCK if config.driver_sim else WALL_CLOCK
        channel, bus = config.state_channel, config.lcm_bus.lcm_url
        self._first = f"state from the robot's relay on {channel} (bus {bus})"
        self._silent = f"the robot's state on {channel} (bus {bus})"
        # State: when the last fresh state message came (our clock), its stamp, the first
        # update's time and its wall clock less the simulation's, whether this update sends.
        self._AT, self._STAMP, self._STARTED, self._OFFSET, self._SEND = range(5)
        self._index = self.DeclareDiscreteState([np.nan, -1.0, np.nan, np.nan, 0.0])
        self.DeclareAbstractInputPort("state_message", Value(lcmt_drake_signal()))
        self.DeclareVectorInputPort("ee_command", EeCommand.size)
        self._initial = np.asarray(initial_ee_state, float)
        self.DeclareVectorOutputPort("ee_state", EeState.size, self._ee_state)
        self.DeclarePeriodicDiscreteUpdateEvent(control_period, 0.0, self._update)
        # Sent after the tick's decisions: the PBP controller's command (its hand-over's
        # state) changes at the tick's report stage (`pbp_drake.systems.tick`); a publish at
        # the tick itself would send the last tick's.
        after_decisions = report_offset(control_period, report_offset(control_period))
        self.DeclarePeriodicPublishEvent(control_period, after_decisions, self._send)

    def _ee_state(self, context, output):
        # The last message itself, not a sample of it: a controller that updates at the
        # same instant reads the robot's latest state.
        message = self.get_input_port(0).Eval(context)
        fresh = not np.isnan(context.get_discrete_state(self._index).value()[self._AT])
        output.SetFromVector(np.asarray(message.val, float) if fresh else self._initial)

    def _update(self, context, discrete_state):
        x = np.array(context.get_discrete_state(self._index).value())
        now, config = clock_now(self._clock, context), self._config
        if np.isnan(x[self._STARTED]):
            x[self._STARTED] = now
            x[self._OFFSET] = clock_now(WALL_CLOCK, context) - context.get_time()
        message = self.get_input_port(0).Eval(context)
        if message.dim and message.timestamp != x[self._STAMP]:
            if x[self._STAMP] < 0:
                # A udpm:// bus keeps the first message that came since it was last handled
                # and drops the later ones: at the run's first step, one as old as the
                # station (the page's wait for Start included). The next one is fresh.
                x[self._STAMP] = message.timestamp
            else:
                values = checked_state(message, config)
                if np.isnan(x[self._AT]):
                    check_hand_start(values, self._initial, config.start_tolerance)
                x[self._AT], x[self._STAMP] = now, message.timestamp
        then = "nothing more is sent, the robot is told to hold"
        heard = check_heard(now, x[self._STARTED], x[self._AT], config.connect_timeout,
                            config.status_timeout, self._first, self._silent, then)
        if heard and self._clock == WALL_CLOCK:
            check_on_the_wall_clock(context, x[self._OFFSET], config.command_expiry, then)
        x[self._SEND] = float(heard)
        discrete_state.set_value(self._index, x)

    def send_hold(self, context):
        """Sends the last command with no velocity, once the run has ended however it
        ended (`pbp_drake.builder.run`): a relay that passes the velocity on would keep the
        robot moving. Nothing when nothing was sent."""
        if np.isnan(context.get_discrete_state(self._index).value()[self._AT]):
            return
        held = EeCommand(np.array(self.get_input_port(1).Eval(context), float))
        held.vx = held.vy = held.vz = 0.0
        if np.all(np.isfinite(held[:])):
            self._lcm.Publish(self._config.command_channel, signal(
                held[:], COMMAND_FIELDS, context.get_time()).encode())

    def _send(self, context):
        x = context.get_discrete_state(self._index).value()
        command = np.asarray(self.get_input_port(1).Eval(context))
        if x[self._SEND] and np.all(np.isfinite(command)):
            self._lcm.Publish(self._config.command_channel, signal(
                command, COMMAND_FIELDS, context.get_time()).encode())


def make_task_space_bridge(config: TaskSpaceBridgeConfig, initial_ee_state, control_period,
                           lcm=None) -> Diagram:
    """A Diagram named ``task_space_bridge`` with a station's ports, whose robot is on the
    far side of `config`'s LCM channels on `lcm` (default a DrakeLcm on `config.lcm_bus`),
    with its own `LcmInterfaceSystem`; `initial_ee_state` is the hand's ``EeState`` until
    the relay's first state comes. Raises ValueError naming a field of `config` that cannot
    work."""
    validate_task_space_bridge(config)
    initial_ee_state = checked_ee_state(initial_ee_state)
    control_period = checked_period(control_period)
    lcm = lcm or DrakeLcm(config.lcm_bus)
    builder = DiagramBuilder()
    builder.AddNamedSystem("lcm", LcmInterfaceSystem(lcm))
    subscriber = builder.AddNamedSystem("state_subscriber", LcmSubscriberSystem.Make(
        config.state_channel, lcmt_drake_signal, lcm))
    link = builder.AddNamedSystem("bridge_link", BridgeLink(config, lcm, initial_ee_state,
                                                            control_period))
    builder.Connect(subscriber.get_output_port(), link.GetInputPort("state_message"))
    builder.ExportInput(link.GetInputPort("ee_command"), "ee_command")
    builder.ExportOutput(link.GetOutputPort("ee_state"), "ee_state")
    bridge = builder.Build()
    bridge.set_name("task_space_bridge")
    return bridge


class _Relay(LeafSystem):
    """The robot's side: the last command that came in, as the station's ee_command, and
    the station's ee_state out on the state channel every `state_period`."""

    def __init__(self, config, lcm, initial_command, state_period):
        super().__init__()
        self._config, self._lcm = config, lcm
        self._initial = np.asarray(initial_command, float)
        self.DeclareAbstractInputPort("command_message", Value(lcmt_drake_signal()))
        self.DeclareVectorInputPort("ee_state", EeState.size)
        self.DeclareVectorOutputPort("ee_command", EeCommand.size, self._command)
        self.DeclarePeriodicPublishEvent(state_period, 0.0, self._publish)

    def _command(self, context, output):
        message = self.get_input_port(0).Eval(context)
        output.SetFromVector(np.asarray(message.val) if message.dim == EeCommand.size
                             else self._initial)

    def _publish(self, context):
        state = self.get_input_port(1).Eval(context)
        self._lcm.Publish(self._config.state_channel,
                          signal(state, STATE_FIELDS, context.get_time()).encode())


def make_station_relay(station, lcm, config: TaskSpaceBridgeConfig, initial_ee_state,
                       state_period=RELAY_STATE_PERIOD) -> Diagram:
    """The robot's side: `station` (any Diagram with ``ee_command`` and ``ee_state``)
    behind the bridge's channels on `lcm`, with its own `LcmInterfaceSystem`, as a ROS
    relay is shaped: each command goes to the station as it comes, and its state goes out
    every `state_period` s. Raises ValueError naming an argument that cannot work."""
    if not isinstance(station, Diagram):
        raise ValueError(f"station must be a Diagram (a station), got {type(station).__name__}")
    check_config_type(config, TaskSpaceBridgeConfig)
    initial_ee_state = checked_ee_state(initial_ee_state)
    state_period = checked_period(state_period, "state_period")
    builder = DiagramBuilder()
    builder.AddNamedSystem("lcm", LcmInterfaceSystem(lcm))
    station = builder.AddSystem(station)
    subscriber = builder.AddNamedSystem("command_subscriber", LcmSubscriberSystem.Make(
        config.command_channel, lcmt_drake_signal, lcm))
    relay = builder.AddNamedSystem("relay", _Relay(
        config, lcm, np.asarray(initial_ee_state)[:EeCommand.size], state_period))
    builder.Connect(subscriber.get_output_port(), relay.GetInputPort("command_message"))
    builder.Connect(relay.GetOutputPort("ee_command"), station.GetInputPort("ee_command"))
    builder.Connect(station.GetOutputPort("ee_state"), relay.GetInputPort("ee_state"))
    diagram = builder.Build()
    diagram.set_name("station_relay")
    return diagram


def make_bridged_station(config: TaskSpaceBridgeConfig, initial_ee_state, control_period,
                         robot_side=None) -> Diagram:
    """A run's station through the bridge (``pbp-drake run --hardware``): on
    `config.lcm_bus` to the robot's relay, or with `config.driver_sim` to `robot_side` (the
    simulated station) behind `make_station_relay`, both on a memq:// bus of their own."""
    validate_task_space_bridge(config)
    builder = DiagramBuilder()
    if config.driver_sim:
        lcm = DrakeLcm("memq://")
        builder.AddNamedSystem("robot_side", make_station_relay(
            robot_side, lcm, config, initial_ee_state))
    else:
        lcm = DrakeLcm(config.lcm_bus)
    bridge = builder.AddSystem(make_task_space_bridge(config, initial_ee_state,
                                                      control_period, lcm))
    builder.ExportInput(bridge.GetInputPort("ee_command"), "ee_command")
    builder.ExportOutput(bridge.GetOutputPort("ee_state"), "ee_state")
    station = builder.Build()
    station.set_name("bridged_station")
    return station
