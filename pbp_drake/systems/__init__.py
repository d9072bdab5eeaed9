"""Layer 2: thin Drake LeafSystems over `pbp_drake.core`, one system a file, by topic:

- `systems.pbp`: the PBP loop (DMP banks, goal estimators, blenders, the hand-over), in
  position form and in six-DoF pose form (the `Pose...` systems);
- `systems.operators`: the person in the browser, the virtual participant, scripted inputs;
- `systems.tasks`: the task monitors, the obstacle task's cylinders, the 2-D robot;
- `systems.visualizers`: Meshcat drawing of each task's scene;
- `systems.ports`: the named entries of the port vectors; `systems.tick`: the order of the
  updates within a control tick; `SampleHold`: the tick's sample of the robot's state.

Port names are the public contract. A robot state is `[positions (D), velocities (D)]`;
`references` of K goals `[positions (K*D, row-major (K, D)), velocities (K*D)]`; the HSR's
and the six-DoF systems' vectors are the named views of `systems.ports`.
"""

from pbp_drake.systems.operators import (
    GamepadOperator, IdleOperator, KeyboardOperator, ObstacleRepulsionOperator,
    PoseGamepadOperator, PoseKeyboardOperator, PoseVirtualOperator, ScriptedOperator,
    VirtualOperator)
from pbp_drake.systems.pbp import (
    Blender, DemonstrationPlayer, DmpBank, GoalEstimator, GoalGrouping, GoalsSource, HandOver,
    HeadingCommand, HopAssistance, IntentFilterGoalEstimator, LikelyGoals, MaxEntGoalEstimator,
    PoseBlender, PoseDmpBank, PoseGoalEstimator, PoseGoalGrouping, PoseHandOver,
    PoseHopAssistance, PoseIntentFilterGoalEstimator, PoseMaxEntGoalEstimator)
from pbp_drake.systems.sample_hold import SampleHold
from pbp_drake.systems.tasks import (
    CollisionMonitor, CylinderObstacleGeometry, GraspTaskMonitor, MovingObstacles,
    PointRobotDynamics, TaskMonitor)
from pbp_drake.systems.visualizers import (
    GraspSceneVisualizer, PointSceneVisualizer, ReachSceneVisualizer)

__all__ = [
    # The PBP loop.
    "Blender", "DemonstrationPlayer", "DmpBank", "GoalEstimator", "GoalGrouping", "GoalsSource",
    "HandOver", "HeadingCommand", "IntentFilterGoalEstimator", "LikelyGoals", "PoseBlender",
    "PoseDmpBank", "PoseGoalEstimator", "PoseGoalGrouping", "PoseHandOver",
    "PoseIntentFilterGoalEstimator",
    # The shared-autonomy baselines (HOP, predict-then-assist) and PBP's maxent_command estimator.
    "HopAssistance", "MaxEntGoalEstimator", "PoseHopAssistance", "PoseMaxEntGoalEstimator",
    # Operators.
    "GamepadOperator", "IdleOperator", "KeyboardOperator", "ObstacleRepulsionOperator",
    "PoseGamepadOperator", "PoseKeyboardOperator", "PoseVirtualOperator", "ScriptedOperator",
    "VirtualOperator",
    # Tasks.
    "CollisionMonitor", "CylinderObstacleGeometry", "GraspTaskMonitor", "MovingObstacles",
    "PointRobotDynamics", "TaskMonitor",
    # Drawing, and the sample-and-hold every task's loop reads the robot through.
    "GraspSceneVisualizer", "PointSceneVisualizer", "ReachSceneVisualizer", "SampleHold",
]
