"""Scenario files: the schema (`schema`), reading them (`loading`, within the bounds of
`bounds`), the checks of their numbers (`validation`), resolving them (`resolution`:
everything checked and derived once by `resolve`; the tasks' scenes in `task_scenes`), the
surrogate pilots (`pilots`) and the words a person reads about runs (`words`).

Data goes through once: YAML -> `ScenarioFile` (its scenario a `PointScenario` or a
`TaskScenario`) -> `resolve` -> `ResolvedScenario` ->
`pbp_drake.builder.build_diagram`.
"""

from pbp_drake.scenarios.loading import (
    LoadedScenarioFile, check_alpha_study, check_method_comparison, load_scenario_file,
    load_scenario_text)
from pbp_drake.core.methods import METHODS
from pbp_drake.scenarios.overrides import ScenarioOverrides
from pbp_drake.scenarios.resolution import (
    ResolvedScenario, TaskScene, demonstration_samples,
    parse_method_label, resolve, task_scene, with_method)
from pbp_drake.scenarios.schema import (
    HSR_OPERATORS, OPERATOR_NAMES, PILOT_CONFIGS, TASK_ROBOTS,
    TOY_OPERATORS, AlphaStudy, AltVsCont, Arm, BentPath, DynamicObstacles, Gamepad, GraspTask,
    Hsr, Keyboard, LaggyPilot, MethodComparison, MultiGoalReach, NoisyPilot, NoOperator,
    Obstacle, ObstacleRepulsion, ParticipantPopulation, PointRobot, PointScenario,
    ProportionalPilot, RecordedPath, Scenario, ScenarioError, ScenarioFile, SceneVariant,
    ScriptedCommands, SinusoidalStep, TaskScenario, TaskScenarioFile, VirtualParticipant,
    forward_key_enabled, shows_intent)
from pbp_drake.scenarios.words import METHOD_NAMES, counted
from pbp_drake.scenarios.pilots import PILOT_NAMES, PILOTS, check_pilot_name, with_pilot

__all__ = [
    "HSR_OPERATORS", "METHOD_NAMES", "METHODS",
    "OPERATOR_NAMES", "PILOT_CONFIGS", "PILOT_NAMES", "PILOTS", "TASK_ROBOTS", "TOY_OPERATORS",
    "AlphaStudy", "AltVsCont", "Arm", "BentPath", "DynamicObstacles", "Gamepad", "GraspTask",
    "Hsr", "Keyboard", "LaggyPilot", "LoadedScenarioFile", "MethodComparison",
    "MultiGoalReach", "NoisyPilot", "NoOperator", "Obstacle", "ObstacleRepulsion",
    "ParticipantPopulation", "PointRobot", "PointScenario", "ProportionalPilot",
    "RecordedPath", "ResolvedScenario", "Scenario", "ScenarioError", "ScenarioFile",
    "ScenarioOverrides",
    "SceneVariant", "ScriptedCommands", "SinusoidalStep", "TaskScenario", "TaskScenarioFile",
    "TaskScene", "VirtualParticipant",
    "check_alpha_study", "check_method_comparison", "check_pilot_name", "counted",
    "demonstration_samples", "forward_key_enabled", "load_scenario_file", "load_scenario_text",
    "parse_method_label", "resolve", "shows_intent", "task_scene",
    "with_method", "with_pilot",
]
