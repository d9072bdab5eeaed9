"""A driver simulator: the arm of an `ArmStationConfig` behind the LCM channels and rules of
its Drake driver, so that the station's whole LCM path runs with no robot (`pbp-drake
driver-sim FILE` on the bus, or in the run's process with `run --hardware --driver-sim`)::

    LcmSubscriberSystem (COMMAND channel) ─► DriverSim ─► status on the STATUS channel
"""

import numpy as np
from pydrake.common.value import Value
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.lcm import LcmInterfaceSystem, LcmSubscriberSystem

from pbp_drake.robots.arm_driver import (
    PANDA_POSITION_MODE, clock_now, command_type, status_message)
from pbp_drake.robots.arm_station_config import DRIVERS
from pbp_drake.systems.tick import decide_offset

# drake-franka-driver's default --expire_sec (s).
PANDA_EXPIRE_SEC = 0.1
# drake-iiwa-driver clamps commands this far (rad) inside the joints' limits.
IIWA_LIMIT_MARGIN = np.radians(1.0)


class DriverSimError(RuntimeError):
    """What the real driver would abort on."""


class DriverSim(LeafSystem):
    """An arm behind its driver's rules: the Panda drops a command stamped more than
    `expire_sec` from its clock and refuses one for another mode than position; the iiwa
    aborts on a command within its start-up guard and clamps commands 1 degree inside the
    limits; both hold the last accepted position, toward which the joints move at their
    velocity limits.

    .. pydrake_system::

        name: DriverSim
        input_ports:
        - command

    ``command`` is the last command message (an ``LcmSubscriberSystem``'s output); the
    status goes out each driver period, stamped on `clock`.
    """

    def __init__(self, driver, lcm, q_start, lower, upper, velocity_limits, clock,
                 expire_sec=PANDA_EXPIRE_SEC):
        super().__init__()
        self._driver_name, self._driver = driver, DRIVERS[driver]
        self._lcm, self._clock, self._expire = lcm, clock, float(expire_sec)
        self._lower, self._upper = np.asarray(lower, float), np.asarray(upper, float)
        self._velocity = np.asarray(velocity_limits, float)
        n = self._n = len(q_start)
        # State: q, v, the accepted command, the last command's utime, the first status's time.
        self._Q, self._V, self._HELD = slice(0, n), slice(n, 2 * n), slice(2 * n, 3 * n)
        self._UTIME, self._FIRST_AT = 3 * n, 3 * n + 1
        q_start = np.asarray(q_start, float)
        self._state_index = self.DeclareDiscreteState(
            np.concatenate([q_start, np.zeros(n), q_start, [-1.0, np.nan]]))
        self.DeclareAbstractInputPort("command", Value(command_type(driver)()))
        self.DeclarePeriodicDiscreteUpdateEvent(self._driver.period, 0.0, self._update)
        # Just after the update of the same instant (see DriverLink): the status of this
        # period's motion, not the last's.
        self.DeclarePeriodicPublishEvent(self._driver.period, decide_offset(self._driver.period),
                                         self._publish)

    def positions(self, context):
        """The simulated arm's joint positions in `context` (its own)."""
        return np.array(context.get_discrete_state(self._state_index).value()[self._Q])

    def _update(self, context, discrete_state):
        x = np.array(context.get_discrete_state(self._state_index).value())
        now = clock_now(self._clock, context)
        if np.isnan(x[self._FIRST_AT]):
            x[self._FIRST_AT] = now  # the first status goes out at this instant
        message = self.get_input_port(0).Eval(context)
        if message.utime != x[self._UTIME] and self._has_positions(message):
            x[self._UTIME] = message.utime
            accepted = self._accept(message, x, now)
            if accepted is not None:
                x[self._HELD] = accepted
        period = self._driver.period
        step = np.clip(x[self._HELD] - x[self._Q], -self._velocity * period,
                       self._velocity * period)
        x[self._Q] += step
        x[self._V] = step / period
        discrete_state.set_value(self._state_index, x)

    def _has_positions(self, message):
        """Whether `message` is a command (the subscriber's default message holds none)."""
        return (message.num_joint_position if self._driver_name == "panda"
                else message.num_joints) > 0

    def _accept(self, message, x, now):
        """The command's positions if the driver takes them, None if it drops them; raises
        DriverSimError where the driver would abort."""
        channel = self._driver.command_channel
        if self._driver_name == "panda":
            if (message.control_mode_expected != PANDA_POSITION_MODE
                    or message.num_joint_velocity or message.num_joint_torque):
                raise DriverSimError(f"{channel}: a command for another mode than position "
                                     "(drake-franka-driver throws)")
            if abs(now - message.utime * 1e-6) > self._expire:
                return None  # stale: the driver drops it and holds
        elif now - x[self._FIRST_AT] < self._driver.start_guard:
            raise DriverSimError(f"{channel}: a command within {self._driver.start_guard:g} "
                                 "s of the first status (drake-iiwa-driver aborts)")
        q = np.asarray(message.joint_position, float)
        if len(q) != self._n or not np.all(np.isfinite(q)):
            raise DriverSimError(f"{channel}: a command of {len(q)} positions or with a NaN "
                                 f"(the arm has {self._n} joints)")
        if self._driver_name == "iiwa":
            q = np.clip(q, self._lower + IIWA_LIMIT_MARGIN, self._upper - IIWA_LIMIT_MARGIN)
        return q

    def _publish(self, context):
        x = context.get_discrete_state(self._state_index).value()
        now = clock_now(self._clock, context)
        message = status_message(self._driver_name, now * 1e6, x[self._Q], x[self._V],
                                 x[self._HELD])
        self._lcm.Publish(self._driver.status_channel, message.encode())


def make_driver_sim(driver, lcm, clock, q_start, lower, upper, velocity_limits,
                    with_interface=True, expire_sec=PANDA_EXPIRE_SEC):
    """A Diagram named ``driver_sim``: an arm of the joints' `lower`, `upper` and
    `velocity_limits` standing at `q_start` behind `driver`'s rules on `lcm`, with its own
    `LcmInterfaceSystem` unless not `with_interface` (the station's pumps `lcm`)."""
    builder = DiagramBuilder()
    if with_interface:
        builder.AddNamedSystem("lcm", LcmInterfaceSystem(lcm))
    commands = builder.AddNamedSystem("command_subscriber", LcmSubscriberSystem.Make(
        DRIVERS[driver].command_channel, command_type(driver), lcm))
    arm = builder.AddNamedSystem("arm", DriverSim(driver, lcm, q_start, lower, upper,
                                                  velocity_limits, clock, expire_sec))
    builder.Connect(commands.get_output_port(), arm.get_input_port(0))
    diagram = builder.Build()
    diagram.set_name("driver_sim")
    return diagram
