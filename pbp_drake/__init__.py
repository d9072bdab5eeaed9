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
        **{name: "pbp_drake.core.dmp" for name in [
            "Dmp", "DmpBankModel", "DmpSettings", "minimum_jerk"]},
        **{name: "pbp_drake.core.dmp.primitive" for name in [
            "Primitive", "teach_primitive", "primitive_bank", "primitive_orientation_bank",
            "primitive_document", "read_primitive_document"]},
        **{name: "pbp_drake.core.dmp" for name in ["OrientationDmp", "OrientationDmpBank"]},
        "GoalEstimatorSettings": "pbp_drake.core.goal_estimation",
        "quaternion": "pbp_drake.core",
        **{name: "pbp_drake.core.pose_arbitration" for name in [
            "HandOverLimits", "PoseReference", "blend_pose", "pose_hand_over"]},
        "VirtualParticipantParams": "pbp_drake.core.participant_params",
        "ParticipantImpairment": "pbp_drake.core.participant_impairment",
        "GraspParticipantParams": "pbp_drake.core.participant_grasp",
    },
    "Methods and goal estimators (registries)": {
        **{name: "pbp_drake.core.methods" for name in [
            "Method", "register_method", "forward_key_enabled"]},
        **{name: "pbp_drake.core.goal_estimation" for name in [
            "Estimator", "register_estimator"]},
        "IntentFilterSettings": "pbp_drake.core.intent_filter",
    },
    "Shared-autonomy baselines (HOP, predict-then-assist)": {
        **{name: "pbp_drake.core.hindsight_optimization" for name in [
            "HopSettings", "hop_targets", "update_posterior", "assisted_command"]},
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
        name: "pbp_drake.robots" for name in [
            "make_hsr_station", "HsrStationConfig", "add_hsr", "CylinderObstacle",
            "hsr_station_plant", "hsr_initial_ee_state", "hsr_initial_hand_pose",
            "hsr_ready_ee_state"]},
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
            "load_scenario_file", "ScenarioOverrides", "resolve", "ResolvedScenario",
            "ScenarioError", "ScenarioFile", "Scenario", "PointScenario", "TaskScenario",
            "Hsr", "Arm", "PointRobot", "MultiGoalReach",
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
        **{name: "pbp_drake.core.toy_scene" for name in ["bent_path", "collision_ratio"]},
        **{name: "pbp_drake.studies.toy" for name in [
            "scene_scenario", "phase_progress", "run_study"]},
    },
    "Studies and the console": {
        "run_method_comparison": "pbp_drake.studies.comparison",
        "run_method_matrix": "pbp_drake.studies.comparison",
        "report": "pbp_drake.studies.report",
        "report_matrix": "pbp_drake.studies.matrix_report",
        "load_task_result": "pbp_drake.studies.trial_files",
        "interaction_metrics": "pbp_drake.core.interaction_metrics",
        "InteractionMetrics": "pbp_drake.core.interaction_metrics",
        **{name: "pbp_drake.console" for name in ["Console", "LiveRun", "PageFront"]},
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
