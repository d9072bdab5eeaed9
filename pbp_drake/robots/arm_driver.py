"""The station's side of a real arm's Drake LCM driver (drake-franka-driver,
drake-iiwa-driver): the messages, the clock, the first status read before a run
(`read_first_status`), and `DriverLink`, which sends the diff IK's joint positions within
the drivers' rules (docs/tasks/real-arm.md, "What the station does"; `ArmHardware` holds
the limits). With the driver simulator in the same process (`ArmHardware.driver_sim`)
both sides keep the simulation's clock (`SIMULATION_CLOCK`).
"""

import time

import numpy as np
from drake import lcmt_iiwa_command, lcmt_iiwa_status, lcmt_panda_command, lcmt_panda_status
from pydrake.common.value import Value
from pydrake.systems.framework import LeafSystem

from pbp_drake.robots.arm_station_config import DRIVERS
from pbp_drake.systems.tick import decide_offset

WALL_CLOCK, SIMULATION_CLOCK = "wall", "simulation"
# drake-franka-driver's position mode (lcmt_panda_status.CONTROL_MODE_POSITION).
PANDA_POSITION_MODE = 1
# A status this far (rad) beyond a joint's limit is the driver's or the arm's fault.
LIMIT_TOLERANCE = 0.01


class DriverError(RuntimeError):
    """The driver's link failed a rule: the run ends and the arm holds where it was last
    commanded."""


def clock_now(clock, context):
    """Seconds on `clock`: the wall clock's epoch time, or the simulation's time."""
    return time.time() if clock == WALL_CLOCK else context.get_time()


def status_type(driver):
    return lcmt_panda_status if driver == "panda" else lcmt_iiwa_status


def command_type(driver):
    return lcmt_panda_command if driver == "panda" else lcmt_iiwa_command


def read_status(driver, message):
    """`(q, v)` measured in a driver's status message (arrays of its joint count)."""
    if driver == "panda":
        return (np.array(message.joint_position, float),
                np.array(message.joint_velocity, float))
    return (np.array(message.joint_position_measured, float),
            np.array(message.joint_velocity_estimated, float))


def status_message(driver, utime, q, v, q_commanded):
    """The status a driver publishes: measured `q`, `v` and the position commanded."""
    n = len(q)
    message = status_type(driver)()
    message.utime, message.num_joints = int(utime), n
    if driver == "panda":
        message.joint_position, message.joint_velocity = list(q), list(v)
        message.joint_position_desired = list(q_commanded)
        for name in ("joint_velocity_desired", "joint_acceleration_desired", "joint_torque",
                     "joint_torque_desired", "joint_torque_external"):
            setattr(message, name, [0.0] * n)
        message.control_command_success_rate = 1.0
        message.robot_mode = 2  # kMove
        message.robot_utime = int(utime)
        message.control_mode = PANDA_POSITION_MODE
    else:
        message.joint_position_measured, message.joint_velocity_estimated = list(q), list(v)
        message.joint_position_commanded = message.joint_position_ipo = list(q_commanded)
        for name in ("joint_torque_measured", "joint_torque_commanded",
                     "joint_torque_external"):
            setattr(message, name, [0.0] * n)
    return message


def command_message(driver, utime, q):
    """A joint position command: the Panda's in position mode (no velocity or torque),
    the iiwa's without torques."""
    message = command_type(driver)()
    message.utime = int(utime)
    if driver == "panda":
        message.num_joint_position, message.joint_position = len(q), list(q)
        message.num_joint_velocity, message.joint_velocity = 0, []
        message.num_joint_torque, message.joint_torque = 0, []
        message.control_mode_expected = PANDA_POSITION_MODE
    else:
        message.num_joints, message.joint_position = len(q), list(q)
        message.num_torques, message.joint_torque = 0, []
    return message


def check_status(driver, q, v, lower, upper):
    """Raises DriverError for a status of the wrong joint count, a NaN, or a position
    beyond a joint's limit."""
    channel = DRIVERS[driver].status_channel
    if len(q) != len(lower) or len(v) != len(lower):
        raise DriverError(f"the driver's status on {channel} has {len(q)} joint positions "
                          f"and {len(v)} velocities; the model has {len(lower)} joints")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
        joint = int(np.flatnonzero(~(np.isfinite(q) & np.isfinite(v)))[0]) + 1
        raise DriverError(f"the driver's status on {channel} holds a NaN or infinite value "
                          f"at joint {joint}")
    beyond = np.flatnonzero((q < lower - LIMIT_TOLERANCE) | (q > upper + LIMIT_TOLERANCE))
    if beyond.size:
        joint = int(beyond[0])
        raise DriverError(f"the driver's status on {channel} puts joint {joint + 1} at "
                          f"{q[joint]:.4f} rad, beyond its limits [{lower[joint]:.4f}, "
                          f"{upper[joint]:.4f}]")


