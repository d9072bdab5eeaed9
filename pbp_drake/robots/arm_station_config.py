"""What an arm station is built from: ``ArmStationConfig``, its ``ArmHardware`` (the real
arm's driver and bus) and their validation (the fields alone; what needs the model, its
frames and limits, is checked where it is loaded, ``pbp_drake.robots.arm_model``)."""

import copyreg
import dataclasses
import re
import typing

import numpy as np
from pydrake.lcm import DrakeLcmParams
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.visualization import VisualizationConfig

from pbp_drake.robots.hsr_station_config import (
    CylinderObstacle, check_config_type, check_field_types, default_station_plant_config,
    default_station_visualization, validate_station)


@dataclasses.dataclass(frozen=True)
class Driver:
    """What a Drake LCM driver of a real arm expects: its channels, its status period (s),
    how many joints it drives, and how long after its first status it refuses any command
    (drake-iiwa-driver aborts on one within 0.25 s)."""

    command_channel: str
    status_channel: str
    period: float
    joint_count: int
    start_guard: float


#: The drivers the station speaks to: drake-franka-driver in position mode (status and
#: commands at libfranka's 1 kHz) and drake-iiwa-driver with the position Java app (FRI's
#: 5 ms).
DRIVERS = {
    "panda": Driver("PANDA_COMMAND", "PANDA_STATUS", 0.001, 7, 0.0),
    "iiwa": Driver("IIWA_COMMAND", "IIWA_STATUS", 0.005, 7, 0.25),
}
#: Drake's hardware_sim bus: multicast with ttl=0, so that its traffic stays on this machine.
DEFAULT_LCM_URL = "udpm://239.241.129.92:20185?ttl=0"
_UDPM = re.compile(r"udpm://(\d{1,3})\.(\d{1,3})\.(\d{1,3})\.(\d{1,3}):(\d{1,5})"
                   r"(\?(ttl|recv_buf_size)=\d+(&(ttl|recv_buf_size)=\d+)?)?")


def _lcm_params(lcm_url, channel_suffix, defer_initialization):
    return DrakeLcmParams(lcm_url=lcm_url, channel_suffix=channel_suffix,
                          defer_initialization=defer_initialization)


# A study sends each trial's scenario to its worker process by pickle, which Drake's
# DrakeLcmParams does not support on its own.
copyreg.pickle(DrakeLcmParams, lambda params: (_lcm_params, (
    params.lcm_url, params.channel_suffix, params.defer_initialization)))


@dataclasses.dataclass
class ArmHardware:
    """The real arm behind an ``ArmStationConfig``: which Drake LCM driver runs it and on
    which bus; unused unless ``connect`` (otherwise the arm is simulated)."""

    #: The arm's driver: "panda" (drake-franka-driver, position mode) or "iiwa"
    #: (drake-iiwa-driver, the position Java app).
    driver: str = ""
    #: The driver's LCM bus (Drake's DrakeLcmParams): udpm://ADDRESS:PORT?ttl=N or memq://.
    #: The default is Drake's hardware_sim bus with ttl=0 (its traffic stays on this
    #: machine); a driver on another machine needs ttl=1.
    lcm_bus: DrakeLcmParams = dataclasses.field(
        default_factory=lambda: DrakeLcmParams(lcm_url=DEFAULT_LCM_URL))
    #: Whether runs drive the arm through its driver (`pbp-drake run --hardware`).
    connect: bool = False
    #: With connect: a driver simulator in the same process in place of the driver, both
    #: on one memq:// bus and the simulation's clock (`pbp-drake run --driver-sim`).
    driver_sim: bool = False
    #: The longest the driver's status may be silent (s) before the station holds the arm
    #: where it last commanded it and ends the run.
    status_timeout: float = 0.05
    #: How long (s) the station waits for the driver's first status before it fails.
    connect_timeout: float = 5.0
    #: Our own expiry: the station sends no command computed more than this (s) behind or
    #: ahead of the wall clock (a control loop off real time holds the arm and ends).
    command_expiry: float = 0.05
    #: How far (rad) the first status may stand from the configuration the run was built
    #: for (read from the driver's status before the run).
    start_tolerance: float = 0.01


