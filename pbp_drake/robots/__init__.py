"""Robot models and the helpers that load them into Drake; the HSR station."""

from pbp_drake.robots.hsr_model import add_hsr
from pbp_drake.robots.hsr_station import (
    hsr_initial_ee_state,
    hsr_initial_hand_pose,
    hsr_ready_ee_state,
    hsr_station_plant,
    make_hsr_station,
)
from pbp_drake.robots.hsr_station_config import CylinderObstacle, HsrStationConfig

__all__ = ["CylinderObstacle", "HsrStationConfig", "add_hsr", "hsr_initial_ee_state",
           "hsr_initial_hand_pose", "hsr_ready_ee_state", "hsr_station_plant",
           "make_hsr_station"]
