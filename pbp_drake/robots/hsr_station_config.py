"""What the HSR station is built from: ``HsrStationConfig`` and its validation."""

import dataclasses
import numbers
import types
import typing

import numpy as np
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.visualization import VisualizationConfig


@dataclasses.dataclass
class CylinderObstacle:
    """An upright cylinder the station measures the robot against (m)."""

    #: The cylinder's radius (m).
    radius: float = 0.12
    #: Its height (m).
    height: float = 1.2


# HsrStationConfig.motion's values.
MOTIONS = ("dynamic", "kinematic")


def default_station_plant_config():
    # SAP enforces the torso's coupler constraint and applies the motors' PD implicitly.
    # Live output ports: see validate_station.
    return MultibodyPlantConfig(time_step=0.005, discrete_contact_approximation="sap",
                                use_sampled_output_ports=False)


def default_station_visualization():
    # Meshcat only: the proximity shapes, contact forces and inertias are off by default
    # (each is a publisher at every frame).
    return VisualizationConfig(publish_proximity=False, publish_contacts=False,
                               publish_inertia=False)


@dataclasses.dataclass
class HsrStationConfig:
    """Everything ``make_hsr_station`` builds from; loads with ``yaml_load_typed``.

    Gains are the plant's PD on each motor, applied implicitly, so stiff gains stay stable
    at a coarse time step. Acceleration limits are in m/s² (base x, y, arm lift) and rad/s²
    (the others); ``.inf`` is no limit. What is published about the robot is in the model
    file and these comments; the rest is ours.
    """

    #: Drake's MultibodyPlantConfig of the robot's plant (time step, contact model).
    plant: MultibodyPlantConfig = dataclasses.field(default_factory=default_station_plant_config)
    #: How the robot moves along the diff IK's plan. "dynamic": the plant (SAP, every
    #: plant.time_step) and its stiff servos track the plan, a few hundredths of a mm
    #: behind it. "kinematic": the joints are on the plan at every instant (the plant's
    #: step, gains and settings go unused), about twice as fast
    #: (docs/tasks/hsr-station.md, "A kinematic robot").
    motion: str = "dynamic"
    #: The whole-body differential IK's period (s), a whole multiple of plant.time_step;
    #: its QP is the station's largest cost.
    diff_ik_time_step: float = 0.01
    #: The period of a control loop that sends each tick the state [p, v] to reach at the
    #: next tick; the station then ramps into p at v (see EeCommandToPose). None: track p.
    control_period: float | None = None
    #: The base's pose (x, y in m, yaw in rad) at the start; x, y within the model's 10 m.
    initial_base: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0, 0.0])
    #: The hand's height at the start (m); it starts level, pointing along the base's +x.
    ee_height: float = 0.7
    #: The base's PD stiffness gains (x, y in N/m, yaw in N m/rad); with the arm's, stiff servos,
    #: kp = I w² and kd = 2 I w (critically damped) with w = 300 rad/s on each joint's
    #: inertia I at the ready pose (34 kg for x and y, 1.0 kg·m² for yaw, 6.1 kg for the
    #: lift with the torso, 0.31, 0.013, 0.015, 0.001 kg·m² for the others). Accelerating at
    #: its limit a joint then trails the plan by a / w², at most a few hundredths of a mm
    #: at the hand, so a control loop re-integrating from the measured hand sees no lag.
    #: At w = 100, setting off at 0.08 to 0.12 m/s overshot the command by up to 13 % for
    #: a tick (8 % at 150).
    base_kp: list[float] = dataclasses.field(default_factory=lambda: [3.0e6, 3.0e6, 9.0e4])
    #: The base's PD damping gains (x, y in N s/m, yaw in N m s/rad).
    base_kd: list[float] = dataclasses.field(default_factory=lambda: [2.0e4, 2.0e4, 600.0])
    #: The arm's PD stiffness gains (lift in N/m, the others in N m/rad).
    arm_kp: list[float] = dataclasses.field(
        default_factory=lambda: [5.5e5, 2.8e4, 1200.0, 1400.0, 90.0])
    #: The arm's PD damping gains (lift in N s/m, the others in N m s/rad).
    arm_kd: list[float] = dataclasses.field(
        default_factory=lambda: [3700.0, 190.0, 7.8, 9.0, 0.6])
    #: Acceleration limits, enforced by the diff IK on its plan (the servos follow it; see
    #: WholeBodyDiffIk). Base (x, y, yaw): published (hsrb_moveit_config joint_limits.yaml)
    #: 0.05 m/s² for x and y, none for yaw. Ours, for x and y, 0.3: a departure. At 0.05
    #: the base needs 3.2 s to reach 0.16 m/s, more than the arm can cover: driven at
    #: 0.16 m/s along x the hand fell to 0.63 of it and stayed under 0.9 for 1.7 s, and
    #: told to stop, the base dragged it on by 7 cm. At 0.1 the hand followed and stopped,
    #: but turning back from 0.16 m/s along x took 2 s to get within 10 % of the command
    #: again (1.2 s at 0.2, 0.15 s at 0.3). Yaw, ours: 5 rad/s², its top speed in 0.2 s.
    #: With none, diff IK swung the base at up to 95 rad/s² to set the hand off sideways,
    #: and the hand overshot a 0.16 m/s sideways command by 18 %.
    base_acceleration_limits: list[float] = dataclasses.field(
        default_factory=lambda: [0.3, 0.3, 5.0])
    #: Arm (lift, flex, roll, wrist flex, wrist roll): none is published. Ours: the lift
    #: and the flex, which carry the arm, reach their top speed (0.2 m/s, 1.2 rad/s) in
    #: 0.2 s; the roll and the wrist joints, which carry the hand only, theirs (2.0, 1.5,
    #: 1.5 rad/s) in 0.05 s. The hand then sets off within about three control ticks.
    #: Without limits the flex and the wrist flex took up to 200 rad/s² and the lift
    #: 27 m/s²; lift and flex twice as fast made a vertical start overshoot by 17 %; roll
    #: and wrists as slow as the flex let a teleoperated hand, turning as it went, run up
    #: to 22 % over the fastest command.
    arm_acceleration_limits: list[float] = dataclasses.field(
        default_factory=lambda: [1.0, 6.0, 40.0, 30.0, 30.0])
    #: How fast the arm drifts back to the ready pose (1/s) in the joint motion the hand's
    #: leaves free; the base has no centering, so it takes over what the arm held.
    arm_centering_gain: float = 1.0
    #: Cylinders measured against the robot (not felt by it); with any, the station has
    #: the input obstacle_positions and the outputs in_collision and clearance.
    obstacles: list[CylinderObstacle] = dataclasses.field(default_factory=list)
    #: What the station shows in Meshcat when it is given one (Drake's config; its
    #: illustration and proximity settings are used, its LCM and contact parts are not).
    visualization: VisualizationConfig = dataclasses.field(
        default_factory=default_station_visualization)


