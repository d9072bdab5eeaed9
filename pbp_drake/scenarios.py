"""Scenario files: dataclasses read from YAML with `pydrake.common.yaml.yaml_load_typed`.

A scenario file holds one `scenario` (everything one simulation needs: robot, method,
operator, goals, demonstration, obstacles, rates) and optionally a `study` that varies it.
Variants are chosen with YAML tags, e.g. ``operator: !ObstacleRepulsion {speed: 1.0}``.
Unknown or misspelled keys are errors that name the key; `validate_scenario` checks values.
"""

import dataclasses
import difflib
import math
import pathlib
import typing

import numpy as np
from pydrake.common.yaml import yaml_load_typed

METHODS = ("pbp_alternated", "pbp_continuous", "fixed_alpha", "confidence_alpha", "teleop",
           "pbp_no_user")


class ScenarioError(ValueError):
    """A scenario file or value that cannot be used; the message names the field."""


@dataclasses.dataclass
class Obstacle:
    """A disc (sphere in 3-D) the robot must not enter."""

    center: list[float] = dataclasses.field(default_factory=list)
    radius: float = 0.1


@dataclasses.dataclass
class PointRobot:
    """The toy robot: a point mass-spring-damper tracking the commanded reference."""

    mass: float = 1.0
    stiffness: float = 400.0
    damping: float = 40.0
    time_step: float = 0.001


@dataclasses.dataclass
class DmpOptions:
    """DMP formulation and gains (see `pbp_drake.core.dmp.DmpSettings`)."""

    formulation: str = "ijspeert"
    basis_count: int = 50
    alpha_z: float = 25.0
    alpha_x: float = math.log(100.0)
    # The DMP's duration tau; 0 takes the demonstration's duration.
    duration: float = 0.0


@dataclasses.dataclass
class BentPath:
    """A demonstration from `start` to `goal` that bows sideways by `bend` at mid-path."""

    start: list[float] = dataclasses.field(default_factory=list)
    goal: list[float] = dataclasses.field(default_factory=list)
    bend: float = 0.0
    duration: float = 1.0
    sample_count: int = 200


@dataclasses.dataclass
class RecordedPath:
    """A demonstration given sample by sample."""

    times: list[float] = dataclasses.field(default_factory=list)
    positions: list[list[float]] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class NoOperator:
    """No operator input at all (u = 0)."""


@dataclasses.dataclass
class ObstacleRepulsion:
    """The paper's virtual human: `speed` away from the nearest obstacle when closer than
    `distance_threshold`; along `axis` only when one is given (empty: radially)."""

    distance_threshold: float = 0.2
    speed: float = 1.0
    axis: list[float] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class SinusoidalStep:
    """Open-loop input along `axis`: `amplitude * sin(2 pi (t - start_time) / period)` for
    `start_time <= t < start_time + duration`, then it stops at once (Fig. 4's input)."""

    axis: list[float] = dataclasses.field(default_factory=list)
    amplitude: float = 1.0
    start_time: float = 0.2
    duration: float = 0.4
    period: float = 1.6


@dataclasses.dataclass
class ScriptedCommands:
    """Commands `(T, D)` held from each of `times` until the next."""

    times: list[float] = dataclasses.field(default_factory=list)
    commands: list[list[float]] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class Keyboard:
    """A person at the browser's keyboard (HSR tasks): arrows move the end effector (forward
    only in teleop), Q and E turn it. `speed` 0 takes the DMPs' nominal speed."""

    speed: float = 0.0
    rotation_speed: float = 0.6
    # A key counts as held this long after its last press. The browser repeats a held key,
    # but only after the system's repeat delay (often 0.25..0.66 s): bridge it.
    hold_time: float = 0.6


@dataclasses.dataclass
class Gamepad:
    """A person with a gamepad in the browser (HSR tasks): left stick moves, right stick
    turns. `speed` 0 takes the DMPs' nominal speed."""

    speed: float = 0.0
    rotation_speed: float = 0.6
    dead_zone: float = 0.15


