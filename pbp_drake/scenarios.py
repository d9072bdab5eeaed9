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

METHODS = ("pbp_alternated", "pbp_continuous", "fixed_alpha", "teleop", "pbp_no_user")


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


OperatorConfig = typing.Union[NoOperator, ObstacleRepulsion, SinusoidalStep, ScriptedCommands]


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
    robot: PointRobot = dataclasses.field(default_factory=PointRobot)
    # The robot's initial position; empty: the demonstration's start.
    start: list[float] = dataclasses.field(default_factory=list)
    # Candidate goals, one DMP each; empty: the demonstration's goal.
    goals: list[list[float]] = dataclasses.field(default_factory=list)
    # The demonstration the DMPs learn from; none: straight paths.
    demonstration: typing.Optional[typing.Union[BentPath, RecordedPath]] = None
    dmp: DmpOptions = dataclasses.field(default_factory=DmpOptions)
    obstacles: list[Obstacle] = dataclasses.field(default_factory=list)
    operator: OperatorConfig = dataclasses.field(default_factory=NoOperator)


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
class ScenarioFile:
    """The top level of a file in `diagrams/`."""

    scenario: Scenario = dataclasses.field(default_factory=Scenario)
    study: typing.Optional[typing.Union[AlphaStudy, AltVsCont]] = None


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