def validate_hsr_station_config(config: HsrStationConfig) -> None:
    """Raises ValueError naming the first field of ``config`` that cannot work."""
    check_config_type(config, HsrStationConfig)
    check_field_types(config, "HsrStationConfig")
    validate_station(config, "HsrStationConfig")
    if config.plant.discrete_contact_approximation == "tamsi":
        raise ValueError("HsrStationConfig.plant.discrete_contact_approximation 'tamsi' "
                         "ignores the torso coupler; use 'sap' or 'lagged'")
    if len(config.initial_base) != 3 or not np.all(np.isfinite(config.initial_base)):
        raise ValueError(f"HsrStationConfig.initial_base must be finite [x, y, yaw], got "
                         f"{config.initial_base}")
    for name, size in [("base_kp", 3), ("base_kd", 3), ("arm_kp", 5), ("arm_kd", 5)]:
        gains = getattr(config, name)
        if len(gains) != size or not all(np.isfinite(gains)) or min(gains) < 0:
            raise ValueError(f"HsrStationConfig.{name} must be {size} gains >= 0, got {gains}")
    for name, size in [("base_acceleration_limits", 3), ("arm_acceleration_limits", 5)]:
        limits = getattr(config, name)
        if len(limits) != size or not all(limit > 0 for limit in limits):
            raise ValueError(f"HsrStationConfig.{name} must be {size} limits > 0 (.inf for "
                             f"none), got {limits}")
    if not config.arm_centering_gain >= 0:
        raise ValueError(f"HsrStationConfig.arm_centering_gain must be >= 0, got "
                         f"{config.arm_centering_gain}")


