"""Resolving a scenario: every value checked and everything derived, once.

`resolve(scenario)` turns the configs of a scenario file into a `ResolvedScenario`: the
robot's start, the goals, the demonstration's samples, the fitted DMP bank, the task's
scene (objects, targets, obstacles, drawn from the seed), the HSR station's config and
the blend mode. Validating is resolving: a value that cannot be used raises a
`ScenarioError` naming its field, and nothing downstream (the builder, the studies, the
CLI) derives any of these again.
"""

import contextlib
import copy
import dataclasses
import json
import math
import typing

import numpy as np

from pbp_drake.core.controller_config import PbpControllerConfig
from pbp_drake.core.coordinates import check_positions
from pbp_drake.core.dmp import DmpBankModel, validate_demonstration
from pbp_drake.core.dmp.primitive import SETTINGS_FIELDS, read_primitive_document
from pbp_drake.core.goal_estimation import (
    ESTIMATORS, READS_INTENT, READS_POSE, READS_POSITION, estimator_entry)
from pbp_drake.core.choices import did_you_mean
from pbp_drake.core.methods import METHODS, method_entry
from pbp_drake.core.toy_scene import bent_path
from pbp_drake.systems.operators.browser_input import check_params
from pbp_drake.systems.operators.obstacle_repulsion_operator import check_repulsion_params
from pbp_drake.systems.operators.scripted_operator import checked_script
from pbp_drake.robots import CylinderObstacle, hsr_ready_ee_state
from pbp_drake.robots.arm_station import arm_ready_ee_state_and_reach
from pbp_drake.robots.hsr_station import hsr_ready_palm_position
from pbp_drake.robots.model_geometry import check_clear_of_base
from pbp_drake.robots.task_space_bridge import validate_task_space_bridge
from pbp_drake.scenarios.bounds import check_goal_counts, is_special_file
from pbp_drake.scenarios.schema import (
    HSR_OPERATORS, RENAMED_METHODS, TOY_OPERATORS, Arm, BentPath, DynamicObstacles, Gamepad,
    GraspTask, Hsr, Keyboard, MultiGoalReach, ObstacleRepulsion, PointScenario, Scenario,
    ScenarioError, ScriptedCommands, PILOT_CONFIGS, ParticipantPopulation, ProportionalPilot,
    SinusoidalStep, TaskScenario, VirtualParticipant)
from pbp_drake.scenarios.task_scenes import TaskScene, scene_boxes, task_scene
from pbp_drake.scenarios.validation import (
    MAX_LIKELY_PATHS, check_bent_path, check_count, check_direction, check_dmp_duration,
    check_duration, check_grasp_task, check_numbers, check_obstacle_task, check_reach_task,
    check_seed, check_pilot, check_simulator, check_time_steps, check_virtual_participant,
    require_finite, whole_steps)


