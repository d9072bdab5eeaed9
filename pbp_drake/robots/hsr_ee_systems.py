"""The stations' task-space adapters: the end-effector command in (as a system, or as the
arithmetic the station's diff IK applies itself), its state out."""

import math

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.ports import EeCommand, EeState, PortGetters
from pbp_drake.systems.tick import decide_offset

# EeCommand's entries, by index.
_POSITION, _VELOCITY, _HEADING = slice(0, 3), slice(3, 6), 6


def heading_of(R_WE: RotationMatrix) -> float:
    """The direction the hand points in the floor plane: atan2 of its z axis' (x, y)."""
    z_axis = R_WE.matrix()[:, 2]
    return float(np.arctan2(z_axis[1], z_axis[0]))


def ee_state_at_rest(X_WE: RigidTransform) -> np.ndarray:
    """The `EeState` (8,) of a hand at rest at `X_WE`: its position and heading."""
    state = EeState(np.zeros(EeState.size))
    state.x, state.y, state.z = X_WE.translation()
    state.heading = heading_of(X_WE.rotation())
    return state[:]


class EeCommandToPose(PortGetters, LeafSystem):
    """Turns the end-effector command into the desired pose and velocity for diff IK.

    .. pydrake_system::

        name: EeCommandToPose
        input_ports:
        - ee_command
        output_ports:
        - X_WE_desired
        - V_WE_desired

    `ee_command` is `[p (3), v (3), heading]` (`EeCommand`). `X_WE_desired` is where the
    command puts the hand `lead` seconds from now, `(Rz(heading) R_E0, position)` with
    `R_E0` the hand pointing along world +x; `V_WE_desired` is the hand's spatial velocity
    `[w (3), v (3)]` in the world frame along the way.

    With a `control_period` (a control loop that sends, at each tick, the state to be in at
    the next tick) both ramp: the position into `p` at `v`, `p - v (t_next - t - lead)`,
    and the heading from the last tick's command into this one's at a constant rate;
    stepping once a tick would leave the robot behind by most of a tick's travel. The last
    tick's heading is sampled just after each tick, before the PBP loop's decide stage
    (`pbp_drake.systems.tick`) changes the command. Without a `control_period`, the
    position is `p + v lead` and the heading the command's. `lead` is how far ahead the
    reader wants the pose (the station's diff IK: its period).
    """

    def __init__(self, R_E0: RotationMatrix, control_period=None, lead=0.0):
        super().__init__()
        self._ramp = EeCommandRamp(R_E0, control_period, lead)
        self._command_port = self.DeclareVectorInputPort("ee_command", EeCommand.size)
        self._last_heading = self._ramp.declare_heading_sample(self, self._command_port)
        self._pose_port = self.DeclareAbstractOutputPort(
            "X_WE_desired", lambda: AbstractValue.Make(RigidTransform()), self._calc_pose)
        self._velocity_port = self.DeclareVectorOutputPort(
            "V_WE_desired", 6, self._calc_velocity)

    def get_pose_output_port(self):
        return self._pose_port

    def get_velocity_output_port(self):
        return self._velocity_port

    def _calc_velocity(self, context, output):
        command = self._command_port.Eval(context)
        velocity = output.get_mutable_value()
        velocity[:2] = 0.0
        velocity[2] = self._ramp.heading_rate(context, self._last_heading, command)
        velocity[3:] = command[_VELOCITY]

    def _calc_pose(self, context, output):
        command = self._command_port.Eval(context)
        rate = self._ramp.heading_rate(context, self._last_heading, command)
        output.set_value(RigidTransform(*self._ramp.rotation_and_position(
            command, rate, context.get_time())))


class CommandRamp:
    """What a command ramp shares (`EeCommandRamp`, `PoseCommandRamp`): the command's
    `control_period` (or None) and the `lead` (s) at which the reader wants the pose."""

    def __init__(self, control_period=None, lead=0.0):
        self.period = control_period
        self.lead = float(lead)

    def ahead(self, time):
        """How far (s) past `time` the command is carried: `lead`, less, with a control
        period, the time left to the next tick."""
        ahead = self.lead
        if self.period:
            # math.ceil's integer times the period: the same product as np.ceil's float's.
            next_tick = math.ceil(time / self.period - 1e-9) * self.period
            ahead -= max(0.0, next_tick - time)
        return ahead


