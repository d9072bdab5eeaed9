"""Layer 2: thin Drake LeafSystems over `pbp_drake.core`, one system a file.

Port names are the public contract: `robot_state`, `goals`, `operator_command`,
`operator_active`, `references`, `selected_goal`, `command`, `state`.

Vector layouts: a robot state is `[positions (D), velocities (D)]`; `references` of K goals is
`[positions (K*D, row-major (K, D)), velocities (K*D)]`; `command` is `[position (D),
velocity (D)]`.
"""

from pbp_drake.systems.blender import Blender
from pbp_drake.systems.demonstration_player import DemonstrationPlayer
from pbp_drake.systems.dmp_bank import DmpBank
from pbp_drake.systems.no_operator import NoOperator
from pbp_drake.systems.obstacle_repulsion_operator import ObstacleRepulsionOperator
from pbp_drake.systems.point_robot import PointRobot
from pbp_drake.systems.scripted_operator import ScriptedOperator

__all__ = [
    "Blender", "DemonstrationPlayer", "DmpBank", "NoOperator", "ObstacleRepulsionOperator",
    "PointRobot", "ScriptedOperator",
]