@dataclasses.dataclass(frozen=True)
class ResolvedScenario:
    """A scenario with everything derived from it (see `resolve`).

    Attributes:
        scenario: a copy of the configs it was resolved from, taken by `resolve`: a
            scenario changed after it was resolved (a field set, a list changed in place)
            changes neither this copy nor what was derived from it.
        start: (D,) where the robot (2-D scenes) or the hand (HSR) starts.
        goals: (K, D) the goals, one DMP each.
        demonstration: (times (T,), positions (T, D)) or None.
        dmp_bank: the 2-D scenes' fitted `pbp_drake.core.dmp.DmpBankModel` (read-only by
            convention); None in the tasks, whose controller fits its own from
            `controller` (`PbpControllerConfig.dmp_bank`).
        scene: the task's `TaskScene` (HSR and arm), None in 2-D scenes.
        station: the station's config, an `HsrStationConfig` (hand height and command
            period filled in from the task) or an `ArmStationConfig`; None in 2-D scenes.
        initial_ee_state: (8,) the hand's state at the start, None in 2-D scenes.
        controller: the tasks' `PbpControllerConfig` (what `make_pbp_controller` builds
            from), None in 2-D scenes.
    """

    scenario: Scenario
    start: np.ndarray
    goals: np.ndarray
    demonstration: typing.Optional[tuple]
    dmp_bank: typing.Optional[DmpBankModel]
    scene: typing.Optional[TaskScene] = None
    station: typing.Any = None
    initial_ee_state: typing.Optional[np.ndarray] = None
    controller: typing.Optional[PbpControllerConfig] = None

    @property
    def nominal_speed(self):
        """The DMPs' nominal speed (m/s) in the tasks (`controller.nominal_speed`), None in
        2-D scenes."""
        return self.controller and self.controller.nominal_speed

    @property
    def blend_mode(self):
        """The blender's mode of `scenario.method` (None for a method with no blender: HOP's
        assistance)."""
        return METHODS[self.scenario.method].blend_mode

    @property
    def has_task(self):
        """Whether a task robot (the HSR or an arm) runs a seeded task, not a 2-D scene."""
        return self.scene is not None

    @property
    def is_arm(self):
        return isinstance(self.scenario.robot, Arm)

    def with_method(self, label):
        """This scenario run by the method `label` (see `parse_method_label`); what does not
        depend on the method (the DMPs, the scene) is kept, not derived again."""
        scenario = with_method(self.scenario, label)
        _check_method(scenario, self.goals.shape[0])
        controller = self.controller and dataclasses.replace(
            self.controller, method=scenario.method, alpha=scenario.alpha)
        return dataclasses.replace(self, scenario=scenario, controller=controller)


def resolve(scenario):
    """Checks `scenario` and derives everything a build needs; see `ResolvedScenario`.

    Raises ScenarioError naming the first field whose value cannot be used.
    """
    if not isinstance(scenario, (PointScenario, TaskScenario)):
        raise ScenarioError(f"a scenario to resolve is a PointScenario or a TaskScenario, "
                            f"not {type(scenario).__name__}")
    # Its own copy: what is derived below and the configs a run reads later (its duration,
    # its period) must stay one scenario when the caller changes theirs in place.
    scenario = _own_copy(scenario)
    _check_operator(scenario)
    _check_common(scenario)
    if isinstance(scenario, TaskScenario):
        return _resolve_task_robot(scenario)
    return _resolve_point_robot(scenario)


def _own_copy(config):
    """A copy of `config` sharing no list or config with it: dataclasses and lists copied
    field by field, a NumPy array as the list of its values (as a file gives them), numbers
    and strings kept (immutable), anything else deep-copied (Drake's config structs).
    Faster than `copy.deepcopy` over a file's 100,000 goals."""
    if config is None or isinstance(config, (bool, int, float, str)):
        return config
    if isinstance(config, np.ndarray):
        return config.tolist()
    if type(config) in (list, tuple):
        return type(config)(_own_copy(item) for item in config)
    if dataclasses.is_dataclass(config) and not isinstance(config, type):
        copied = copy.copy(config)
        for field in dataclasses.fields(config):
            # object.__setattr__: a frozen dataclass's fields too.
            object.__setattr__(copied, field.name, _own_copy(getattr(config, field.name)))
        return copied
    return copy.deepcopy(config)


def parse_method_label(label):
    """`(name, alpha)` of a method label: a name of the methods registry (alpha None), or
    `fixed_alpha=A` for explicit arbitration with weight A (so that one study can sweep
    alpha)."""
    name, equals, alpha = label.partition("=")
    renamed_method(name)
    weighted = " or ".join(f"{m}=A" for m, method in METHODS.items() if method.takes_weight)
    if name not in METHODS:
        raise ScenarioError(f"method {label!r} is unknown; choose from {', '.join(METHODS)} or "
                            f"{weighted}{did_you_mean(name, METHODS)}")
    if not equals:
        return name, None
    if not METHODS[name].takes_weight:
        raise ScenarioError(f"method {label!r}: only {weighted} takes a weight")
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


def renamed_method(name, field="method"):
    """Raises ScenarioError when `name` is a method's old name (`RENAMED_METHODS`), naming
    the new one."""
    if name in RENAMED_METHODS:
        new, why = RENAMED_METHODS[name]
        raise ScenarioError(f"{field} {name!r} is now called {new!r} ({why})")


