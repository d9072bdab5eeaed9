"""Robot models and the helpers that load them into Drake; the HSR's and any arm's
stations (a Diagram from `ee_command` to `ee_state`)."""

from pbp_drake.robots.arm_station import (
    arm_initial_ee_state,
    arm_reach,
    arm_ready_ee_state,
    arm_station_plant,
    make_arm_station,
)
from pbp_drake.robots.arm_station_config import ArmStationConfig
from pbp_drake.robots.hsr_model import add_hsr
from pbp_drake.robots.hsr_station import (
    hsr_initial_ee_state,
    hsr_initial_hand_pose,
    hsr_ready_ee_state,
    hsr_station_plant,
    make_hsr_station,
)
from pbp_drake.robots.hsr_station_config import CylinderObstacle, HsrStationConfig

__all__ = ["ArmStationConfig", "CylinderObstacle", "HsrStationConfig", "add_hsr",
           "arm_initial_ee_state", "arm_reach", "arm_ready_ee_state", "arm_station_plant",
           "hsr_initial_ee_state", "hsr_initial_hand_pose", "hsr_ready_ee_state",
           "hsr_station_plant", "make_arm_station", "make_hsr_station"]
