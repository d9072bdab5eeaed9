"""Layer 2: thin Drake LeafSystems over `pbp_drake.core`, one system a file.

Port names are the public contract: `robot_state`, `goals`, `operator_command`,
`operator_active`, `references`, `selected_goal`, `goal_probabilities`, `command`, `state`,
`ee_state`, `target`, `task_status`.

Vector layouts: a robot state is `[positions (D), velocities (D)]`; `references` of K goals is
`[positions (K*D, row-major (K, D)), velocities (K*D)]`; `command` is `[position (D),
velocity (D)]`. On the HSR, `ee_state` is `[p (3), v (3), heading, heading_rate]` and an
operator's command `[vx, vy, vz, yaw_rate]` in the world frame; `systems.layouts` names their
entries. Six-DoF PBP (`PoseDmpBank`, `PoseBlender`, `PoseHandOver`) uses `PoseState`
`[x, y, z, qw, qx, qy, qz, vx, vy, vz, wx, wy, wz]` and `OperatorTwist` (docs/six_dof.md); its browser
operators (`GamepadTwistOperator`, `KeyboardTwistOperator`) take the hand's `hand_state` and
output `operator_twist`; so do the grasping task's `PoseGoalEstimator`,
`GraspParticipantSystem` and `GraspTaskMonitor` (docs/grasp_task.md). `systems.tick` states
the order of the updates within a control tick.
"""

from pbp_drake.systems.blender import Blender
from pbp_drake.systems.demonstration_player import DemonstrationPlayer
from pbp_drake.systems.dmp_bank import DmpBank
from pbp_drake.systems.gamepad_operator import GamepadOperator
from pbp_drake.systems.gamepad_twist_operator import GamepadTwistOperator
from pbp_drake.systems.goal_estimator import GoalEstimator
from pbp_drake.systems.goals_source import GoalsSource
from pbp_drake.systems.grasp_participant import GraspParticipantSystem
from pbp_drake.systems.grasp_scene_visualizer import GraspSceneVisualizer
from pbp_drake.systems.grasp_task_monitor import GraspTaskMonitor
from pbp_drake.systems.hand_over import HandOver
from pbp_drake.systems.heading_command import HeadingCommand
from pbp_drake.systems.keyboard_operator import KeyboardOperator
from pbp_drake.systems.keyboard_twist_operator import KeyboardTwistOperator
from pbp_drake.systems.no_operator import NoOperator
from pbp_drake.systems.obstacle_repulsion_operator import ObstacleRepulsionOperator
from pbp_drake.systems.point_robot import PointRobot
from pbp_drake.systems.pose_blender import PoseBlender
from pbp_drake.systems.pose_dmp_bank import PoseDmpBank
from pbp_drake.systems.pose_goal_estimator import PoseGoalEstimator
from pbp_drake.systems.pose_hand_over import PoseHandOver
from pbp_drake.systems.reach_scene_visualizer import ReachSceneVisualizer
from pbp_drake.systems.sample_hold import SampleHold
from pbp_drake.systems.scripted_operator import ScriptedOperator
from pbp_drake.systems.task_monitor import TaskMonitor
from pbp_drake.systems.virtual_participant import VirtualParticipant

__all__ = [
    "Blender", "DemonstrationPlayer", "DmpBank", "GamepadOperator", "GamepadTwistOperator",
    "GoalEstimator", "GoalsSource", "GraspSceneVisualizer", "HandOver", "HeadingCommand",
    "KeyboardOperator", "KeyboardTwistOperator", "NoOperator", "ObstacleRepulsionOperator",
    "PointRobot", "PoseBlender", "PoseDmpBank", "PoseHandOver", "ReachSceneVisualizer", "SampleHold", "ScriptedOperator", "TaskMonitor",
    "VirtualParticipant",
    # The grasping task's (docs/grasp_task.md).
    "GraspParticipantSystem", "GraspTaskMonitor", "PoseGoalEstimator",
]