def _check_common(scenario):
    check_goal_counts(scenario)  # first: every check after it walks the goals
    check_numbers(scenario)
    renamed_method(scenario.method, "scenario.method")
    with _refused_as(""):
        method_entry(scenario.method, "scenario.method")
    with _refused_as("scenario."):
        scenario.validate_settings()
    require_finite(scenario, "scenario", ("duration",))
    estimator, grasping = scenario.goal_estimator.method, isinstance(
        getattr(scenario, "task", None), GraspTask)
    reads = estimator_entry(estimator).reads
    if reads == READS_POSE and not grasping:
        raise ScenarioError(f"scenario.goal_estimator.method {estimator} "
                            f"reads grasp orientations: use it with task: !GraspTask {{...}}")
    if reads == READS_POSITION and grasping:  # the grasp builder has no position form
        raise ScenarioError(f"scenario.goal_estimator.method {estimator} reads positions "
                            "alone; the grasping task takes one that reads grasp poses: "
                            + ", ".join(name for name, entry in ESTIMATORS.items()
                                        if entry.reads != READS_POSITION))
    check_time_steps([("scenario.control_period", scenario.control_period)])
    check_duration(scenario.duration, scenario.control_period)
    check_simulator(scenario.simulator)


def _check_operator(scenario):
    """The operator is one of the scenario type's (a file's walk checks it; a scenario
    made in Python is checked here)."""
    operators = TOY_OPERATORS if isinstance(scenario, PointScenario) else HSR_OPERATORS
    if not isinstance(scenario.operator, operators):
        raise ScenarioError(
            f"scenario.operator !{type(scenario.operator).__name__} does not drive a "
            f"{type(scenario).__name__}; expected one of "
            f"{', '.join('!' + cls.__name__ for cls in operators)}")


@contextlib.contextmanager
def _refused_as(prefix, config_name=None, field=None):
    """A ValueError raised inside becomes a ScenarioError: `prefix` before its message, and
    `config_name` in it (a config's name before its fields) said as `field`."""
    try:
        yield
    except ValueError as error:
        message = f"{prefix}{error}"
        raise ScenarioError(message.replace(config_name, field) if config_name else message
                            ) from None


def _with_period(scenario, period):
    """`scenario` run at `period` (itself when that is its control period)."""
    if period == scenario.control_period:
        return scenario
    return dataclasses.replace(scenario, control_period=period)


def _check_method(scenario, goal_count):
    """What the method asks of the rest of the scenario."""
    if isinstance(scenario, TaskScenario):
        return
    method = METHODS[scenario.method]
    if method.task_only:
        raise ScenarioError(f"scenario.method {method.name} {method.task_only}: use it in the "
                            "HSR tasks (robot: !Hsr)")
    if method.plays_demonstration and scenario.demonstration is None:
        raise ScenarioError(
            f"scenario.method {method.name} plays the demonstration as P: give "
            "scenario.demonstration")
    if method.plays_demonstration and goal_count != 1:
        raise ScenarioError(f"scenario.method {method.name} takes exactly one goal here")


def demonstration_samples(demonstration):
    """Times `(T,)` and positions `(T, D)` of a demonstration config."""
    if isinstance(demonstration, BentPath):
        return bent_path(demonstration.start, demonstration.goal, demonstration.bend,
                         demonstration.duration, demonstration.sample_count)
    return (np.asarray(demonstration.times, float),
            np.asarray(demonstration.positions, float))


def _check_point_robot(robot):
    """The toy robot's dynamics: a positive mass, time step and spring (without a spring
    the robot never follows the reference's position), a damper that is not negative."""
    require_finite(robot, "scenario.robot", ("mass", "time_step", "stiffness"))
    require_finite(robot, "scenario.robot", ("damping",), positive=False)
    check_time_steps([("scenario.robot.time_step", robot.time_step)])