@dataclasses.dataclass
class VirtualParticipant:
    """The stand-in for the paper's participants (HSR tasks): sees the true target; in PBP
    it turns and sidesteps only until the estimated goal is the target, in teleop it drives
    the whole way. `speed` 0 takes the DMPs' nominal speed. Noise comes from the scenario's
    seed."""

    speed: float = 0.0
    rotation_speed: float = 0.8
    reaction_delay: float = 0.3
    direction_noise: float = 0.1
    speed_noise: float = 0.1


OperatorConfig = typing.Union[NoOperator, ObstacleRepulsion, SinusoidalStep, ScriptedCommands,
                              Keyboard, Gamepad, VirtualParticipant]
HSR_OPERATORS = (NoOperator, Keyboard, Gamepad, VirtualParticipant)
TOY_OPERATORS = (NoOperator, ObstacleRepulsion, SinusoidalStep, ScriptedCommands)
# The names `pbp-drake run --operator` takes for the HSR tasks.
OPERATOR_NAMES = {"keyboard": Keyboard, "gamepad": Gamepad, "virtual": VirtualParticipant,
                  "none": NoOperator}


@dataclasses.dataclass
class Hsr:
    """The simulated Toyota HSR (our primitive-shape model) under whole-body differential IK;
    the PBP loop commands its end effector in task space."""

    time_step: float = 0.005
    # The whole-body differential IK's period (s), a whole multiple of time_step. Its QP is
    # the loop's largest cost: 0.01 runs the reaching task about 11x real time, 0.005 about
    # 9.5x, with the same success (30 of 30 for teleop and PBP-Alt); at 0.015 the teleop
    # participant failed 3 of 30 reaches.
    diff_ik_time_step: float = 0.01
    # The DMPs' nominal speed (m/s): their duration is the farthest goal's distance over it.
    speed: float = 0.12


@dataclasses.dataclass
class MultiGoalReach:
    """The paper's multi-goal reaching task (section IV-B.1): objects drawn from the seed in
    a rectangle in front of the robot at one height; the target switches to another object
    at each progress threshold of `switch_schedule` after the first (0 %)."""

    object_count: list[int] = dataclasses.field(default_factory=lambda: [2, 4])
    x_range: list[float] = dataclasses.field(default_factory=lambda: [1.25, 2.5])
    y_range: list[float] = dataclasses.field(default_factory=lambda: [-1.05, 1.05])
    height: float = 0.7
    min_separation: float = 0.2
    switch_schedule: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.3, 0.6])
    success_distance: float = 0.05
    # Fixed objects `(M, 3)` and targets (object indices, one per schedule entry) instead of
    # drawing them from the seed.
    objects: list[list[float]] = dataclasses.field(default_factory=list)
    targets: list[int] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class DynamicObstacles:
    """The paper's obstacle task (section IV-B.2): one target drawn from the seed; cylinder
    obstacles start still at random places and, once the progress passes each one's
    threshold (drawn in `activation_range`), move at `obstacle_speed` to the midpoint of the
    line from the hand to the target. Collisions are measured on the HSR's collision
    geometry and do not push the robot."""

    x_range: list[float] = dataclasses.field(default_factory=lambda: [1.25, 2.5])
    y_range: list[float] = dataclasses.field(default_factory=lambda: [-1.05, 1.05])
    height: float = 0.7
    success_distance: float = 0.05
    obstacle_count: int = 3
    obstacle_radius: float = 0.12
    obstacle_height: float = 1.2
    obstacle_speed: float = 0.15
    obstacle_x_range: list[float] = dataclasses.field(default_factory=lambda: [0.9, 2.6])
    obstacle_y_range: list[float] = dataclasses.field(default_factory=lambda: [-1.3, 1.3])
    activation_range: list[float] = dataclasses.field(default_factory=lambda: [0.05, 0.5])


