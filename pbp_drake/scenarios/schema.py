"""The schema of a scenario file: dataclasses read from YAML with `yaml_load_typed`.

A file holds one `scenario` (everything one simulation needs: robot, method, operator,
goals, demonstration, obstacles, rates) and optionally a `study` that varies it. Variants
are chosen with YAML tags, e.g. ``operator: !ObstacleRepulsion {speed: 1.0}``.

One default per knob: where a system is configurable, its section IS that system's
parameter dataclass (``goal_estimator`` is `GoalEstimatorSettings`, ``operator: !Keyboard``
a `KeyboardParams`, the HSR's ``station`` an `HsrStationConfig`, ``simulator`` Drake's
`SimulatorConfig`), so a Python user and a YAML user get the same robot; the tag classes
(`Keyboard`, `PointRobot`, ...) only name the variants, adding no field or default.
`pbp_drake.scenarios.resolve` checks and derives everything else.
"""

import copyreg
import dataclasses
import math
import typing

from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import SimulatorConfig
from pydrake.visualization import VisualizationConfig

from pbp_drake.core.controller_config import (
    ControlSettings, HandLimits, HandOverSettings, PbpControllerConfig)
from pbp_drake.core.methods import forward_key_enabled, shows_intent  # noqa: F401 (public)
from pbp_drake.robots.arm_station_config import ArmStationConfig
from pbp_drake.robots.hsr_station_config import HsrStationConfig
from pbp_drake.robots.task_space_bridge import TaskSpaceBridgeConfig
from pbp_drake.systems.operators.gamepad_operator import GamepadParams
from pbp_drake.systems.operators.keyboard_operator import KeyboardParams
from pbp_drake.systems.operators.obstacle_repulsion_operator import ObstacleRepulsionParams
from pbp_drake.systems.tasks.point_robot_dynamics import PointRobotParams
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.pilot_population import ParticipantPopulationParams
from pbp_drake.core.surrogate_pilots import (
    LaggyPilotParams, NoisyPilotParams, ProportionalPilotParams)


def _config_from_yaml(config_type, text):
    return yaml_load_typed(schema=config_type, data=text)


def _reduce_config(config):
    return _config_from_yaml, (type(config), yaml_dump_typed(config))


# Drake's config structs do not pickle, and a study sends its scenario to worker processes:
# they travel as their YAML.
for _config_type in (MultibodyPlantConfig, SimulatorConfig, VisualizationConfig):
    copyreg.pickle(_config_type, _reduce_config)


#: The metadata key of a `[low, high]` field: one number there is the range [n, n].
RANGE = "range"


def range_field(*low_high):
    """A `[low, high]` field (empty: none) that also takes one number, exactly it."""
    return dataclasses.field(default_factory=lambda: list(low_high), metadata={RANGE: True})


class ScenarioError(ValueError):
    """A scenario file or value that cannot be used; the message names the field."""


#: Old method name -> (its name now, why): a scenario, `--method` or `--methods` naming the
#: old one is refused with a message naming the new one (`resolution.renamed_method`).
RENAMED_METHODS = {
    "policy_blending": ("predict_then_assist", "HOP's action added once the two most "
                        "probable goals differ by hop.blending_threshold; Dragan and "
                        "Srinivasa's arbitration is confidence_alpha"),
}


@dataclasses.dataclass
class Obstacle:
    """A disc (sphere in 3-D) the 2-D robot must not enter."""

    #: The centre (m), one coordinate per dimension.
    center: list[float] = dataclasses.field(default_factory=list)
    #: The radius (m).
    radius: float = 0.1


class PointRobot(PointRobotParams):
    """`robot: {...}` (the default variant): the toy robot, a point mass-spring-damper."""