def _resolve_point_robot(scenario):
    if scenario.goal_estimator.group_mass > 0.0:
        raise ScenarioError("scenario.goal_estimator.group_mass: goal groups steer the "
                            "DMPs of the robot tasks (reach, obstacles, grasp; HSR and arm); "
                            "this scenario has a point robot: set it to 0")
    if estimator_entry(scenario.goal_estimator.method).reads == READS_INTENT:
        raise ScenarioError("scenario.goal_estimator.method intent_filter reads the hand's "
                            "pose and the operator's command in the robot tasks (reach, "
                            "obstacles, grasp; HSR and arm); this scenario has a point robot: "
                            "use angle in the 2-D scenes")
    _check_point_robot(scenario.robot)
    if scenario.dmp.primitive:
        raise ScenarioError("scenario.dmp.primitive gives a robot task's DMPs a taught shape; "
                            "a 2-D scene learns its shape from scenario.demonstration")
    scenario = _with_period(scenario, whole_steps(
        scenario.control_period, scenario.robot.time_step, "scenario.control_period",
        "scenario.robot.time_step"))
    demonstration = None
    if scenario.demonstration is not None:
        if isinstance(scenario.demonstration, BentPath):
            check_bent_path(scenario.demonstration)
        with _refused_as("scenario.demonstration: "):
            demonstration = validate_demonstration(
                *demonstration_samples(scenario.demonstration))
    elif not scenario.start or not scenario.goals:
        raise ScenarioError(
            "scenario.start and scenario.goals are needed when there is no demonstration")
    start = (np.asarray(scenario.start, float) if scenario.start
             else demonstration[1][0].copy())
    goals = (np.asarray(scenario.goals, float).reshape(len(scenario.goals), -1)
             if scenario.goals else demonstration[1][-1][np.newaxis, :].copy())
    if goals.shape[1] != start.size:
        raise ScenarioError(
            f"scenario.goals have dimension {goals.shape[1]}, scenario.start has {start.size}")
    # The bound every goal of a running diagram is held to (GoalsSource, the DMP bank).
    for field, name, points in (("scenario.goals", "goal", goals),
                                ("scenario.start", "start", start)):
        with _refused_as(f"{field}: "):
            check_positions(points, name)
    _check_method(scenario, goals.shape[0])
    if scenario.dmp_duration <= 0 and demonstration is None:
        raise ScenarioError("scenario.dmp_duration is needed when there is no demonstration")
    check_obstacles(scenario.obstacles, start.size)
    _check_toy_operator(scenario.operator, start.size)
    duration = scenario.dmp_duration if scenario.dmp_duration > 0 else None
    check_dmp_duration(
        duration or demonstration[0][-1] - demonstration[0][0], scenario.control_period,
        "scenario.dmp_duration" if duration else "scenario.demonstration's duration")
    if demonstration is None:
        bank = DmpBankModel.straight(start, goals.shape[0], duration, scenario.dmp)
    else:
        bank = DmpBankModel.from_demonstration(*demonstration, goals.shape[0], scenario.dmp,
                                          start, duration)
    return ResolvedScenario(
        scenario=scenario, start=start, goals=goals, demonstration=demonstration,
        dmp_bank=bank)


def check_obstacles(obstacles, dimension, field="scenario.obstacles"):
    """Each obstacle of a 2-D (any-D) scene has a finite center of `dimension` and a finite
    positive radius; the error names `field[i]`."""
    for index, obstacle in enumerate(obstacles):
        if (len(obstacle.center) != dimension or not np.isfinite(obstacle.center).all()
                or not (np.isfinite(obstacle.radius) and obstacle.radius > 0)):
            raise ScenarioError(
                f"{field}[{index}] needs a finite center of dimension {dimension} and a "
                f"finite positive radius, got center {obstacle.center}, radius "
                f"{obstacle.radius}")


def _check_toy_operator(operator, dimension):
    if isinstance(operator, ObstacleRepulsion):
        with _refused_as(""):
            check_repulsion_params(operator, dimension, "scenario.operator")
    elif isinstance(operator, SinusoidalStep):
        check_direction(operator.axis, dimension, "scenario.operator.axis")
        if not (np.isfinite(operator.amplitude) and operator.duration > 0 and operator.period > 0):
            raise ScenarioError("scenario.operator.amplitude must be finite, duration and "
                                "period positive")
    elif isinstance(operator, ScriptedCommands):
        commands = np.asarray(operator.commands, float)
        if commands.ndim != 2 or commands.shape != (len(operator.times), dimension):
            raise ScenarioError(
                f"scenario.operator.commands must be one command of dimension {dimension} "
                "per time")
        with _refused_as("scenario.operator."):
            checked_script(operator.times, operator.commands)