@dataclasses.dataclass
class ToolPose:
    """A pose of the tool (the station's ee_frame) in the world."""

    #: Where it stands: x, y, z (m).
    position: list[float] = dataclasses.field(default_factory=list)
    #: Its orientation: roll, pitch, yaw (degrees; Drake's RollPitchYaw, about the world's
    #: fixed x, y, z axes in that order). [0, 90, 0] points the tool's z axis along +x.
    rpy_degrees: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0, 0.0])

    def transform(self):
        """The pose as a RigidTransform."""
        return RigidTransform(RollPitchYaw(np.radians(self.rpy_degrees)), self.position)


@dataclasses.dataclass
class ArmStationConfig:
    """Everything ``make_arm_station`` builds from; loads with ``yaml_load_typed``. The
    arm is any fixed-base serial chain of revolute or prismatic joints in a URDF or
    SDFormat file, its base welded to the world; see docs/concepts/your-robot.md."""

    #: The model: a URDF or SDFormat file, as a path or a package:// URL
    #: (package://pbp_drake_models/... is ours; nothing is downloaded).
    model_file: str = ""
    #: The frame the arm stands on (usually its root link), welded to the world at
    #: base_pose.
    base_frame: str = ""
    #: The frame the hand's command and state are about; its z axis points out of the
    #: tool (the heading is the direction it points in the floor plane).
    ee_frame: str = ""
    #: Where base_frame sits in the world: x, y, z (m), yaw (rad).
    base_pose: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])
    #: The ready configuration the arm starts in (rad or m), one per joint in the model's
    #: joint order; empty: the model's default positions. Its ee_frame z axis must be
    #: within 60 degrees of the floor plane. With ready_tool_pose: where inverse
    #: kinematics starts from and stays near.
    initial_positions: list[float] = dataclasses.field(default_factory=list)
    #: The ready configuration as the pose of ee_frame in the world (a ToolPose: its
    #: position and rpy_degrees), solved by inverse kinematics within the joints' limits;
    #: none: initial_positions is the ready configuration.
    ready_tool_pose: typing.Optional[ToolPose] = None
    #: "kinematic": the joints are on the diff IK's plan at every instant (no plant is
    #: stepped); "dynamic": the plant and stiff PD servos (servo_frequency) track it.
    motion: str = "kinematic"
    #: Drake's MultibodyPlantConfig of the arm's plant (dynamic motion steps it).
    plant: MultibodyPlantConfig = dataclasses.field(default_factory=default_station_plant_config)
    #: The differential IK's period (s), a whole multiple of plant.time_step.
    diff_ik_time_step: float = 0.01
    #: The period of a control loop that sends each tick the state [p, v] to reach at the
    #: next tick; the station then ramps into p at v (see EeCommandToPose). None: track p.
    control_period: float | None = None
    #: Each joint's acceleration limit (rad/s^2 or m/s^2) where the model gives none.
    default_acceleration_limit: float = 10.0
    #: How fast the arm drifts back to its ready configuration (1/s) in the joint motion
    #: the hand's leaves free (a redundant arm's elbow, say).
    centering_gain: float = 1.0
    #: Near a singular configuration (the Jacobian's least singular value under this, m
    #: per rad), the diff IK damps the joints' velocities rather than spin a joint pair to
    #: move the hand along a direction it has all but lost (damped least squares); 0: off.
    singular_margin: float = 0.0
    #: Within this distance (rad or m) of a joint's position limit, the diff IK pushes the
    #: joint back in the joint motion the hand's leaves free, so that the arm does not
    #: stall with a joint on its limit and the hand short of its command; 0: off.
    limit_margin: float = 0.0
    #: Dynamic motion: each joint's servo is critically damped at this frequency (rad/s)
    #: on the joint's own inertia in the ready configuration (kp = I w^2, kd = 2 I w).
    servo_frequency: float = 300.0
    #: Cylinders measured against the arm (not felt by it); with any, the station has the
    #: input obstacle_positions and the outputs in_collision and clearance.
    obstacles: list[CylinderObstacle] = dataclasses.field(default_factory=list)
    #: What the station shows in Meshcat when it is given one (Drake's config).
    visualization: VisualizationConfig = dataclasses.field(
        default_factory=default_station_visualization)
    #: The real arm's driver and bus (used with `hardware.connect`); none: simulated only.
    hardware: typing.Optional[ArmHardware] = None


