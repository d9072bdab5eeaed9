"""The surrogate pilots (docs/concepts/pilots.md) as Drake systems: thin wrappers of
`pbp_drake.core.surrogate_pilots`. Each task's keys (`ReachKeys`, `GraspKeys`) say how a
key state or a velocity becomes its command: `[vx, vy, vz, yaw_rate]`, or the grasping
task's twist `[v (3), omega (3)]`.
"""

import numpy as np
from pydrake.systems.framework import Diagram, DiagramBuilder

from pbp_drake.core.surrogate_pilots import (
    GRASP_AXES, REACH_AXES, REACH_VERTICAL_AXES, grasp_key_command,
    grasp_proportional_command, lag_per_tick, laggy_draw, noisy_draw, reach_key_command,
    reach_proportional_command)
from pbp_drake.systems.operators.sampled_operator import SampledOperator
from pbp_drake.systems.ports import (
    EeState, OperatorCommand, OperatorTwist, PortGetters, PoseState, Target, position_of)
from pbp_drake.systems.tick import pilot_offset

#: The port that says whether the method enables the forward key (size 1).
FORWARD_KEY = "forward_key"


def _forward_enabled(port, context):
    return bool(port.Eval(context)[0] > 0.5)


class ReachKeys:
    """The reaching and obstacle tasks' keys: forward/back, left/right, (up/down with
    `vertical`,) turn left/right, at `speed` (m/s) and `rotation_speed` (rad/s); the hand
    is read from `ee_state`."""

    hand_port = "ee_state"
    hand_size = EeState.size
    command_size = OperatorCommand.size
    # The keyboard has no forward button where the forward key is disabled.
    forward_is_a_button = True

    def __init__(self, speed, rotation_speed, vertical=False):
        self.speed, self.rotation_speed = float(speed), float(rotation_speed)
        self.vertical = bool(vertical)
        self.axes = REACH_VERTICAL_AXES if self.vertical else REACH_AXES

    def key_command(self, keys, hand, forward_enabled):
        """`(command, active)` of a key state (its forward axis already limited to the
        enabled states by `key_state`)."""
        return reach_key_command(keys, EeState(hand).heading, self.speed, self.rotation_speed)

    def proportional_command(self, params, hand, target, max_speed, forward_enabled):
        ee_state = EeState(hand)
        return reach_proportional_command(
            params, position_of(ee_state), ee_state.heading, position_of(Target(target)),
            max_speed, self.vertical, forward_enabled)


class GraspKeys:
    """The grasping task's keys: forward/back, left/right, up/down, yaw, pitch, roll, at
    `speed` (m/s) and `rotation_speed` (rad/s); the hand is read from `hand_pose`."""

    hand_port = "hand_pose"
    hand_size = PoseState.size
    command_size = OperatorTwist.size
    axes = GRASP_AXES
    # Its ↑ stays (it tips the hand in rotate mode); the twist loses its forward part.
    forward_is_a_button = False

    def __init__(self, speed, rotation_speed):
        self.speed, self.rotation_speed = float(speed), float(rotation_speed)

    @staticmethod
    def _orientation(hand):
        quaternion = np.asarray(hand, float)[3:7]
        return quaternion / np.linalg.norm(quaternion)

    def key_command(self, keys, hand, forward_enabled):
        return grasp_key_command(keys, self._orientation(hand), self.speed,
                                 self.rotation_speed, forward_enabled)

    def proportional_command(self, params, hand, target, max_speed, forward_enabled):
        return grasp_proportional_command(
            params, np.asarray(hand, float)[:3], self._orientation(hand),
            position_of(Target(target)), max_speed, forward_enabled)


class PilotFilter(SampledOperator):
    """Base of the filters between a base pilot's outputs and the controller.

    .. pydrake_system::

        name: PilotFilter
        input_ports:
        - base_command
        - base_active
        - ee_state (or hand_pose)
        - forward_key
        output_ports:
        - operator_command
        - operator_active

    Each tick, at `pbp_drake.systems.tick.pilot_offset` (between the sense and decide
    stages), it samples the base pilot's output and holds what `_filter` makes of it.
    Subclasses implement `_filter(context, tick, command, active, previous) -> (command,
    active)`, `previous` being its own last output (None at the first tick).
    """

    def __init__(self, keys, control_period, seed):
        super().__init__(keys.command_size, control_period)
        self.keys = keys
        self._seed = int(seed)
        self._base_command_port = self.DeclareVectorInputPort("base_command", keys.command_size)
        self._base_active_port = self.DeclareVectorInputPort("base_active", 1)
        self._hand_port = self.DeclareVectorInputPort(keys.hand_port, keys.hand_size)
        self._forward_port = self.DeclareVectorInputPort(FORWARD_KEY, 1)
        self._taken_index = self.DeclareDiscreteState(1)  # 1 once a sample has been taken
        self._declare_operator_outputs(offset=pilot_offset(self._period))

    def _update(self, context, discrete_state):
        tick = int(round(context.get_time() / self._period))
        held = self._held(context)
        taken = context.get_discrete_state(self._taken_index).value()[0] > 0.5
        previous = (held[:-1], bool(held[-1] > 0.5)) if taken else None
        command, active = self._filter(
            context, tick, np.array(self._base_command_port.Eval(context), float),
            bool(self._base_active_port.Eval(context)[0] > 0.5), previous)
        discrete_state.set_value(self._taken_index, [1.0])
        self._store_sample(discrete_state, command, active)