@dataclasses.dataclass
class TaskRobot(HandLimits):
    """What the HSR and an arm share: the hand-over law's limits (`HandLimits`) and the
    DMPs' nominal speed; the controller takes them (`PbpControllerConfig.nominal_speed`,
    `hand_over`)."""

    #: The DMPs' nominal speed (m/s): their duration is the farthest goal's distance over
    #: it, and operators whose speed is 0 move the hand at it.
    speed: float = PbpControllerConfig.nominal_speed

    def hand_over(self):
        """The controller's `HandOverSettings`: these limits, and the heading's bound where
        the robot has one."""
        return HandOverSettings(**{field.name: getattr(self, field.name, math.inf)
                                   for field in dataclasses.fields(HandOverSettings)})


@dataclasses.dataclass
class Hsr(TaskRobot):
    """`robot: !Hsr {...}`: the simulated Toyota HSR (our primitive-shape model) under
    whole-body differential IK; the PBP loop commands its end effector in task space."""

    #: What the HSR station is built from (see HsrStationConfig).
    station: HsrStationConfig = dataclasses.field(default_factory=HsrStationConfig)
    #: A real HSR (or any robot that is not Drake's) through the task-space bridge: the
    #: hand's command and state as LCM channels to a relay on the robot's side
    #: (TaskSpaceBridgeConfig, docs/tasks/real-arm.md); used with `connect`. None: the
    #: simulated HSR only.
    hardware: typing.Optional[TaskSpaceBridgeConfig] = None


@dataclasses.dataclass
class Arm(ArmStationConfig, TaskRobot):
    """`robot: !Arm {model_file: ..., base_frame: ..., ee_frame: ...}`: a fixed-base arm
    from a URDF or SDFormat file (ours, `package://pbp_drake_models/arm7/pbp_arm7.urdf`,
    or a user's own) under differential IK; every field of ArmStationConfig, and the
    HSR's speed and hand-over limits. The task sets the station's control_period (the
    scenario's) and obstacles (the obstacle task's cylinders); the file leaves them out."""

    #: How far (rad) the hand's heading may turn either way from its start: a wrist's
    #: turn is bounded, and past about 90 degrees the tool points back at the arm.
    max_heading_turn: float = 1.2

    def station_config(self):
        """Its fields of ArmStationConfig, as one."""
        return ArmStationConfig(**{field.name: getattr(self, field.name)
                                   for field in dataclasses.fields(ArmStationConfig)})


# The robots that run the tasks (goals drawn from a seed, an operator, a station).
TASK_ROBOTS = (Hsr, Arm)


@dataclasses.dataclass
class BentPath:
    """A demonstration from `start` to `goal` that bows sideways by `bend` at mid-path."""

    #: Where the demonstration starts (m).
    start: list[float] = dataclasses.field(default_factory=list)
    #: Where it ends (m).
    goal: list[float] = dataclasses.field(default_factory=list)
    #: The sideways offset at mid-path (m).
    bend: float = 0.0
    #: Its duration (s).
    duration: float = 1.0
    #: How many samples it has (a count).
    sample_count: int = 200


@dataclasses.dataclass
class RecordedPath:
    """A demonstration given sample by sample."""

    #: The sample times (s), increasing.
    times: list[float] = dataclasses.field(default_factory=list)
    #: The positions (m), one row per time.
    positions: list[list[float]] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class NoOperator:
    """No operator input at all (u = 0)."""


class ObstacleRepulsion(ObstacleRepulsionParams):
    """`operator: !ObstacleRepulsion {...}`: the paper's virtual human of the 2-D scenes."""


@dataclasses.dataclass
class SinusoidalStep:
    """Open-loop input along `axis`: `amplitude * sin(2 pi (t - start_time) / period)` for
    `start_time <= t < start_time + duration`, then it stops at once (Fig. 4's input)."""

    #: The input's direction (a vector, one entry per dimension).
    axis: list[float] = dataclasses.field(default_factory=list)
    #: The input's amplitude (the operator command's unit, m/s).
    amplitude: float = 1.0
    #: When the input starts (s).
    start_time: float = 0.2
    #: How long it lasts (s).
    duration: float = 0.4
    #: The sine's period (s).
    period: float = 1.6