def check_config_type(config, cls):
    """Raises ValueError naming `config` unless it is a `cls` (a dict or None would fail
    later on a missing attribute)."""
    if not isinstance(config, cls):
        raise ValueError(f"config must be {cls.__name__}, got {type(config).__name__}")


def check_field_types(config, name):
    """Raises ValueError naming `name.FIELD` for the first field of the dataclass `config`
    whose value is not of its annotated kind (None for a number, a dict for a ToolPose):
    the checks of values that follow would fail on it with a bare TypeError."""
    hints = typing.get_type_hints(type(config))
    for field in dataclasses.fields(config):
        value, kind = getattr(config, field.name), hints[field.name]
        if not _is_kind(value, kind):
            raise ValueError(f"{name}.{field.name} must be {_kind_text(kind)}, got {value!r}")
        if dataclasses.is_dataclass(value) and type(value).__module__.startswith("pbp_drake"):
            check_field_types(value, f"{name}.{field.name}")
        if typing.get_origin(kind) is list:
            for index, item in enumerate(value):
                if dataclasses.is_dataclass(item):
                    check_field_types(item, f"{name}.{field.name}[{index}]")


def _is_kind(value, kind):
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin in (typing.Union, types.UnionType):
        return any(_is_kind(value, arg) for arg in args)
    if origin is list:
        return (isinstance(value, (list, tuple, np.ndarray))
                and all(_is_kind(item, args[0]) for item in value))
    if kind is float:
        return isinstance(value, numbers.Real)
    return isinstance(value, kind)


def _kind_text(kind):
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin in (typing.Union, types.UnionType):
        return " or ".join(_kind_text(arg) for arg in args)
    if origin is list:
        return f"a list, each {_kind_text(args[0])}"
    article = "an" if kind.__name__[0] in "AEIOU" else "a"
    return {float: "a number", str: "a string", bool: "True or False",
            type(None): "None"}.get(kind, f"{article} {kind.__name__}")


def validate_station(config, name):
    """The fields every station config (`name`: its class) shares: the motion, a discrete
    plant with live output ports, a diff IK period a whole multiple of the plant's step, a
    positive command period or None, obstacles of positive size. Raises ValueError naming
    the field."""
    if config.motion not in MOTIONS:
        raise ValueError(f"{name}.motion must be one of {MOTIONS}, got {config.motion!r}")
    time_step = config.plant.time_step
    if not time_step > 0:
        raise ValueError(f"{name}.plant.time_step must be positive (a discrete plant), got "
                         f"{time_step}")
    if config.plant.use_sampled_output_ports:
        # Sampled ports are refreshed by the plant's step, an unrestricted update, which
        # Drake applies before the discrete updates of the same instant: a control loop
        # sampling the robot at a tick would see the state one plant step later whenever
        # the tick and a plant step fall on the same float time, and not otherwise.
        raise ValueError(f"{name}.plant.use_sampled_output_ports must be False, so that a "
                         "sample at a control tick sees the robot at that tick")
    steps = config.diff_ik_time_step / time_step
    if not (config.diff_ik_time_step > 0 and abs(steps - round(steps)) < 1e-9):
        raise ValueError(f"{name}.diff_ik_time_step must be a whole multiple of "
                         f"plant.time_step {time_step}, got {config.diff_ik_time_step}")
    if config.control_period is not None and not config.control_period > 0:
        raise ValueError(f"{name}.control_period must be positive or None, got "
                         f"{config.control_period}")
    for index, obstacle in enumerate(config.obstacles):
        if not (obstacle.radius > 0 and obstacle.height > 0):
            raise ValueError(f"{name}.obstacles[{index}] needs a positive radius and height, "
                             f"got {obstacle}")