class NoisyFilter(PilotFilter):
    """The noisy pilot's filter: each tick, with probability `eps`, the base pilot's output
    is replaced by a uniformly random state of the enabled keys (`noisy_draw`)."""

    def __init__(self, keys, control_period, seed, eps):
        super().__init__(keys, control_period, seed)
        self.eps = float(eps)

    def _filter(self, context, tick, command, active, previous):
        forward = _forward_enabled(self._forward_port, context)
        corrupted, key_state = noisy_draw(self._seed, tick, self.eps, len(self.keys.axes),
                                          forward or not self.keys.forward_is_a_button)
        if not corrupted:
            return command, active
        return self.keys.key_command(key_state, self._hand_port.Eval(context), forward)


class LaggyFilter(PilotFilter):
    """The laggy pilot's filter: each tick, with probability `p_tick` (the sources' `p` at
    our tick, `lag_per_tick`), it repeats its previous output instead of the base pilot's."""

    def __init__(self, keys, control_period, seed, p):
        super().__init__(keys, control_period, seed)
        self.p_tick = lag_per_tick(p, control_period)

    def _filter(self, context, tick, command, active, previous):
        if laggy_draw(self._seed, tick, self.p_tick) and previous is not None:
            return previous
        return command, active


class PilotOperator(PortGetters, Diagram):
    """A base pilot and its filter, with exactly the base pilot's ports.

    .. pydrake_system::

        name: PilotOperator
        input_ports:
        - ee_state (or hand_pose)
        - target
        - selected_goal
        - forward_key
        - obstacle_positions (optional)
        output_ports:
        - operator_command
        - operator_active

    Every input port of `base` and of `pilot_filter` is exported once under its name; the
    outputs are the filter's.
    """

    def __init__(self, base, pilot_filter):
        super().__init__()
        builder = DiagramBuilder()
        base = builder.AddNamedSystem("participant", base)
        pilot_filter = builder.AddNamedSystem("pilot_filter", pilot_filter)
        builder.Connect(base.get_operator_command_output_port(),
                        pilot_filter.GetInputPort("base_command"))
        builder.Connect(base.get_operator_active_output_port(),
                        pilot_filter.GetInputPort("base_active"))
        exported = {}
        for system in (base, pilot_filter):
            for index in range(system.num_input_ports()):
                port = system.get_input_port(index)
                name = port.get_name()
                if name in ("base_command", "base_active"):
                    continue
                if name in exported:
                    builder.ConnectInput(exported[name], port)
                else:
                    exported[name] = builder.ExportInput(port, name)
        builder.ExportOutput(pilot_filter.get_operator_command_output_port(), "operator_command")
        builder.ExportOutput(pilot_filter.get_operator_active_output_port(), "operator_active")
        builder.BuildInto(self)


class ProportionalOperator(SampledOperator):
    """HOP's simulated user: `u = gain (p_target - p_hand)`, its norm clipped to
    `max_speed` (m/s), translation only (`core.surrogate_pilots.proportional_velocity`).

    .. pydrake_system::

        name: ProportionalOperator
        input_ports:
        - ee_state (or hand_pose)
        - target
        - selected_goal
        - forward_key
        - obstacle_positions (optional)
        output_ports:
        - operator_command
        - operator_active

    It reads only the hand, the target and `forward_key`: it is blind to the robot's intent
    and to obstacles, and acts wherever its command is not zero. `keys` is the task's
    `ReachKeys` or `GraspKeys`.
    """

    def __init__(self, keys, control_period, params, max_speed, obstacle_count=0):
        super().__init__(keys.command_size, control_period)
        self.keys, self.params, self.max_speed = keys, params, float(max_speed)
        self._hand_port = self.DeclareVectorInputPort(keys.hand_port, keys.hand_size)
        self._target_port = self.DeclareVectorInputPort("target", Target.size)
        self.DeclareVectorInputPort("selected_goal", 1)
        self._forward_port = self.DeclareVectorInputPort(FORWARD_KEY, 1)
        if obstacle_count > 0:
            self.DeclareVectorInputPort("obstacle_positions", 2 * int(obstacle_count))
        self._declare_operator_outputs()

    def _sample(self, context):
        return self.keys.proportional_command(
            self.params, self._hand_port.Eval(context), self._target_port.Eval(context),
            self.max_speed, _forward_enabled(self._forward_port, context))
