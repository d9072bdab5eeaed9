"""Scenario files: the schema (`schema`), reading them (`loading`), the checks of their text,
shape and numbers (`validation`) and resolving them (`resolution`: everything checked and
derived once by `resolve`), and the words a person reads about runs (`words`: each method's
name, counts).

Data goes through once: YAML -> `ScenarioFile` -> `resolve` -> `ResolvedScenario` ->
`pbp_drake.builder.build_diagram`.
"""

from pbp_drake.scenarios.loading import (
    LoadedScenarioFile, check_alpha_study, check_method_comparison, load_scenario_file)
from pbp_drake.core.methods import METHODS
from pbp_drake.scenarios.resolution import (
    ResolvedScenario, TaskScene, demonstration_samples,
    parse_method_label, resolve, task_scene, with_method)
from pbp_drake.scenarios.schema import (
    HSR_OPERATORS, OPERATOR_NAMES, TASK_ROBOTS, TOY_OPERATORS,
    AlphaStudy, AltVsCont, Arm, BentPath, DynamicObstacles, Gamepad, GraspTask, Hsr, Keyboard, MethodComparison,
    MultiGoalReach, NoOperator, Obstacle, ObstacleRepulsion, OperatorConfig, PointRobot,
    RecordedPath, Scenario, ScenarioError, ScenarioFile, SceneVariant, ScriptedCommands,
    SinusoidalStep, VirtualParticipant, forward_key_enabled, shows_intent, NoisyPilot,
    LaggyPilot, ProportionalPilot, ParticipantPopulation, PILOT_CONFIGS)
from pbp_drake.scenarios.words import METHOD_NAMES, counted
from pbp_drake.scenarios.pilots import PILOT_NAMES, PILOTS, check_pilot_name, with_pilot

__all__ = [
    "HSR_OPERATORS", "METHOD_NAMES", "METHODS",
    "OPERATOR_NAMES", "TASK_ROBOTS", "TOY_OPERATORS", "AlphaStudy", "AltVsCont", "Arm",
    "BentPath",
    "DynamicObstacles", "Gamepad", "GraspTask", "Hsr", "Keyboard", "LoadedScenarioFile",
    "MethodComparison", "MultiGoalReach",
    "NoOperator", "Obstacle", "ObstacleRepulsion", "OperatorConfig", "PointRobot",
    "RecordedPath", "ResolvedScenario", "Scenario", "ScenarioError", "ScenarioFile",
    "SceneVariant", "ScriptedCommands", "SinusoidalStep", "TaskScene", "VirtualParticipant",
    "NoisyPilot", "LaggyPilot", "ProportionalPilot", "ParticipantPopulation", "PILOT_CONFIGS",
    "PILOT_NAMES", "PILOTS", "check_pilot_name", "with_pilot",
    "check_alpha_study", "check_method_comparison", "counted", "demonstration_samples",
    "forward_key_enabled", "load_scenario_file", "parse_method_label", "resolve", "shows_intent", "task_scene", "with_method",
]