@dataclasses.dataclass
class GoalEstimatorOptions:
    """Which goal the operator intends (see `pbp_drake.core.goal_estimation`)."""

    # angle (the paper's heuristic), nearest or bayesian.
    method: str = "angle"
    # Softmax temperature (rad for angle, m for nearest): low enough that objects a few
    # degrees apart are told apart.
    temperature: float = 0.1
    beta: float = 5.0
    # Hysteresis: a challenger must beat the selection by `margin` for `hold_steps` updates.
    margin: float = 0.1
    hold_steps: int = 2


@dataclasses.dataclass
class Scenario:
    """Everything one simulation needs."""

    name: str = "scenario"
    # One of METHODS.
    method: str = "pbp_alternated"
    # The arbitration weight of `fixed_alpha`, in [0, 1].
    alpha: float = 0.5
    control_period: float = 0.01
    duration: float = 2.0
    robot: typing.Union[PointRobot, Hsr] = dataclasses.field(default_factory=PointRobot)
    # The robot's initial position; empty: the demonstration's start.
    start: list[float] = dataclasses.field(default_factory=list)
    # Candidate goals, one DMP each; empty: the demonstration's goal.
    goals: list[list[float]] = dataclasses.field(default_factory=list)
    # The demonstration the DMPs learn from; none: straight paths.
    demonstration: typing.Optional[typing.Union[BentPath, RecordedPath]] = None
    dmp: DmpOptions = dataclasses.field(default_factory=DmpOptions)
    obstacles: list[Obstacle] = dataclasses.field(default_factory=list)
    operator: OperatorConfig = dataclasses.field(default_factory=NoOperator)
    # HSR tasks: the task, the goal estimator, and the seed every random draw comes from.
    # An untagged task is a MultiGoalReach; `!DynamicObstacles {...}` the obstacle task.
    task: typing.Optional[typing.Union[MultiGoalReach, DynamicObstacles]] = None
    goal_estimator: GoalEstimatorOptions = dataclasses.field(
        default_factory=GoalEstimatorOptions)
    seed: int = 0


@dataclasses.dataclass
class SceneVariant:
    """A test scene of the alpha study: the scenario with its obstacles replaced."""

    name: str = ""
    obstacles: list[Obstacle] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class AlphaStudy:
    """Explicit arbitration over `alphas` against PBP, in each scene (Fig. 2)."""

    # Where the obstacles stood when the demonstration was given (drawn in panel a).
    demonstration_obstacles: list[Obstacle] = dataclasses.field(default_factory=list)
    scenes: list[SceneVariant] = dataclasses.field(default_factory=list)
    alphas: list[float] = dataclasses.field(
        default_factory=lambda: [round(0.1 * i, 1) for i in range(11)])


@dataclasses.dataclass
class AltVsCont:
    """The same DMP and open-loop input in continuous and alternated mode (Fig. 4)."""

    # Both modes must end this close to the goal.
    goal_tolerance: float = 0.01


@dataclasses.dataclass
class MethodComparison:
    """The same seeded scenes for each method (trial i uses seed `seed + i`), driven by the
    scenario's operator; `pbp-drake study --methods --trials --seed` override these."""

    methods: list[str] = dataclasses.field(
        default_factory=lambda: ["pbp_alternated", "pbp_continuous", "teleop"])
    trials: int = 10
    seed: int = 0


@dataclasses.dataclass
class ScenarioFile:
    """The top level of a file in `diagrams/`."""

    scenario: Scenario = dataclasses.field(default_factory=Scenario)
    study: typing.Optional[typing.Union[AlphaStudy, AltVsCont, MethodComparison]] = None