def check_heard(now, started_at, heard_at, connect_timeout, status_timeout, first, silent,
                then):
    """The watchdog of a link that listens on a channel: raises DriverError when nothing
    was heard within `connect_timeout` of `started_at` ("no `first` within ..."), or
    nothing for `status_timeout` since `heard_at` ("`silent` has been silent for ...:
    `then`"); returns whether anything has been heard (`heard_at` is NaN until then)."""
    if np.isnan(heard_at):
        if now - started_at > connect_timeout:
            raise DriverError(f"no {first} within {connect_timeout:g} s")
        return False
    silence = now - heard_at
    if silence > status_timeout:
        raise DriverError(f"{silent} has been silent for {silence:.3f} s (at most "
                          f"{status_timeout:g} s): {then}")
    return True


def check_on_the_wall_clock(context, offset, expiry, then):
    """Raises DriverError ("...: `then`") when the simulation at `context` runs more than
    `expiry` s behind or ahead of the wall clock, `offset` the wall clock less the
    simulation's time when the link started. Ahead, each command's speed limit would hold
    in simulated time only: the robot would be sent faster than its limits; behind, a
    stalled loop would go unseen and then rush to catch up."""
    lag = time.time() - context.get_time() - offset
    if abs(lag) > expiry:
        raise DriverError(
            f"the control loop ran {abs(lag):.3f} s {'behind' if lag > 0 else 'ahead of'} "
            f"the wall clock (at most {expiry:g} s; the simulator's real-time rate must be "
            f"1): {then}")


def first_message(lcm, channel, decode, timeout, missing):
    """The first message on `channel` of `lcm` (a DrakeLcm that no `LcmInterfaceSystem`
    pumps: this subscribes a Python callback), decoded by `decode`, waiting at most
    `timeout` s; DriverError(`missing`) when none comes."""
    received = []
    lcm.Subscribe(channel, lambda data: received.append(decode(data)))
    deadline = time.monotonic() + timeout
    while not received:
        left = deadline - time.monotonic()
        if left <= 0:
            raise DriverError(missing)
        lcm.HandleSubscriptions(int(min(left, 0.1) * 1000) + 1)
    return received[0]


def read_first_status(hardware, lcm, lower, upper):
    """The joint positions of the driver's first status on `lcm` (`first_message`'s),
    waiting at most `hardware.connect_timeout`; DriverError naming the bus and the channel
    when none comes, and as `check_status` for a bad one."""
    channel = DRIVERS[hardware.driver].status_channel
    status = first_message(
        lcm, channel, status_type(hardware.driver).decode, hardware.connect_timeout,
        f"no status from the {hardware.driver} driver on {channel} (bus "
        f"{hardware.lcm_bus.lcm_url}) within {hardware.connect_timeout:g} s: is the driver "
        "running on that bus?")
    q, v = read_status(hardware.driver, status)
    check_status(hardware.driver, q, v, lower, upper)
    return q