def _resolve_task_robot(scenario):
    """The HSR's or an arm's task: the scene drawn from the seed, the station's config, the
    hand's start and the controller's config."""
    robot = scenario.robot
    tag = f"!{type(robot).__name__}"
    if scenario.task is None:
        raise ScenarioError(f"robot {tag} needs scenario.task, e.g. task: "
                            "{object_count: [2, 4]}")
    check_seed(scenario.seed)
    check_count(scenario.likely_paths, "scenario.likely_paths", 0, MAX_LIKELY_PATHS)
    station_field = "scenario.robot.station" if isinstance(robot, Hsr) else "scenario.robot"
    station = robot.station if isinstance(robot, Hsr) else robot.station_config()
    _refuse_what_the_task_sets(station, station_field)
    require_finite(robot, "scenario.robot", ("speed",))
    check_time_steps([
        (f"{station_field}.plant.time_step", station.plant.time_step),
        (f"{station_field}.diff_ik_time_step", station.diff_ik_time_step)])
    step, step_field = station.plant.time_step, f"{station_field}.plant.time_step"
    scenario = _with_period(scenario, whole_steps(
        scenario.control_period, step, "scenario.control_period", step_field,
        [station.diff_ik_time_step]))
    station = dataclasses.replace(station, diff_ik_time_step=whole_steps(
        station.diff_ik_time_step, step, f"{station_field}.diff_ik_time_step", step_field,
        [scenario.control_period]))
    operator = scenario.operator
    if isinstance(operator, PILOT_CONFIGS):
        check_pilot(operator)  # its participant's fields too; a population's are ranges
    else:
        require_finite(operator, "scenario.operator",
                       ("speed", "rotation_speed", "hold_time", "dead_zone", "reaction_delay",
                        "direction_noise", "speed_noise"), positive=False)
    if isinstance(operator, VirtualParticipant):
        check_virtual_participant(operator)
    if isinstance(operator, (Keyboard, Gamepad)):
        _check_person(operator, scenario.task)
    _check_hand_over(scenario)
    task = scenario.task
    if isinstance(robot, Hsr) and robot.hardware is not None:
        _check_bridge(robot.hardware, task)
    if isinstance(task, DynamicObstacles):
        check_obstacle_task(task)
    elif isinstance(task, GraspTask):
        if isinstance(robot, Arm):
            raise ScenarioError("scenario.task !GraspTask runs on the HSR's pose station; "
                                "robot !Arm takes the reaching and obstacle tasks")
        check_grasp_task(task)
    else:
        check_reach_task(task)
        if task.z_range and isinstance(operator, Gamepad):
            raise ScenarioError("scenario.operator !Gamepad has no up and down: a task whose "
                                "objects stand at heights of their own (scenario.task."
                                "z_range) takes !Keyboard or !VirtualParticipant")
    if isinstance(robot, Arm):
        # The station ramps between the loop's ticks; refusals name scenario.robot's fields.
        station = dataclasses.replace(station, control_period=scenario.control_period)
        with _refused_as("", "ArmStationConfig.", "scenario.robot."):
            initial_ee_state, reach = arm_ready_ee_state_and_reach(station)
    else:
        reach = None
    with _refused_as("scenario.task: ", "scenario.task: scenario.", "scenario."):
        scene = task_scene(task, scenario.seed, reach)
        if isinstance(robot, Arm):
            check_clear_of_base(station, scene_boxes(task, scene, scenario.seed),
                                "scenario.robot.model_file")
    # The HSR's hand starts at the task's height; the station ramps between the loop's
    # ticks, and it measures the task's cylinders against the robot.
    cylinders = [] if scene.obstacles is None else [
        CylinderObstacle(radius=task.obstacle_radius, height=task.obstacle_height)
        for _ in scene.obstacles.obstacle_starts]
    if isinstance(robot, Hsr):
        station = dataclasses.replace(station, ee_height=task.height,
                                      control_period=scenario.control_period,
                                      obstacles=cylinders)
        with _refused_as("scenario.robot.station: "):
            initial_ee_state = hsr_ready_ee_state(station)
    else:
        station = dataclasses.replace(station, obstacles=cylinders)
    start = initial_ee_state[:3].copy()
    goals = np.asarray(scene.objects, float)
    nearest = float(np.min(np.linalg.norm(goals - start, axis=1)))
    if task.success_distance >= nearest:
        raise ScenarioError(
            f"scenario.task.success_distance {task.success_distance} m reaches the nearest "
            f"object ({nearest:.2f} m from the hand's start): the task would succeed at once")
    controller = PbpControllerConfig(**{
        **scenario.control_settings(), "nominal_speed": float(robot.speed),
        "hand_over": robot.hand_over(), "dmp_primitive": _taught_primitive(scenario, task)})
    if isinstance(task, GraspTask):  # its DMPs move the palm to the grasps (builder.grasp)
        duration = controller.duration_for(hsr_ready_palm_position(station),
                                           scene.grasps.grasp_positions)
    else:
        duration = controller.duration_for(start, goals)
    check_dmp_duration(duration, scenario.control_period, "scenario.dmp_duration" if
                       scenario.dmp_duration > 0 else "scenario.robot.speed")
    controller = dataclasses.replace(controller, dmp_duration=float(duration))
    # The DMPs are fitted where they run: by the controller, from `controller`.
    return ResolvedScenario(
        scenario=scenario, start=start, goals=goals, demonstration=None, dmp_bank=None,
        scene=scene, station=station, initial_ee_state=initial_ee_state,
        controller=controller)


