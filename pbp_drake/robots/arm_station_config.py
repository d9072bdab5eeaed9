"""What an arm station is built from: ``ArmStationConfig`` and its validation (the fields
alone; what needs the model, its frames and limits, is checked where it is loaded,
``pbp_drake.robots.arm_model``)."""

import dataclasses

import numpy as np
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.visualization import VisualizationConfig

from pbp_drake.robots.hsr_station_config import (
    MOTIONS, CylinderObstacle, default_station_plant_config, default_station_visualization,
    validate_station_obstacles, validate_station_timing)


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
    #: within 60 degrees of the floor plane.
    initial_positions: list[float] = dataclasses.field(default_factory=list)
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
    #: Dynamic motion: each joint's servo is critically damped at this frequency (rad/s)
    #: on the joint's own inertia in the ready configuration (kp = I w^2, kd = 2 I w).
    servo_frequency: float = 300.0
    #: Cylinders measured against the arm (not felt by it); with any, the station has the
    #: input obstacle_positions and the outputs in_collision and clearance.
    obstacles: list[CylinderObstacle] = dataclasses.field(default_factory=list)
    #: What the station shows in Meshcat when it is given one (Drake's config).
    visualization: VisualizationConfig = dataclasses.field(
        default_factory=default_station_visualization)


def validate_arm_station_config(config: ArmStationConfig) -> None:
    """Raises ValueError naming the first field of ``config`` that cannot work (the model
    itself is checked when it is loaded)."""
    for name in ("model_file", "base_frame", "ee_frame"):
        if not isinstance(getattr(config, name), str) or not getattr(config, name):
            raise ValueError(f"ArmStationConfig.{name} is needed (a non-empty string)")
    if config.motion not in MOTIONS:
        raise ValueError(f"ArmStationConfig.motion must be one of {MOTIONS}, got "
                         f"{config.motion!r}")
    time_step = config.plant.time_step
    if not time_step > 0:
        raise ValueError(f"ArmStationConfig.plant.time_step must be positive, got {time_step}")
    validate_station_timing(config, "ArmStationConfig")
    if len(config.base_pose) != 4 or not np.all(np.isfinite(config.base_pose)):
        raise ValueError(f"ArmStationConfig.base_pose must be finite [x, y, z, yaw], got "
                         f"{config.base_pose}")
    if not np.all(np.isfinite(config.initial_positions)):
        raise ValueError(f"ArmStationConfig.initial_positions must be finite, got "
                         f"{config.initial_positions}")
    for name in ("default_acceleration_limit", "servo_frequency"):
        value = getattr(config, name)
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"ArmStationConfig.{name} must be finite and positive, got "
                             f"{value}")
    if not (np.isfinite(config.centering_gain) and config.centering_gain >= 0):
        raise ValueError(f"ArmStationConfig.centering_gain must be >= 0, got "
                         f"{config.centering_gain}")
    validate_station_obstacles(config, "ArmStationConfig")