class DriverLink(LeafSystem):
    """The station's link to a real arm's driver, under the drivers' rules
    (docs/tasks/real-arm.md).

    .. pydrake_system::

        name: DriverLink
        input_ports:
        - status
        - desired_state
        output_ports:
        - state

    ``status`` is the driver's last status message (an ``LcmSubscriberSystem``'s output,
    ``lcmt_panda_status`` or ``lcmt_iiwa_status``), ``desired_state`` the diff IK's
    ``[q_d, v_d]``, ``state`` the arm's measured ``[q, v]`` (``q_start`` at rest before
    the first status). The command is sent in a publish event after each driver period's
    update.
    """

    def __init__(self, hardware, lcm, q_start, lower, upper, velocity_limits, clock):
        super().__init__()
        self._hardware, self._lcm, self._clock = hardware, lcm, clock
        self._driver = DRIVERS[hardware.driver]
        self._lower, self._upper = np.asarray(lower, float), np.asarray(upper, float)
        # The farthest each joint's command moves in one driver period.
        self._step = np.asarray(velocity_limits, float) * self._driver.period
        self._q_start = np.asarray(q_start, float)
        n = self._n = len(self._q_start)
        channel = self._driver.status_channel
        bus = ("memq:// (the driver simulator)" if hardware.driver_sim
               else hardware.lcm_bus.lcm_url)
        self._first = f"status from the {hardware.driver} driver on {channel} (bus {bus})"
        self._silent = f"the {hardware.driver} driver's status on {channel} (bus {bus})"
        # State: measured q and v, the last command; the last status's utime and when it
        # came (our clock), when the first status came, the first update's time and its
        # wall clock less the simulation's (the loop's lag is measured from it); whether
        # this update sends.
        self._Q, self._V, self._SENT = slice(0, n), slice(n, 2 * n), slice(2 * n, 3 * n)
        (self._UTIME, self._STATUS_AT, self._FIRST_AT, self._STARTED_AT, self._OFFSET,
         self._SEND) = range(3 * n, 3 * n + 6)
        initial = np.concatenate([self._q_start, np.zeros(n), self._q_start,
                                  [-1.0, np.nan, np.nan, np.nan, np.nan, 0.0]])
        self._state_index = self.DeclareDiscreteState(initial)
        self.DeclareAbstractInputPort("status", Value(status_type(hardware.driver)()))
        self.DeclareVectorInputPort("desired_state", 2 * n)
        self.DeclareVectorOutputPort("state", 2 * n, self._output_state,
                                     prerequisites_of_calc={self.xd_ticket()})
        self.DeclarePeriodicDiscreteUpdateEvent(self._driver.period, 0.0, self._update)
        # Sent just after the update of the same instant: Drake publishes at the end of the
        # step that reaches an instant and updates at the start of the next, so a publish at
        # the instant itself would send the last period's command.
        self.DeclarePeriodicPublishEvent(self._driver.period, decide_offset(self._driver.period),
                                         self._send)

    def _output_state(self, context, output):
        output.SetFromVector(context.get_discrete_state(self._state_index).value()[:2 * self._n])

    def _update(self, context, discrete_state):
        x = np.array(context.get_discrete_state(self._state_index).value())
        now = clock_now(self._clock, context)
        if np.isnan(x[self._STARTED_AT]):
            x[self._STARTED_AT] = now
            x[self._OFFSET] = time.time() - context.get_time()
        message = self.get_input_port(0).Eval(context)
        if message.num_joints and message.utime != x[self._UTIME]:
            if x[self._UTIME] < 0:
                # A udpm:// bus keeps the first message that came since it was last handled
                # and drops the later ones: at the run's first step, one as old as the
                # station. The next one is fresh.
                x[self._UTIME] = message.utime
            else:
                self._read(message, x, now)
        x[self._SEND] = 0.0
        hardware = self._hardware
        if check_heard(now, x[self._STARTED_AT], x[self._STATUS_AT], hardware.connect_timeout,
                       hardware.status_timeout, self._first, self._silent,
                       "the arm holds where it was last commanded"):
            if self._clock == WALL_CLOCK:
                check_on_the_wall_clock(context, x[self._OFFSET], hardware.command_expiry,
                                        "the arm holds where it was last commanded")
            if now - x[self._FIRST_AT] >= self._driver.start_guard:
                x[self._SENT] = self._command(context, x)
                x[self._SEND] = 1.0
        discrete_state.set_value(self._state_index, x)

    def _read(self, message, x, now):
        q, v = read_status(self._hardware.driver, message)
        check_status(self._hardware.driver, q, v, self._lower, self._upper)
        if np.isnan(x[self._FIRST_AT]):
            offset = float(np.max(np.abs(q - self._q_start)))
            if offset > self._hardware.start_tolerance:
                raise DriverError(
                    f"the arm stands {offset:.4f} rad from the configuration the run was "
                    f"built for (at most {self._hardware.start_tolerance:g}): it moved after "
                    "the first status was read")
            x[self._FIRST_AT] = now
        x[self._Q], x[self._V] = q, v
        x[self._UTIME], x[self._STATUS_AT] = message.utime, now

    def _command(self, context, x):
        """The diff IK's q_d within the position limits and the velocity limits' step."""
        q_d = np.asarray(self.get_input_port(1).Eval(context))[:self._n]
        if not np.all(np.isfinite(q_d)):
            raise DriverError("the diff IK's joint positions hold a NaN: nothing is sent, "
                              "the arm holds where it was last commanded")
        q = np.clip(q_d, x[self._SENT] - self._step, x[self._SENT] + self._step)
        return np.clip(q, self._lower, self._upper)

    def _send(self, context):
        x = context.get_discrete_state(self._state_index).value()
        if x[self._SEND]:
            utime = clock_now(self._clock, context) * 1e6
            message = command_message(self._hardware.driver, utime, x[self._SENT])
            self._lcm.Publish(self._driver.command_channel, message.encode())