#: The largest primitive file read (a demonstration of an hour at 100 Hz is about 20 MiB).
MAX_PRIMITIVE_BYTES = 64 * 2**20

#: The station's fields a task sets, each from its one home in the scenario.
_SET_BY_THE_TASK = {"control_period": "scenario.control_period",
                    "ee_height": "scenario.task.height",
                    "obstacles": "scenario.task (the obstacle task's cylinders)"}


def _refuse_what_the_task_sets(station, station_field):
    """A station field the task sets, given in the file, would be overwritten unseen: it is
    refused, naming where the value belongs."""
    defaults = type(station)()
    for name, home in _SET_BY_THE_TASK.items():
        if hasattr(station, name) and getattr(station, name) != getattr(defaults, name):
            raise ScenarioError(f"{station_field}.{name} is set by the task from {home}; "
                                "give it there")


def _taught_primitive(scenario, task):
    """The scenario's taught primitive (`dmp.primitive`), read and checked against the
    task's DMPs; None without one."""
    dmp = scenario.dmp
    if not dmp.primitive:
        return None
    field = f"scenario.dmp.primitive {dmp.primitive}"
    primitive = load_primitive(dmp.primitive, field)
    if isinstance(task, GraspTask) and primitive.orientation is None:
        raise ScenarioError(f"{field} teaches positions alone; the grasping task's DMPs "
                            "move the hand's pose: teach it on a grasping task")
    if primitive.dimension != 3:
        raise ScenarioError(f"{field} teaches {primitive.dimension}-D paths; the task's "
                            "DMPs move the hand in 3-D")
    for name in SETTINGS_FIELDS:
        ours, theirs = getattr(dmp, name), getattr(primitive.settings, name)
        if ours != theirs:
            raise ScenarioError(f"scenario.dmp.{name} is {ours!r}; the primitive {dmp.primitive} "
                                f"was fitted with {theirs!r}: set it so, or teach it again")
    return primitive