class EeCommandRamp(CommandRamp):
    """`EeCommandToPose`'s arithmetic (see it), for it and for `WholeBodyDiffIk`, which
    reads the command itself (no system between them: two Python calls fewer a step)."""

    port_name = "ee_command"
    command_size = EeCommand.size

    def __init__(self, R_E0: RotationMatrix, control_period=None, lead=0.0):
        super().__init__(control_period, lead)
        self.R_E0 = RotationMatrix(R_E0)

    def declare_heading_sample(self, system, command_port):
        """Declares on `system` the last tick's heading (a discrete state of one entry,
        whose index it returns) and the events that sample it from `command_port`: at
        initialization and, with a command period, just after each tick."""
        index = system.DeclareDiscreteState(1)

        def sample(context, discrete_state):
            discrete_state.set_value(index, [command_port.Eval(context)[_HEADING]])

        system.DeclareInitializationDiscreteUpdateEvent(sample)
        if self.period:
            system.DeclarePeriodicDiscreteUpdateEvent(
                self.period, 0.5 * decide_offset(self.period), sample)
        return index

    def heading_rate(self, context, last_heading_index, command):
        """The heading's rate (rad/s) from the last tick's heading (in `context`'s discrete
        state `last_heading_index`) into the command's over a period; 0 without one."""
        if not self.period:
            return 0.0
        last = float(context.get_discrete_state(last_heading_index).get_value()[0])
        turn = (command[_HEADING] - last + math.pi) % (2 * math.pi) - math.pi
        return turn / self.period

    def rotation_and_position(self, command, heading_rate, time):
        """`X_WE_desired` at `time` as `(RotationMatrix, position)`, the position a list of
        3 floats (no RigidTransform built at each diff IK step); `command` an array or a
        list."""
        ahead = self.ahead(time)
        heading = command[_HEADING] + heading_rate * ahead
        R = RotationMatrix.MakeZRotation(heading) @ self.R_E0
        return R, [p + v * ahead for p, v in zip(command[_POSITION], command[_VELOCITY])]

    def desired(self, context, last_heading_index, command, time):
        """`(R_WE_desired, p_WE_desired, V_WE_desired)` at `time` for the diff IK's step,
        the position and velocity as lists of floats (Python floats: the same IEEE
        operations as numpy's, without a numpy call per operation)."""
        command = command.tolist()
        rate = self.heading_rate(context, last_heading_index, command)
        R, position = self.rotation_and_position(command, rate, time)
        return R, position, [0.0, 0.0, rate, *command[_VELOCITY]]


def station_ramp(X_WE0, config):
    """A station's `EeCommandRamp`: `R_E0` the hand's orientation at the ready pose `X_WE0`
    turned back to heading 0, `lead` the diff IK's period (it reads the pose as the one to
    have at the end of its step), the period `config.control_period`."""
    R_WE0 = X_WE0.rotation()
    R_E0 = RotationMatrix.MakeZRotation(-heading_of(R_WE0)) @ R_WE0
    return EeCommandRamp(R_E0, config.control_period, lead=config.diff_ik_time_step)


class FrameStateFromPlant(PortGetters, LeafSystem):
    """The base of `EeStateFromPlant` and `PoseStateFromPlant`: the world pose and spatial
    velocity of `frame` (a body, or a frame) with the plant at the input `plant_state`, in
    a plant context of its own (the plant's `body_poses` would cross into Python as every
    body's); the output `output_name` (`output_size`) is `_calc_output`'s."""

    def __init__(self, plant, frame, output_name, output_size):
        super().__init__()
        self._plant = plant
        self._pose = getattr(frame, "EvalPoseInWorld", None) or frame.CalcPoseInWorld
        self._velocity = (getattr(frame, "EvalSpatialVelocityInWorld", None)
                          or frame.CalcSpatialVelocityInWorld)
        self._plant_context = plant.CreateDefaultContext()
        self._plant_state_port = self.DeclareVectorInputPort(
            "plant_state", plant.num_multibody_states())
        self.DeclareVectorOutputPort(output_name, output_size, self._calc_output)

    def _kinematics(self, context):
        """`(X_WF, V_WF)` of the frame at the plant's state."""
        plant_context = self._plant_context
        self._plant.SetPositionsAndVelocities(plant_context,
                                              self._plant_state_port.Eval(context))
        return self._pose(plant_context), self._velocity(plant_context)


class EeStateFromPlant(FrameStateFromPlant):
    """Reads the end effector's position, velocity and heading off the plant's state.

    .. pydrake_system::

        name: EeStateFromPlant
        input_ports:
        - plant_state
        output_ports:
        - ee_state

    `plant_state` is `plant`'s state output; `ee_state` is `[p_WE (3), v_WE (3), heading,
    heading_rate]` (`EeState`) of `ee_body` (a body, or any frame of the plant);
    heading_rate is the hand's angular velocity about world z.
    """

    def __init__(self, plant, ee_body):
        # A body frame is read through its body, whose pose and velocity the plant caches.
        if hasattr(ee_body, "body") and ee_body.index() == ee_body.body().body_frame().index():
            ee_body = ee_body.body()
        super().__init__(plant, ee_body, "ee_state", EeState.size)

    def _calc_output(self, context, output):
        X_WE, V_WE = self._kinematics(context)
        w, v = V_WE.rotational(), V_WE.translational()
        output.SetFromVector(np.concatenate(
            [X_WE.translation(), v, [heading_of(X_WE.rotation()), w[2]]]))
