"""pbp_drake: Policy Blending with Primitives (PBP) for shared control, on Drake.

Every name the documentation lists imports from here: `from pbp_drake import DmpBank,
make_hsr_station`. Each is loaded on first use, so that `import pbp_drake` stays cheap and
the NumPy core never pulls in Drake. `API_GROUPS` says where each name belongs by topic (the
API reference is generated from it); the subpackages hold the rest:

- `pbp_drake.core`: the math, NumPy only (DMPs, blending, goal estimation, the tasks);
- `pbp_drake.systems`: the Drake LeafSystems (`pbp`, `operators`, `tasks`, `visualizers`);
- `pbp_drake.robots`: the HSR model and its station;
- `pbp_drake.scenarios`: scenario files (schema, loading, checks, `resolve`);
- `pbp_drake.builder`: a resolved scenario to a Diagram, and runs;
- `pbp_drake.studies`, `pbp_drake.console`: studies, the operator's page.

The bench and the soak test are the package `pbp_drake_bench`, beside this one.
"""

import importlib

__version__ = "0.1.0"

# Topic -> {public name: the module that defines it}. One place: `__all__`, `__getattr__`
# and the API reference all read it.
API_GROUPS = {
    "DMP math (NumPy)": {
        "Dmp": "pbp_drake.core.dmp",
        "DmpBankModel": "pbp_drake.core.dmp",
        "DmpSettings": "pbp_drake.core.dmp",
        "minimum_jerk": "pbp_drake.core.dmp",
        **{name: "pbp_drake.core.dmp.primitive" for name in [
            "Primitive", "teach_primitive", "primitive_bank", "primitive_orientation_bank",
            "primitive_document", "read_primitive_document"]},
        "OrientationDmp": "pbp_drake.core.dmp",
        "OrientationDmpBank": "pbp_drake.core.dmp",
        "GoalEstimatorSettings": "pbp_drake.core.goal_estimation",
        "quaternion": "pbp_drake.core",
        "HandOverLimits": "pbp_drake.core.pose_arbitration",
        "PoseReference": "pbp_drake.core.pose_arbitration",
        "blend_pose": "pbp_drake.core.pose_arbitration",
        "pose_hand_over": "pbp_drake.core.pose_arbitration",
        "VirtualParticipantParams": "pbp_drake.core.participant_params",
        "ParticipantImpairment": "pbp_drake.core.participant_impairment",
        "GraspParticipantParams": "pbp_drake.core.participant_grasp",
    },
    "Methods and goal estimators (registries)": {
        "Method": "pbp_drake.core.methods",
        "register_method": "pbp_drake.core.methods",
        "Estimator": "pbp_drake.core.goal_estimation",
        "register_estimator": "pbp_drake.core.goal_estimation",
        "IntentFilterSettings": "pbp_drake.core.intent_filter",
    },
    "Shared-autonomy baselines (HOP, predict-then-assist)": {
        "HopSettings": "pbp_drake.core.hindsight_optimization",
        "hop_targets": "pbp_drake.core.hindsight_optimization",
        "update_posterior": "pbp_drake.core.hindsight_optimization",
        "assisted_command": "pbp_drake.core.hindsight_optimization",
        **{name: "pbp_drake.systems.pbp" for name in [
            "MaxEntGoalEstimator", "HopAssistance", "PoseMaxEntGoalEstimator",
            "PoseHopAssistance"]},
    },
    "The PBP loop's systems": {
        name: "pbp_drake.systems.pbp" for name in [
            "DmpBank", "GoalEstimator", "GoalGrouping", "IntentFilterGoalEstimator", "Blender",
            "HandOver", "GoalsSource",
            "HeadingCommand", "DemonstrationPlayer"]},
    "Six-DoF PBP systems": {
        name: "pbp_drake.systems.pbp" for name in [
            "PoseDmpBank", "PoseGoalEstimator", "PoseBlender", "PoseHandOver",
            "PoseGoalGrouping", "PoseIntentFilterGoalEstimator"]},
    "Operators": {
        name: "pbp_drake.systems.operators" for name in [
            "KeyboardOperator", "GamepadOperator", "VirtualOperator", "ScriptedOperator",
            "ObstacleRepulsionOperator", "IdleOperator", "PoseKeyboardOperator",
            "PoseGamepadOperator", "PoseVirtualOperator"]},
    "Tasks and drawing": {
        **{name: "pbp_drake.systems.tasks" for name in [
            "TaskMonitor", "GraspTaskMonitor", "MovingObstacles", "CollisionMonitor",
            "CylinderObstacleGeometry", "PointRobotDynamics"]},
        **{name: "pbp_drake.systems.visualizers" for name in [
            "ReachSceneVisualizer", "GraspSceneVisualizer", "PointSceneVisualizer"]},
        "SampleHold": "pbp_drake.systems",
    },
    "Port vectors": {
        name: "pbp_drake.systems.ports" for name in [
            "EeState", "EeCommand", "OperatorCommand", "Target", "TaskStatus", "PoseState",
            "OperatorTwist"]},
    "The HSR": {
        "make_hsr_station": "pbp_drake.robots",
        "HsrStationConfig": "pbp_drake.robots",
        "add_hsr": "pbp_drake.robots",
        "CylinderObstacle": "pbp_drake.robots",
        "hsr_station_plant": "pbp_drake.robots",
        "hsr_initial_ee_state": "pbp_drake.robots",
        "hsr_initial_hand_pose": "pbp_drake.robots",
        "hsr_ready_ee_state": "pbp_drake.robots",
    },
    "Your own arm": {
        **{name: "pbp_drake.robots" for name in [
            "make_arm_station", "ArmStationConfig", "arm_initial_ee_state", "arm_reach",
            "arm_ready_ee_state", "arm_station_plant", "ToolPose"]},
        **{name: "pbp_drake.core.controller_config" for name in [
            "PbpControllerConfig", "HandOverSettings"]},
    },
    "Real robots": {
        name: "pbp_drake.robots" for name in [
            "ArmHardware", "DriverError", "arm_driver_sim", "measured_ready_positions",
            "drives_real_robot", "TaskSpaceBridgeConfig", "make_task_space_bridge",
            "make_station_relay"]},
    "Scenario files": {
        name: "pbp_drake.scenarios" for name in [
            "load_scenario_file", "resolve", "ResolvedScenario", "ScenarioError",
            "ScenarioFile", "Scenario", "PointScenario", "TaskScenario", "Hsr", "Arm",
            "PointRobot", "MultiGoalReach",
            "DynamicObstacles", "GraspTask", "VirtualParticipant", "Keyboard", "Gamepad",
            "NoOperator", "ScriptedCommands", "SinusoidalStep", "ObstacleRepulsion",
            "BentPath", "RecordedPath", "Obstacle", "MethodComparison", "AlphaStudy",
            "AltVsCont", "SceneVariant", "NoisyPilot", "LaggyPilot", "ProportionalPilot",
            "ParticipantPopulation", "with_pilot"]},
    "Building and running": {
        name: "pbp_drake.builder" for name in [
            "build_diagram", "make_pbp_controller", "find_system", "simulate", "run_task",
            "TaskResult"]},
    "The 2-D scenes": {
        "bent_path": "pbp_drake.core.toy_scene",
        "collision_ratio": "pbp_drake.core.toy_scene",
        "scene_scenario": "pbp_drake.studies.toy",
        "phase_progress": "pbp_drake.studies.toy",
        "run_study": "pbp_drake.studies.toy",
    },
    "Studies and the console": {
        "run_method_comparison": "pbp_drake.studies.comparison",
        "run_method_matrix": "pbp_drake.studies.comparison",
        "report": "pbp_drake.studies.report",
        "report_matrix": "pbp_drake.studies.matrix_report",
        "load_task_result": "pbp_drake.studies.trial_files",
        "interaction_metrics": "pbp_drake.core.interaction_metrics",
        "InteractionMetrics": "pbp_drake.core.interaction_metrics",
        "Console": "pbp_drake.console",
        "LiveRun": "pbp_drake.console",
        "PageFront": "pbp_drake.console",
    },
}
_PUBLIC = {name: module for group in API_GROUPS.values() for name, module in group.items()}
__all__ = ["__version__", *_PUBLIC]


def __getattr__(name):
    if name in _PUBLIC:
        module = importlib.import_module(_PUBLIC[name])
        try:
            return getattr(module, name)
        except AttributeError:  # a public submodule (`quaternion`)
            return importlib.import_module(f"{module.__name__}.{name}")
    raise AttributeError(f"module 'pbp_drake' has no attribute {name!r}")


def __dir__():
    return sorted([*globals(), *_PUBLIC])