def load_primitive(path, field):
    """The primitive in the file at `path`; ScenarioError `field: what is wrong` (one line)
    for a file that cannot be read, is not JSON (truncated, corrupt) or not a primitive."""
    if is_special_file(path):
        raise ScenarioError(f"{field} is not a regular file: not a primitive")
    try:
        with open(path, "rb") as file:
            data = file.read(MAX_PRIMITIVE_BYTES + 1)
    except OSError as error:
        raise ScenarioError(f"{field} cannot be read: {error.strerror or error}") from None
    if len(data) > MAX_PRIMITIVE_BYTES:
        raise ScenarioError(f"{field} is over {MAX_PRIMITIVE_BYTES // 2**20} MiB: not a "
                            "primitive")
    try:
        document = json.loads(data)
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ScenarioError(f"{field} is not a primitive file (truncated or corrupt: "
                            f"{getattr(error, 'msg', error)})") from None
    with _refused_as(f"{field}: "):
        return read_primitive_document(document)


def _check_bridge(hardware, task):
    """The HSR's task-space bridge: its fields, and a task whose station ports it carries
    (the hand's command and state, nothing more)."""
    with _refused_as("", "TaskSpaceBridgeConfig.", "scenario.robot.hardware."):
        validate_task_space_bridge(hardware)
    if hardware.connect and not isinstance(task, MultiGoalReach):
        raise ScenarioError(
            f"scenario.robot.hardware: the task-space bridge carries the hand's command and "
            f"state alone; scenario.task !{type(task).__name__} needs more of the station "
            "(the obstacles' positions and contacts, the hand's pose): the bridge runs the "
            "reaching task")


def _check_person(operator, task):
    """A person's `!Keyboard` or `!Gamepad` as its operator system takes it: a gamepad's
    dead zone a fraction of the stick's travel; on the grasping task's pose operators, a
    turn rate and a key's hold time above 0."""
    positive = ()
    if isinstance(task, GraspTask):
        positive = ("rotation_speed", "hold_time") if isinstance(operator, Keyboard) else (
            "rotation_speed",)
    fraction = ("dead_zone",) if isinstance(operator, Gamepad) else ()
    with _refused_as("", f"{type(operator).__name__}.", "scenario.operator."):
        check_params(operator, positive=positive, fraction=fraction)


def _check_hand_over(scenario):
    """The hand-over's limits must let the hand reach the task's speeds (the DMPs' and the
    operator's) within the time limit."""
    robot = scenario.robot
    with _refused_as("scenario.robot."):
        robot.hand_over().validate()
    acceleration, top_speed = robot.max_hand_acceleration, robot.max_hand_speed
    yaw_acceleration = robot.max_hand_yaw_acceleration
    operator_speed, turn = _operator_top_speeds(scenario)
    speed = max(robot.speed, operator_speed)
    if speed > top_speed:
        raise ScenarioError(
            f"scenario.robot.max_hand_speed {top_speed} m/s is below the task's speed "
            f"{speed} m/s (scenario.robot.speed or scenario.operator.speed): raise it")
    if speed / acceleration > scenario.duration:
        raise ScenarioError(
            f"scenario.robot.max_hand_acceleration {acceleration} m/s^2 takes "
            f"{speed / acceleration:.1f} s to reach the task's speed {speed} m/s, longer "
            f"than scenario.duration {scenario.duration} s: raise it")
    if turn / yaw_acceleration > scenario.duration:
        raise ScenarioError(
            f"scenario.robot.max_hand_yaw_acceleration {yaw_acceleration} rad/s^2 takes "
            f"{turn / yaw_acceleration:.1f} s to reach the operator's rotation_speed {turn} "
            f"rad/s, longer than scenario.duration {scenario.duration} s: raise it")


def _operator_top_speeds(scenario):
    """`(m/s, rad/s)`: the fastest the scenario's operator moves and turns the hand (a
    speed of 0 is the robot's): a pilot's participant's, the population's fastest draw,
    HOP's simulated user's clip."""
    operator = scenario.operator
    if isinstance(operator, ProportionalPilot):
        return operator.max_speed, 0.0
    if isinstance(operator, ParticipantPopulation):
        speed = operator.participant.speed or scenario.robot.speed
        return speed * max(operator.speed_factor), max(operator.rotation_speed)
    participant = getattr(operator, "participant", operator)
    return getattr(participant, "speed", 0.0), getattr(participant, "rotation_speed", 0.0)
