"""Robot models and the helpers that load them into Drake; the HSR's and any arm's
stations (a Diagram from `ee_command` to `ee_state`)."""

from pbp_drake.robots.arm_driver import DriverError
from pbp_drake.robots.arm_station import (
    arm_driver_sim,
    arm_initial_ee_state,
    arm_reach,
    arm_ready_ee_state,
    arm_station_plant,
    drives_real_robot,
    make_arm_station,
    measured_ready_positions,
)
from pbp_drake.robots.arm_station_config import ArmHardware, ArmStationConfig, ToolPose
from pbp_drake.robots.hsr_model import add_hsr
from pbp_drake.robots.hsr_station import (
    hsr_initial_ee_state,
    hsr_initial_hand_pose,
    hsr_ready_ee_state,
    hsr_station_plant,
    make_hsr_station,
)
from pbp_drake.robots.hsr_station_config import CylinderObstacle, HsrStationConfig
from pbp_drake.robots.task_space_bridge import (
    TaskSpaceBridgeConfig,
    make_station_relay,
    make_task_space_bridge,
)

__all__ = ["ArmHardware", "ArmStationConfig", "CylinderObstacle", "DriverError",
           "HsrStationConfig", "add_hsr", "arm_driver_sim", "arm_initial_ee_state",
           "arm_reach", "arm_ready_ee_state", "arm_station_plant", "drives_real_robot",
           "hsr_initial_ee_state", "hsr_initial_hand_pose", "hsr_ready_ee_state",
           "hsr_station_plant", "make_arm_station", "make_hsr_station",
           "measured_ready_positions", "ToolPose", "TaskSpaceBridgeConfig",
           "make_station_relay", "make_task_space_bridge"]
