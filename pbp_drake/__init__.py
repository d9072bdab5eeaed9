"""pbp_drake: Policy Blending with Primitives (PBP) for shared control, on Drake.

The math lives in `pbp_drake.core` (NumPy only); the Drake systems in `pbp_drake.systems`;
`pbp_drake.scenarios.resolve` derives everything from a scenario once, and
`pbp_drake.builder.build_diagram` turns it into a Diagram. The names below
can be imported from `pbp_drake` directly; each is loaded on first use, so that
`import pbp_drake` stays cheap and the NumPy core never pulls in Drake.
"""

import importlib

__version__ = "0.1.0"

# Public name -> the module that defines it.
_PUBLIC = {
    # DMP math (NumPy only); the vectorised bank is `pbp_drake.core.dmp.DmpBank`.
    "Dmp": "pbp_drake.core.dmp",
    "DmpSettings": "pbp_drake.core.dmp",
    "GoalEstimatorSettings": "pbp_drake.core.goal_estimation",
    # Scenarios, diagrams, runs and studies.
    "load_scenario_file": "pbp_drake.scenarios",
    "resolve": "pbp_drake.scenarios",
    "ResolvedScenario": "pbp_drake.scenarios",
    "build_diagram": "pbp_drake.builder",
    "find_system": "pbp_drake.builder",
    "make_pbp_controller": "pbp_drake.builder",
    "simulate": "pbp_drake.builder",
    "run_task": "pbp_drake.builder",
    "run_method_comparison": "pbp_drake.studies.comparison",
    # The robot.
    "add_hsr": "pbp_drake.robots.hsr_model",
    "make_hsr_station": "pbp_drake.robots.hsr_station",
    "HsrStationConfig": "pbp_drake.robots.hsr_station_config",
    "hsr_initial_ee_state": "pbp_drake.robots.hsr_station",
    "hsr_ready_ee_state": "pbp_drake.robots.hsr_station",
    # Drake systems.
    "Blender": "pbp_drake.systems",
    "DmpBank": "pbp_drake.systems",
    "GoalEstimator": "pbp_drake.systems",
    "GoalsSource": "pbp_drake.systems",
    "HandOver": "pbp_drake.systems",
    "TaskMonitor": "pbp_drake.systems",
    "HeadingCommand": "pbp_drake.systems",
    "KeyboardOperator": "pbp_drake.systems",
    "GamepadOperator": "pbp_drake.systems",
    "VirtualParticipant": "pbp_drake.systems",
    "NoOperator": "pbp_drake.systems",
    "ObstacleRepulsionOperator": "pbp_drake.systems",
    "ScriptedOperator": "pbp_drake.systems",
    "PointRobot": "pbp_drake.systems",
    "ReachSceneVisualizer": "pbp_drake.systems",
    "MovingObstacles": "pbp_drake.systems.moving_obstacles",
    "CollisionMonitor": "pbp_drake.systems.collision_monitor",
}
__all__ = ["__version__", *_PUBLIC]


def __getattr__(name):
    if name in _PUBLIC:
        return getattr(importlib.import_module(_PUBLIC[name]), name)
    raise AttributeError(f"module 'pbp_drake' has no attribute {name!r}")