@dataclasses.dataclass
class ScriptedCommands:
    """Commands `(T, D)` held from each of `times` until the next."""

    #: When each command starts (s), increasing strictly.
    times: list[float] = dataclasses.field(default_factory=list)
    #: The commands (m/s), one row per time.
    commands: list[list[float]] = dataclasses.field(default_factory=list)


class Keyboard(KeyboardParams):
    """`operator: !Keyboard {...}`: a person at the browser's keyboard (HSR tasks)."""


class Gamepad(GamepadParams):
    """`operator: !Gamepad {...}`: a person with a gamepad in the browser (HSR tasks)."""


class VirtualParticipant(VirtualParticipantParams):
    """`operator: !VirtualParticipant {...}`: the stand-in for the paper's participants."""


# The field's surrogate pilots (`pbp_drake.scenarios.pilots` is their registry; each
# `participant:` is an untagged `VirtualParticipantParams` mapping).
class NoisyPilot(NoisyPilotParams):
    """`operator: !NoisyPilot {eps: 0.3, participant: {...}}`: the virtual participant
    whose output is, each tick with probability eps, a random key state."""


class LaggyPilot(LaggyPilotParams):
    """`operator: !LaggyPilot {p: 0.85, participant: {...}}`: the virtual participant
    that repeats its previous output with probability p (per 1/50 s)."""


class ProportionalPilot(ProportionalPilotParams):
    """`operator: !ProportionalPilot {gain: 10, max_speed: 0}`: HOP's simulated user."""


class ParticipantPopulation(ParticipantPopulationParams):
    """`operator: !ParticipantPopulation {...}`: each trial's participant drawn from its
    seed over ranges of conformance, proficiency, aggressiveness and speed."""


PILOT_CONFIGS = (NoisyPilot, LaggyPilot, ProportionalPilot, ParticipantPopulation)
HSR_OPERATORS = (NoOperator, Keyboard, Gamepad, VirtualParticipant, *PILOT_CONFIGS)
TOY_OPERATORS = (NoOperator, ObstacleRepulsion, SinusoidalStep, ScriptedCommands)
# The names `pbp-drake run --operator` takes for the HSR tasks.
OPERATOR_NAMES = {"keyboard": Keyboard, "gamepad": Gamepad, "virtual": VirtualParticipant,
                  "none": NoOperator}


