"""Named layouts of the port and state vectors (`pydrake` `namedview`s), e.g.
``EeState(vector).heading``, ``EeState.size`` its length; and the systems' shared helpers
(checks of their arguments, reads of ports)."""

import dataclasses
import math
import re

import numpy as np
from pydrake.common.containers import namedview

from pbp_drake.core.coordinates import is_whole


def _view(name, fields):
    view = namedview(name, fields)
    view.size = len(fields)
    return view


# The end effector's state, world frame: position, velocity, heading on the floor plane
# (rad, counter-clockwise from +x) and its rate.
EeState = _view("EeState", ["x", "y", "z", "vx", "vy", "vz", "heading", "heading_rate"])
# The command the HSR station follows: the position to be at, its velocity, the heading.
EeCommand = _view("EeCommand", ["x", "y", "z", "vx", "vy", "vz", "heading"])
# An operator's command on the HSR: a world-frame velocity and a yaw rate.
OperatorCommand = _view("OperatorCommand", ["vx", "vy", "vz", "yaw_rate"])
# The current target of the task: its position and the object's index.
Target = _view("Target", ["x", "y", "z", "index"])
# The task monitor's status (see `TaskMonitor`).
TaskStatus = _view("TaskStatus", ["progress", "stage", "success", "task_time",
                                  "intervention_ratio", "steps", "collision_ratio"])


def position_of(view):
    """`[x, y, z]` of a view with those fields (`EeState`, `EeCommand`, `Target`), a copy."""
    return np.array([view.x, view.y, view.z])


def checked_count(value, name):
    """`value` as an int; ValueError, naming it `name`, unless it is an integer >= 1."""
    if not is_whole(value, 1):
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


def checked_objects(objects, name="objects"):
    """`objects` as a float array; ValueError, naming it `name`, unless non-empty finite (M, 3)."""
    objects = np.asarray(objects, dtype=float)
    if (objects.ndim != 2 or objects.shape[0] == 0 or objects.shape[1] != 3
            or not np.isfinite(objects).all()):
        raise ValueError(f"{name} must be a non-empty finite (M, 3) array, got shape "
                         f"{objects.shape}")
    return objects


def checked_settings(settings, kind):
    """A private copy of `settings`; ValueError unless it is a `kind` whose `validate`
    passes (a plain dataclass: its fields may have changed since construction)."""
    if not isinstance(settings, kind):
        raise ValueError(f"settings must be {kind.__name__}, got {type(settings).__name__}")
    settings.validate()
    return dataclasses.replace(settings)


def goal_index(port, context, goal_count, unconnected=None):
    """The goal index `[k]` on `port` as an int, checked to be one of `goal_count` goals;
    `unconnected` when nothing is connected to the port."""
    if not port.HasValue(context):
        return unconnected
    value = port.Eval(context)[0]
    index = int(value) if math.isfinite(value) else -1
    if not 0 <= index < goal_count or index != value:
        raise ValueError(f"{port.get_name()} {value:g} is not one of the {goal_count} goals")
    return index


# Six-DoF PBP (`PoseDmpBank`, `PoseBlender`, `PoseHandOver`): orientations are unit
# quaternions (w, x, y, z), angular velocities world-frame rad/s (see docs/concepts/six-dof.md).
# A hand's measured pose and twist; also the layout of a pose reference or command (the
# pose to be at after one control period, and the twist to move at).
PoseState = _view("PoseState", ["x", "y", "z", "qw", "qx", "qy", "qz",
                                "vx", "vy", "vz", "wx", "wy", "wz"])
# A goal pose, one row of a pose bank's `goal_poses` (K rows flattened).
GoalPose = _view("GoalPose", ["x", "y", "z", "qw", "qx", "qy", "qz"])
# An operator's six-DoF command: a world-frame linear and angular velocity.
OperatorTwist = _view("OperatorTwist", ["vx", "vy", "vz", "wx", "wy", "wz"])


def finite_pose_state(state, name):
    """`state` (a `PoseState`) as a float array; raises ValueError naming `name` and the
    fields that are NaN or infinite."""
    return finite_fields(state, name, PoseState.get_fields())


def finite_fields(vector, name, fields):
    """`vector` as a float array; raises ValueError naming `name` and the `fields` (one name
    an entry) that are NaN or infinite."""
    vector = np.asarray(vector, dtype=float)
    # A sum of floats is finite unless a number is NaN or infinite (or the sum overflows,
    # which the exact check below lets pass): a fifth of `np.isfinite`'s time.
    if not math.isfinite(sum(vector.tolist())):
        bad = [field for field, value in zip(fields, vector) if not math.isfinite(value)]
        if bad:
            raise ValueError(f"{name} {', '.join(bad)} is NaN or infinite: {vector.tolist()}")
    return vector


_GETTER = re.compile(r"get_(\w+)_(input|output)_port")


class PortGetters:
    """`get_NAME_input_port()` and `get_NAME_output_port()` for every port NAME the system
    declares, as Drake's C++ systems have. A mixin before `LeafSystem` or `Diagram`;
    `dir()` lists the getters."""

    def __getattr__(self, attribute):
        match = _GETTER.fullmatch(attribute)
        if match is not None:
            name, kind = match.groups()
            if kind == "input" and self.HasInputPort(name):
                port = self.GetInputPort(name)
                return lambda: port
            if kind == "output" and self.HasOutputPort(name):
                port = self.GetOutputPort(name)
                return lambda: port
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {attribute!r}")

    def __dir__(self):
        inputs = (self.get_input_port(i).get_name() for i in range(self.num_input_ports()))
        outputs = (self.get_output_port(i).get_name() for i in range(self.num_output_ports()))
        return [*super().__dir__(), *(f"get_{name}_input_port" for name in inputs),
                *(f"get_{name}_output_port" for name in outputs)]