def load_scenario_file(path):
    """Reads and validates a scenario file; errors name the file and the field."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: no such scenario file")
    try:
        loaded = yaml_load_typed(schema=ScenarioFile, filename=str(path))
    except RuntimeError as error:
        raise ScenarioError(f"{path}: {error}{_suggestion(str(error))}") from None
    try:
        validate_scenario(loaded.scenario)
        if isinstance(loaded.study, AlphaStudy):
            _validate_alpha_study(loaded.study, loaded.scenario)
        if isinstance(loaded.study, MethodComparison):
            validate_method_comparison(loaded.study, loaded.scenario)
    except ScenarioError as error:
        raise ScenarioError(f"{path}: {error}") from None
    return loaded


def demonstration_samples(demonstration):
    """Times `(T,)` and positions `(T, D)` of a demonstration config."""
    from pbp_drake.core.toy_scene import bent_path

    if isinstance(demonstration, BentPath):
        return bent_path(demonstration.start, demonstration.goal, demonstration.bend,
                         demonstration.duration, demonstration.sample_count)
    return (np.asarray(demonstration.times, float),
            np.asarray(demonstration.positions, float))


def resolved_start(scenario):
    if scenario.start:
        return np.asarray(scenario.start, float)
    return demonstration_samples(scenario.demonstration)[1][0]


def resolved_goals(scenario):
    """Goals `(K, D)`."""
    if scenario.goals:
        return np.asarray(scenario.goals, float).reshape(len(scenario.goals), -1)
    return demonstration_samples(scenario.demonstration)[1][-1][np.newaxis, :]


def validate_scenario(scenario):
    """Raises ScenarioError naming the first field whose value cannot be used."""
    from pbp_drake.core.dmp import validate_demonstration

    if scenario.method not in METHODS:
        raise ScenarioError(
            f"scenario.method {scenario.method!r} is unknown; choose one of {METHODS}"
            f"{_close(scenario.method, METHODS)}")
    if not (np.isfinite(scenario.alpha) and 0.0 <= scenario.alpha <= 1.0):
        raise ScenarioError(f"scenario.alpha = {scenario.alpha} is outside [0, 1]")
    for name in ("control_period", "duration"):
        if not getattr(scenario, name) > 0:
            raise ScenarioError(f"scenario.{name} must be positive")
    steps = scenario.control_period / scenario.robot.time_step
    if abs(steps - round(steps)) > 1e-9 or round(steps) < 1:
        raise ScenarioError(
            "scenario.control_period must be a whole multiple of scenario.robot.time_step")
    if isinstance(scenario.robot, Hsr):
        _validate_hsr_scenario(scenario)
        return
    if scenario.task is not None or not isinstance(scenario.operator, TOY_OPERATORS):
        raise ScenarioError(
            f"scenario.task and operator !{type(scenario.operator).__name__} need "
            "robot: !Hsr {...}")
    if scenario.demonstration is not None:
        try:
            validate_demonstration(*demonstration_samples(scenario.demonstration))
        except ValueError as error:
            raise ScenarioError(f"scenario.demonstration: {error}") from None
    elif not scenario.start or not scenario.goals:
        raise ScenarioError(
            "scenario.start and scenario.goals are needed when there is no demonstration")
    start = resolved_start(scenario)
    goals = resolved_goals(scenario)
    if goals.shape[1] != start.size:
        raise ScenarioError(
            f"scenario.goals have dimension {goals.shape[1]}, scenario.start has {start.size}")
    if not (np.isfinite(goals).all() and np.isfinite(start).all()):
        raise ScenarioError("scenario.goals and scenario.start must be finite")
    if scenario.method == "confidence_alpha":
        raise ScenarioError("scenario.method confidence_alpha needs a goal estimator's "
                            "confidence: use it in the HSR tasks (robot: !Hsr)")
    if scenario.method == "fixed_alpha" and scenario.demonstration is None:
        raise ScenarioError(
            "scenario.method fixed_alpha plays the demonstration as P: give "
            "scenario.demonstration")
    if scenario.method == "fixed_alpha" and goals.shape[0] != 1:
        raise ScenarioError("scenario.method fixed_alpha takes exactly one goal here")
    if scenario.dmp.duration <= 0 and scenario.demonstration is None:
        raise ScenarioError("scenario.dmp.duration is needed when there is no demonstration")
    try:
        dmp_settings(scenario.dmp)
    except ValueError as error:
        raise ScenarioError(f"scenario.dmp: {error}") from None
    for index, obstacle in enumerate(scenario.obstacles):
        if len(obstacle.center) != start.size or not obstacle.radius > 0:
            raise ScenarioError(
                f"scenario.obstacles[{index}] needs a center of dimension {start.size} and a "
                "positive radius")
    _validate_operator(scenario.operator, start.size)


def _validate_hsr_scenario(scenario):
    if scenario.task is None:
        raise ScenarioError("robot !Hsr needs scenario.task, e.g. task: {object_count: [2, 4]}")
    if not isinstance(scenario.operator, HSR_OPERATORS):
        raise ScenarioError(
            f"scenario.operator !{type(scenario.operator).__name__} drives the 2-D toy robot; "
            f"the HSR takes one of {[c.__name__ for c in HSR_OPERATORS]}")
    if scenario.demonstration is not None or scenario.goals or scenario.start:
        raise ScenarioError("the HSR task draws its own goals (the objects) and starts "
                            "where the robot stands: remove scenario.demonstration, goals "
                            "and start")
    if not scenario.robot.speed > 0:
        raise ScenarioError("scenario.robot.speed must be positive")
    ratio = scenario.robot.diff_ik_time_step / scenario.robot.time_step
    if not (ratio >= 1 - 1e-9 and abs(ratio - round(ratio)) < 1e-9):
        raise ScenarioError("scenario.robot.diff_ik_time_step must be a whole multiple of "
                            "scenario.robot.time_step")
    task = scenario.task
    if isinstance(task, DynamicObstacles):
        _validate_obstacle_task(scenario)
    else:
        if not (0 < task.success_distance and 0 < task.min_separation):
            raise ScenarioError("scenario.task.success_distance and min_separation must be "
                                "positive")
        schedule = np.asarray(task.switch_schedule, float)
        if (len(schedule) == 0 or schedule[0] != 0.0 or np.any(np.diff(schedule) <= 0)
                or schedule[-1] >= 1.0):
            raise ScenarioError(f"scenario.task.switch_schedule {task.switch_schedule} must "
                                "start at 0.0 and increase strictly below 1.0")
    try:
        task_layout(scenario)
    except ValueError as error:
        raise ScenarioError(f"scenario.task: {error}") from None
    try:
        goal_estimator_settings(scenario.goal_estimator)
    except ValueError as error:
        raise ScenarioError(f"scenario.goal_estimator: {error}") from None
    try:
        dmp_settings(scenario.dmp)
    except ValueError as error:
        raise ScenarioError(f"scenario.dmp: {error}") from None
    operator = scenario.operator
    for name in ("speed", "rotation_speed", "hold_time", "dead_zone", "reaction_delay",
                 "direction_noise", "speed_noise"):
        value = getattr(operator, name, 0.0)
        if not (np.isfinite(value) and value >= 0):
            raise ScenarioError(f"scenario.operator.{name} must be finite and not negative")


def _validate_obstacle_task(scenario):
    task = scenario.task
    for name in ("success_distance", "obstacle_radius", "obstacle_height", "obstacle_speed"):
        if not (np.isfinite(getattr(task, name)) and getattr(task, name) > 0):
            raise ScenarioError(f"scenario.task.{name} must be positive")
    if task.obstacle_count < 0:
        raise ScenarioError("scenario.task.obstacle_count must not be negative")
    for name in ("x_range", "y_range", "obstacle_x_range", "obstacle_y_range",
                 "activation_range"):
        low_high = getattr(task, name)
        if len(low_high) != 2 or not low_high[0] <= low_high[1]:
            raise ScenarioError(f"scenario.task.{name} must be [low, high], got {low_high}")
    if not 0.0 <= task.activation_range[0] <= task.activation_range[1] <= 1.0:
        raise ScenarioError("scenario.task.activation_range must lie in [0, 1]")


@dataclasses.dataclass(frozen=True)
class TaskLayout:
    """What an HSR task puts in front of the robot: the goals `(K, 3)` (one DMP each), the
    target sequence and its switch schedule, and the obstacles (None without)."""

    objects: np.ndarray
    targets: tuple
    switch_schedule: tuple
    obstacles: typing.Any = None


def task_layout(scenario):
    """The goals, targets and obstacles of an HSR task, drawn from the seed when asked."""
    from pbp_drake.core.obstacle_task import sample_obstacle_scene

    task = scenario.task
    if isinstance(task, DynamicObstacles):
        _validate_region(task)
        obstacles = sample_obstacle_scene(
            scenario.seed, tuple(task.x_range), tuple(task.y_range), task.height,
            task.obstacle_count, tuple(task.obstacle_x_range), tuple(task.obstacle_y_range),
            tuple(task.activation_range))
        return TaskLayout(objects=obstacles.target[np.newaxis, :], targets=(0,),
                          switch_schedule=(0.0,), obstacles=obstacles)
    scene = reach_scene(scenario)
    return TaskLayout(objects=scene.objects, targets=scene.targets,
                      switch_schedule=tuple(task.switch_schedule))


def reach_scene(scenario):
    """The objects and target sequence of an HSR task: given, or drawn from the seed."""
    from pbp_drake.core.reach_task import ReachScene, sample_reach_scene, validate_objects

    task = scenario.task
    if task.objects:
        objects = validate_objects(task.objects, task.min_separation)
        targets = tuple(int(t) for t in task.targets)
        if len(task.switch_schedule) > 1 and len(objects) < 2:
            raise ValueError("target switching needs at least 2 objects: add objects or set "
                             "switch_schedule to [0.0]")
        if len(targets) != len(task.switch_schedule):
            raise ValueError(f"targets {list(targets)} needs one object index per entry of "
                             f"switch_schedule {task.switch_schedule}")
        if any(not 0 <= t < len(objects) for t in targets):
            raise ValueError(f"targets {list(targets)} name objects that do not exist "
                             f"({len(objects)} objects)")
        if any(a == b for a, b in zip(targets, targets[1:])):
            raise ValueError(f"targets {list(targets)}: each switch must go to a different "
                             "object")
        return ReachScene(objects=objects, targets=targets)
    if task.targets:
        raise ValueError("targets are given without objects")
    _validate_region(task)
    return sample_reach_scene(scenario.seed, tuple(task.object_count), tuple(task.x_range),
                              tuple(task.y_range), task.height, tuple(task.switch_schedule),
                              task.min_separation)


def _validate_region(task):
    """Every corner of the region the task draws its targets from must be in reach."""
    from pbp_drake.core.reach_task import validate_objects

    if len(task.x_range) != 2 or len(task.y_range) != 2:
        raise ValueError("x_range and y_range must be [low, high]")
    validate_objects([[x, y, task.height] for x in task.x_range for y in task.y_range], 0.0)


def goal_estimator_settings(options):
    from pbp_drake.core.goal_estimation import GoalEstimatorSettings

    return GoalEstimatorSettings(
        method=options.method, temperature=options.temperature, beta=options.beta,
        margin=options.margin, hold_steps=options.hold_steps)


def dmp_settings(options):
    from pbp_drake.core.dmp import DmpSettings

    return DmpSettings(formulation=options.formulation, basis_count=options.basis_count,
                       alpha_z=options.alpha_z, alpha_x=options.alpha_x)


def _validate_operator(operator, dimension):
    if isinstance(operator, ObstacleRepulsion):
        if operator.axis and (len(operator.axis) != dimension or not np.any(operator.axis)):
            raise ScenarioError(
                f"scenario.operator.axis must be a nonzero vector of dimension {dimension}")
        if not np.isfinite(operator.speed) or not operator.distance_threshold > 0:
            raise ScenarioError("scenario.operator.speed must be finite and "
                                "distance_threshold positive")
    elif isinstance(operator, SinusoidalStep):
        if len(operator.axis) != dimension:
            raise ScenarioError(f"scenario.operator.axis must have dimension {dimension}")
        if not (np.isfinite(operator.amplitude) and operator.duration > 0 and operator.period > 0):
            raise ScenarioError("scenario.operator.amplitude must be finite, duration and "
                                "period positive")
    elif isinstance(operator, ScriptedCommands):
        commands = np.asarray(operator.commands, float)
        if commands.ndim != 2 or commands.shape != (len(operator.times), dimension):
            raise ScenarioError(
                f"scenario.operator.commands must be one command of dimension {dimension} "
                "per time")
        if not np.isfinite(commands).all():
            raise ScenarioError("scenario.operator.commands contain NaN or infinite values")


def _validate_alpha_study(study, scenario):
    if not study.scenes:
        raise ScenarioError("study.scenes is empty")
    if not study.alphas:
        raise ScenarioError("study.alphas is empty")
    for alpha in study.alphas:
        if not (np.isfinite(alpha) and 0.0 <= alpha <= 1.0):
            raise ScenarioError(f"study.alphas has {alpha}, outside [0, 1]")
    if scenario.demonstration is None:
        raise ScenarioError("the alpha study needs scenario.demonstration")


def parse_method_label(label):
    """`(name, alpha)` of a method label: a name of METHODS (alpha None), or `fixed_alpha=A`
    for explicit arbitration with weight A (so that one study can sweep alpha)."""
    name, _, alpha = label.partition("=")
    if name not in METHODS:
        raise ScenarioError(f"method {label!r} is unknown; choose from {METHODS} or "
                            f"fixed_alpha=A{_close(name, METHODS)}")
    if not alpha:
        return name, None
    if name != "fixed_alpha":
        raise ScenarioError(f"method {label!r}: only fixed_alpha takes a weight (=A)")
    try:
        value = float(alpha)
    except ValueError:
        value = math.nan
    if not (np.isfinite(value) and 0.0 <= value <= 1.0):
        raise ScenarioError(f"method {label!r}: alpha must be a number in [0, 1]")
    return name, value


def with_method(scenario, label):
    """The scenario run by the method `label` (see `parse_method_label`)."""
    name, alpha = parse_method_label(label)
    if alpha is None:
        return dataclasses.replace(scenario, method=name)
    return dataclasses.replace(scenario, method=name, alpha=alpha)


def validate_method_comparison(study, scenario):
    if not isinstance(scenario.robot, Hsr):
        raise ScenarioError("study !MethodComparison runs HSR tasks: use robot: !Hsr")
    if not study.methods:
        raise ScenarioError("study.methods is empty")
    for method in study.methods:
        try:
            with_method(scenario, method)
        except ScenarioError as error:
            raise ScenarioError(f"study.methods: {error}") from None
    if study.trials < 1:
        raise ScenarioError(f"study.trials must be at least 1, got {study.trials}")
    if isinstance(scenario.operator, (Keyboard, Gamepad)):
        raise ScenarioError("a study runs unattended: use operator: !VirtualParticipant {}")


def _all_field_names(schema=ScenarioFile, seen=None):
    seen = set() if seen is None else seen
    names = set()
    for cls in [schema]:
        if not dataclasses.is_dataclass(cls) or cls in seen:
            continue
        seen.add(cls)
        for field in dataclasses.fields(cls):
            names.add(field.name)
            for inner in _dataclasses_in(field.type):
                names |= _all_field_names(inner, seen)
    return names


def _dataclasses_in(annotation):
    if dataclasses.is_dataclass(annotation):
        return [annotation]
    return [inner for arg in typing.get_args(annotation) for inner in _dataclasses_in(arg)]


def _suggestion(message):
    """`did you mean` for Drake's "The fields ['sped'] were unknown" messages."""
    start, end = message.find("["), message.find("]")
    if start < 0 or end < start:
        return ""
    unknown = [name.strip(" '\"") for name in message[start + 1:end].split(",")]
    known = _all_field_names()
    return "".join(_close(name, known) for name in unknown)


def _close(name, choices):
    matches = difflib.get_close_matches(name, list(choices), n=1)
    return f" (did you mean {matches[0]!r}?)" if matches else ""