@dataclasses.dataclass
class MultiGoalReach:
    """The paper's multi-goal reaching task (section IV-B.1): objects drawn from the seed in
    a rectangle in front of the robot at one height; the target switches to another object
    at each progress threshold of `switch_schedule` after the first (0 %)."""

    #: The range [min, max] of how many objects are drawn (a count); one number: exactly
    #: that many.
    object_count: list[int] = range_field(2, 4)
    #: K > 0: K objects instead, one in each cell of a K-cell grid over the region, drawn
    #: from the seed (thousands are placed at once; `pbp-drake run` and `study` --goals K);
    #: 0: object_count objects drawn min_separation apart.
    grid_objects: int = 0
    #: The objects' x range (m).
    x_range: list[float] = range_field(1.25, 2.5)
    #: The objects' y range (m).
    y_range: list[float] = range_field(-1.05, 1.05)
    #: The objects' and the HSR hand's height (m).
    height: float = 0.7
    #: The objects' height range [min, max] (m), drawn per object; empty: all at height.
    #: The hand then starts where the robot's ready pose puts it, and the operators get
    #: up and down keys.
    z_range: list[float] = range_field()
    #: The least distance between two objects (m).
    min_separation: float = 0.2
    #: The progress fractions (0 to 1) at which the target switches.
    switch_schedule: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.3, 0.6])
    #: The hand within this distance (m) of the target is a success.
    success_distance: float = 0.05
    #: Fixed objects `(M, 3)` and targets (object indices, one per schedule entry) instead of
    #: drawing them from the seed.
    objects: list[list[float]] = dataclasses.field(default_factory=list)
    #: The target object indices with `objects`, one per schedule entry.
    targets: list[int] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class DynamicObstacles:
    """The paper's obstacle task (section IV-B.2): one target drawn from the seed; cylinder
    obstacles start still at random places and, once the progress passes each one's
    threshold (drawn in `activation_range`), move at `obstacle_speed` to the midpoint of the
    line from the hand to the target. Collisions are measured on the HSR's collision
    geometry and do not push the robot."""

    #: The target's x range (m).
    x_range: list[float] = range_field(1.25, 2.5)
    #: The target's y range (m).
    y_range: list[float] = range_field(-1.05, 1.05)
    #: The target's and the hand's height (m).
    height: float = 0.7
    #: The hand within this distance (m) of the target is a success.
    success_distance: float = 0.05
    #: How many cylinder obstacles (a count).
    obstacle_count: int = 3
    #: The obstacles' radius (m).
    obstacle_radius: float = 0.12
    #: The obstacles' height (m).
    obstacle_height: float = 1.2
    #: The obstacles' speed once they move (m/s).
    obstacle_speed: float = 0.15
    #: The obstacles' starting x range (m).
    obstacle_x_range: list[float] = range_field(0.9, 2.6)
    #: The obstacles' starting y range (m).
    obstacle_y_range: list[float] = range_field(-1.3, 1.3)
    #: The progress fractions (0 to 1) between which each obstacle's start threshold is drawn.
    activation_range: list[float] = range_field(0.05, 0.5)
    #: Obstacles start at least this far (m) from the robot's base, the target and each
    #: other (the HSR's scene; an arm's workspace takes less).
    obstacle_spacing: float = 0.45
    #: Fixed starts `(N, 2)` (x, y, m) of the obstacle_count obstacles instead of drawing
    #: them (they may stand closer than obstacle_spacing to each other: a wall, but not to
    #: the robot's base); the target is then drawn at least obstacle_spacing from each.
    #: With obstacle_speed 0 they stay.
    obstacle_starts: list[list[float]] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class GraspTask:
    """The grasping task (`pbp_drake.core.grasp_task`): upright cylinders drawn
    from the seed, each on its own table in the reach task's rectangle, each with a grasp
    pose of the hand, from the side at a yaw or from above with a wrist roll; the target
    switches as in the reach task; success is the hand within `success_distance` of the
    target's grasp position and within `success_angle` of its grasp orientation. It runs
    on the pose station (`pbp_drake.builder.grasp`) with the virtual participant."""

    #: The range [min, max] of how many objects are drawn (a count); one number: exactly
    #: that many.
    object_count: list[int] = range_field(2, 4)
    #: The tables' centres are drawn in this rectangle (m), min_separation apart (at least
    #: the tables' diagonal, so that no two overlap).
    x_range: list[float] = range_field(1.25, 2.5)
    #: The tables' y range (m), as `x_range`.
    y_range: list[float] = range_field(-1.05, 1.05)
    #: The least distance between two tables' centres (m).
    min_separation: float = 0.45
    #: The height (m) the hand starts at (the station's ready pose), as the reach task's.
    height: float = 0.7
    #: Each table is a box table_size (x, y) m wide with its top at table_height (m).
    table_height: float = 0.6
    #: The tables' size (x, y) (m).
    table_size: list[float] = dataclasses.field(default_factory=lambda: [0.3, 0.3])
    #: Each object is an upright cylinder standing at its table's centre.
    object_radius: float = 0.03
    #: The objects' height (m).
    object_height: float = 0.15
    #: An object is grasped from above with this probability, else from the side.
    top_probability: float = 0.5
    #: Side grasps approach horizontally at a yaw (degrees, counter-clockwise from the
    #: direction the robot faces) drawn here; inside [-90, 90].
    approach_yaw_range: list[float] = range_field(-60.0, 60.0)
    #: Top grasps approach straight down with a wrist roll (degrees) drawn here; inside
    #: [-180, 180].
    roll_range: list[float] = range_field(-90.0, 90.0)
    #: The palm stands this far (m) behind the point the fingers close on.
    grasp_depth: float = 0.08
    #: The progress fractions (0 to 1) at which the target switches.
    switch_schedule: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.3, 0.6])
    #: The hand within this distance (m) of the target's grasp position (and within
    #: `success_angle`) is a success.
    success_distance: float = 0.03
    #: Degrees.
    success_angle: float = 10.0
    #: How many grasps each object offers (a count), each a goal of its own drawn as the
    #: one grasp is; the targets are grasps. 1: one grasp an object (the paper's).
    grasps_per_object: int = 1


