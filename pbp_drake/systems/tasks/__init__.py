"""The tasks' systems: what measures a task (`TaskMonitor` for reaching and obstacles,
`GraspTaskMonitor`, `CollisionMonitor`), the obstacle task's moving cylinders
(`MovingObstacles`, `CylinderObstacleGeometry`) and the 2-D scenes' robot
(`PointRobotDynamics`)."""

from pbp_drake.systems.tasks.collision_monitor import CollisionMonitor
from pbp_drake.systems.tasks.grasp_task_monitor import GraspTaskMonitor
from pbp_drake.systems.tasks.moving_obstacles import MovingObstacles
from pbp_drake.systems.tasks.obstacle_geometry import CylinderObstacleGeometry
from pbp_drake.systems.tasks.point_robot_dynamics import PointRobotDynamics
from pbp_drake.systems.tasks.task_monitor import TaskMonitor

__all__ = ["CollisionMonitor", "CylinderObstacleGeometry", "GraspTaskMonitor",
           "MovingObstacles", "PointRobotDynamics", "TaskMonitor"]