def validate_arm_station_config(config: ArmStationConfig) -> None:
    """Raises ValueError naming the first field of ``config`` that cannot work (the model
    itself is checked when it is loaded)."""
    check_config_type(config, ArmStationConfig)
    check_field_types(config, "ArmStationConfig")
    for name in ("model_file", "base_frame", "ee_frame"):
        if not getattr(config, name):  # a string: check_field_types
            raise ValueError(f"ArmStationConfig.{name} is needed (a non-empty string)")
    validate_station(config, "ArmStationConfig")
    if len(config.base_pose) != 4 or not np.all(np.isfinite(config.base_pose)):
        raise ValueError(f"ArmStationConfig.base_pose must be finite [x, y, z, yaw], got "
                         f"{config.base_pose}")
    if not np.all(np.isfinite(config.initial_positions)):
        raise ValueError(f"ArmStationConfig.initial_positions must be finite, got "
                         f"{config.initial_positions}")
    pose = config.ready_tool_pose
    if pose is not None:
        for name in ("position", "rpy_degrees"):
            value = getattr(pose, name)
            if len(value) != 3 or not np.all(np.isfinite(value)):
                raise ValueError(f"ArmStationConfig.ready_tool_pose.{name} must be three "
                                 f"finite numbers, got {value}")
    check_positive(config, ("default_acceleration_limit", "servo_frequency"),
                   "ArmStationConfig")
    for name in ("singular_margin", "centering_gain", "limit_margin"):
        value = getattr(config, name)
        if not (np.isfinite(value) and value >= 0):
            raise ValueError(f"ArmStationConfig.{name} must be >= 0, got {value}")
    hardware = config.hardware
    if hardware is not None:
        if hardware.driver not in DRIVERS:
            raise ValueError(f"ArmStationConfig.hardware.driver must be one of "
                             f"{sorted(DRIVERS)}, got {hardware.driver!r}")
        validate_link(hardware, "ArmStationConfig.hardware", (
            "status_timeout", "connect_timeout", "command_expiry", "start_tolerance"))


def validate_link(link, field, positive):
    """Raises ValueError naming the field (`field`: where `link` stands) unless the LCM URL
    of an `ArmHardware` or `TaskSpaceBridgeConfig` can be shared by two processes, its
    fields `positive` are finite and positive, and `driver_sim` comes only with `connect`."""
    url = link.lcm_bus.lcm_url
    if not (url == "memq://" or _valid_udpm(url)):
        raise ValueError(f"{field}.lcm_bus.lcm_url {url!r} is not an LCM URL the driver can "
                         "share: udpm://ADDRESS:PORT?ttl=N (a multicast IPv4 address) or "
                         f"memq://; Drake's hardware_sim uses {DEFAULT_LCM_URL}")
    check_positive(link, positive, field)
    if link.driver_sim and not link.connect:
        raise ValueError(f"{field}.driver_sim needs connect (pbp-drake run --hardware "
                         "--driver-sim)")


def check_positive(config, names, prefix):
    """Raises ValueError naming `prefix.NAME` for the first of `names` of `config` that is
    not finite and positive."""
    for name in names:
        value = getattr(config, name)
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{prefix}.{name} must be finite and positive, got {value}")


def _valid_udpm(url):
    """Whether `url` is udpm:// with a multicast IPv4 address and a port."""
    match = _UDPM.fullmatch(url)
    if match is None:
        return False
    octets = [int(match.group(index)) for index in range(1, 5)]
    return (224 <= octets[0] <= 239 and all(octet <= 255 for octet in octets)
            and 0 < int(match.group(5)) < 65536)