@dataclasses.dataclass
class Scenario(ControlSettings):
    """What every scenario has: the controller's settings (`ControlSettings`: method,
    alpha, control_period, dmp, dmp_duration, goal_estimator, hop), its name, time limit
    and simulator. A file's `scenario:` is a `TaskScenario` when its robot is tagged
    `!Hsr` or `!Arm`, else a `PointScenario` (a 2-D scene)."""

    #: The scenario's name (in outputs and the console).
    name: str = "scenario"
    #: The time limit (s) of a run, at least one control_period: a run lasts the whole
    #: control ticks nearest to it.
    duration: float = 2.0
    #: How runs are simulated (Drake's own config; `pbp-drake run --realtime-rate` sets
    #: its target_realtime_rate). Its start_time stays 0: a scenario's times count from it.
    simulator: SimulatorConfig = dataclasses.field(default_factory=SimulatorConfig)


@dataclasses.dataclass
class PointScenario(Scenario):
    """A 2-D (any-D) scene: the point robot, its goals or a demonstration, disc obstacles
    and a toy operator (the paper's section IV-A)."""

    #: The toy point robot (untagged).
    robot: PointRobot = dataclasses.field(default_factory=PointRobot)
    #: The robot's initial position; empty: the demonstration's start.
    start: list[float] = dataclasses.field(default_factory=list)
    #: Candidate goals, one DMP each; empty: the demonstration's goal.
    goals: list[list[float]] = dataclasses.field(default_factory=list)
    #: The demonstration the DMPs learn from; none: straight paths.
    demonstration: typing.Optional[typing.Union[BentPath, RecordedPath]] = None
    #: The scene's obstacles (discs).
    obstacles: list[Obstacle] = dataclasses.field(default_factory=list)
    #: Who drives the robot: a tagged operator variant; untagged: none.
    operator: typing.Union[TOY_OPERATORS] = dataclasses.field(default_factory=NoOperator)


@dataclasses.dataclass
class TaskScenario(Scenario):
    """A robot task (the paper's section IV-B): the HSR (`robot: !Hsr`) or an arm
    (`robot: !Arm`) reaching, among obstacles or grasping in a scene drawn from the seed,
    the objects its goals; the hand starts where the robot stands."""

    #: The robot: `!Hsr` or `!Arm` (the tag chooses the scenario's type).
    robot: typing.Union[TASK_ROBOTS] = dataclasses.field(default_factory=Hsr)
    #: The seed of every random draw: the scene's and the participant's (an integer).
    seed: int = 0
    #: Who drives the robot: a tagged operator variant; untagged: none.
    operator: typing.Union[HSR_OPERATORS] = dataclasses.field(default_factory=NoOperator)
    #: The task: untagged a MultiGoalReach; `!DynamicObstacles {...}` the obstacle task,
    #: `!GraspTask {...}` the grasping task.
    task: typing.Optional[typing.Union[MultiGoalReach, DynamicObstacles, GraspTask]] = None
    #: In Meshcat: how many of the next most probable goals' DMP paths the page draws
    #: beside the selected goal's (the grasping task past 100 grasps: their grasp triads),
    #: 0 to 20; what is drawn does not grow with the goal count.
    likely_paths: int = 3

    @property
    def vertical(self):
        """Whether the operators move the hand up and down too: the reaching task's objects
        stand at heights of their own (`task.z_range`)."""
        return bool(getattr(self.task, "z_range", None))


@dataclasses.dataclass
class SceneVariant:
    """A test scene of the alpha study: the scenario with its obstacles replaced."""

    #: The scene's name.
    name: str = ""
    #: The scene's obstacles, replacing the scenario's.
    obstacles: list[Obstacle] = dataclasses.field(default_factory=list)


@dataclasses.dataclass
class AlphaStudy:
    """Explicit arbitration over `alphas` against PBP, in each scene (Fig. 2)."""

    #: Where the obstacles stood when the demonstration was given (drawn in panel a).
    demonstration_obstacles: list[Obstacle] = dataclasses.field(default_factory=list)
    #: The test scenes.
    scenes: list[SceneVariant] = dataclasses.field(default_factory=list)
    #: The fixed arbitration weights compared (each in [0, 1], no two alike; the summary
    #: names each by `alpha_key`).
    alphas: list[float] = dataclasses.field(
        default_factory=lambda: [round(0.1 * i, 1) for i in range(11)])
    #: The virtual operator's speeds (its `speed`) at which every scene runs, beside the
    #: scenario operator's own speed: the summary holds each scene's results per speed.
    #: The paper's Eq. 5 pushes at 1.
    operator_speeds: list[float] = dataclasses.field(default_factory=list)
    #: A run reached the goal when it ends this close to it (AltVsCont's tolerance). Reported
    #: beside the collision ratio; the ideal alpha stays the paper's (no collision).
    goal_tolerance: float = 0.01


def alpha_key(alpha):
    """An alpha as the alpha study's summary names it: with two decimals ("0.10"), or with
    all its digits where two would round it ("0.125")."""
    key = f"{alpha:.2f}"
    return key if float(key) == alpha else repr(float(alpha))


@dataclasses.dataclass
class AltVsCont:
    """The same DMP and open-loop input in continuous and alternated mode (Fig. 4)."""

    #: Both modes must end this close to the goal (m, positive).
    goal_tolerance: float = 0.01


#: The two parts of a method study's seeds (see MethodComparison).
STUDY_SPLITS = ("tuning", "evaluation")


@dataclasses.dataclass
class MethodComparison:
    """The same seeded scenes for each method, driven by the scenario's operator: trial i
    of `split` uses seed `tuning_seed + i` or `evaluation_seed + i`. Seeds from
    `tuning_seed` below `evaluation_seed` are the only ones the virtual participant may be
    tuned on; seeds from `evaluation_seed` on are for judging and publishing (see
    `pbp_drake.studies.splits`). `pbp-drake study --methods --trials --split --seed`
    override these."""

    #: The methods compared (names of the methods registry).
    methods: list[str] = dataclasses.field(
        default_factory=lambda: ["pbp_alternated", "pbp_continuous", "teleop"])
    #: Trials per method (a count).
    trials: int = 10
    #: The first seed of the tuning split.
    tuning_seed: int = 0
    #: The first seed of the evaluation split.
    evaluation_seed: int = 10_000
    #: Which split the trials use: tuning or evaluation.
    split: str = "evaluation"


@dataclasses.dataclass
class ScenarioFile:
    """The top level of a file in `diagrams/`. Its `scenario:` is not tagged: the robot's
    tag chooses its type (`pbp_drake.scenarios.loading.file_schema`; `TaskScenarioFile` is
    the file of a robot task)."""

    #: The scenario: everything one simulation needs (a 2-D scene, or a robot task with
    #: `robot: !Hsr` or `!Arm`).
    scenario: PointScenario = dataclasses.field(default_factory=PointScenario)
    #: The study that varies it, a tagged variant; none: no study.
    study: typing.Optional[typing.Union[AlphaStudy, AltVsCont, MethodComparison]] = None


@dataclasses.dataclass
class TaskScenarioFile(ScenarioFile):
    """A `ScenarioFile` whose scenario is a robot task."""

    #: The robot task.
    scenario: TaskScenario = dataclasses.field(default_factory=TaskScenario)
