"""Which of K goals the operator means (the paper's GOAL_ESTIMATOR), in pure NumPy.

Here: the registry `ESTIMATORS` (`goal_estimator: {method: NAME}`; a new estimator is one
`register_estimator` entry), the estimators that read the hand's position `p` (3) and
heading (rad, counter-clockwise from +x on the floor plane): ``angle`` (the paper, section
III-C), ``nearest`` and ``bayesian`` (Dragan & Srinivasa 2013), and the selection with
hysteresis (`update_selection`). ``pose``, ``maxent_command`` and ``intent_filter`` live in
their own modules. What each reads and scores: docs/concepts/goal-estimators.md."""

import dataclasses
import math
import typing

import numpy as np

from pbp_drake.core.choices import unknown_choice
from pbp_drake.core.coordinates import check_positions, is_real
from pbp_drake.core.intent_filter import NO_BEARING, IntentFilterSettings

#: `Estimator.reads`: the hand's position and heading (`GoalEstimator`, any task) ...
READS_POSITION = "position"
#: ... the hand's pose and the operator's twist (`PoseGoalEstimator`, the grasping task) ...
READS_POSE = "pose"
#: ... or the operator's command, recursively (`MaxEntGoalEstimator`, every task) ...
READS_COMMAND = "command"
#: ... or the operator's motions, silences and turns and the hand's heading, recursively
#: with a hazard (`IntentFilterGoalEstimator`, the position tasks).
READS_INTENT = "intent"

#: What an estimator may read.
READS = (READS_POSITION, READS_POSE, READS_COMMAND, READS_INTENT)

# `SelectionMemory.challenger` when no goal challenges the selection.
NO_CHALLENGER = -1


@dataclasses.dataclass
class GoalEstimatorSettings:
    """How goals are scored and how sticky the selection is (scenario files: the
    `goal_estimator` section). `margin=0, hold_steps=1` switches to the most probable goal
    at once; the ``pose`` score's weights are `grasp_estimation`'s."""

    #: The score: angle (the paper's heuristic), nearest, bayesian, pose (grasping task
    #: only), maxent_command (HOP's posterior on the operator's command; its constants are
    #: the scenario's `hop` section) or intent_filter (the robot tasks).
    method: str = "angle"
    #: The scale of the angle (rad), nearest (m) and pose (rad) scores: low enough that
    #: objects a few degrees apart are told apart.
    temperature: float = 0.1
    #: The rationality of bayesian (1/m).
    beta: float = 5.0
    #: Another goal must beat the selection by more than this (a probability) to take over.
    margin: float = 0.1
    #: How many consecutive updates (a count) another goal must beat it by `margin` to switch.
    hold_steps: int = 2
    #: The pose score's weight of the distance (rad per m).
    distance_weight: float = 0.1
    #: The pose score's weight of the angle to the grasp orientation (a factor).
    orientation_weight: float = 1.0
    #: The pose score subtracts the angle the hand's turning takes off in this time (s).
    turn_horizon: float = 1.0
    #: The direction of travel counts only while the hand moves this fast or faster (m/s).
    min_speed: float = 0.01
    #: PBP's goal groups (`pbp_drake.core.goal_groups`): the probability mass of the group
    #: the robot heads for until it commits to a goal; 0 (the paper's): no groups, the
    #: robot follows the selected goal from the start.
    group_mass: float = 0.0
    #: The robot commits once the group's goals lie this close (m) to their point.
    commit_radius: float = 0.05
    #: ... or once the most probable goal holds this probability.
    commit_probability: float = 0.8
    #: The intent_filter estimator's operator model (`pbp_drake.core.intent_filter`).
    intent_filter: IntentFilterSettings = dataclasses.field(
        default_factory=IntentFilterSettings)

    def __post_init__(self):
        self.validate()

    def validate(self):
        """Raises ValueError naming the first field that cannot be used (a YAML loader sets
        the fields after construction, so `resolve` calls this again)."""
        estimator_entry(self.method)
        for name in ("temperature", "beta"):
            value = getattr(self, name)
            if not is_real(value) or not math.isfinite(value) or value <= 0.0:
                raise ValueError(f"{name} must be a positive finite number, got {value!r}")
        for name in ("distance_weight", "orientation_weight", "turn_horizon", "min_speed"):
            value = getattr(self, name)
            if not is_real(value) or not math.isfinite(value) or value < 0.0:
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        check_hysteresis(self.margin, self.hold_steps)
        if not (is_real(self.group_mass) and 0.0 <= self.group_mass < 1.0):
            raise ValueError(f"group_mass must lie in [0, 1) (0: no groups), got "
                             f"{self.group_mass!r}")
        if not (is_real(self.commit_radius) and math.isfinite(self.commit_radius)
                and self.commit_radius > 0.0):
            raise ValueError(f"commit_radius must be a positive finite distance (m), got "
                             f"{self.commit_radius!r}")
        if not (is_real(self.commit_probability) and 0.0 < self.commit_probability <= 1.0):
            raise ValueError(f"commit_probability must lie in (0, 1], got "
                             f"{self.commit_probability!r}")
        if not isinstance(self.intent_filter, IntentFilterSettings):
            raise ValueError(f"intent_filter must be an IntentFilterSettings, got "
                             f"{type(self.intent_filter).__name__}")
        self.intent_filter.validate()


def check_hysteresis(margin, hold_steps):
    """Raises ValueError unless `margin` (a probability) lies in [0, 1) and `hold_steps` is
    an integer >= 1 (`update_selection`'s)."""
    if not is_real(margin) or not 0.0 <= margin < 1.0:
        raise ValueError(f"margin must lie in [0, 1), got {margin!r}")
    if (isinstance(hold_steps, bool) or not isinstance(hold_steps, (int, np.integer))
            or hold_steps < 1):
        raise ValueError(f"hold_steps must be an integer >= 1, got {hold_steps!r}")


class SelectionMemory(typing.NamedTuple):
    """The hysteresis memory: the selected goal, the goal challenging it (`NO_CHALLENGER`
    if none) and for how many consecutive updates a challenger has beaten it."""

    selected: int
    challenger: int = NO_CHALLENGER
    count: int = 0


class GoalEstimate(typing.NamedTuple):
    """What `estimate` returns: the selected goal index, the K probabilities, the memory to
    pass to the next call."""

    selected: int
    probabilities: np.ndarray
    memory: SelectionMemory


def validate_goals(goals):
    """Goals as a float `(K, 3)` array with K >= 1, finite and within the toolbox's bounds
    (`pbp_drake.core.coordinates`)."""
    goals = np.asarray(goals, dtype=float)
    if goals.ndim != 2 or goals.shape[1] != 3 or len(goals) == 0:
        raise ValueError(f"goals must be (K, 3) with K >= 1, got shape {goals.shape}")
    check_positions(goals, "goal")
    return goals


def validate_point(point, name):
    """A point as a float (3,) array with finite entries; errors name `name`."""
    point = np.asarray(point, dtype=float)
    if point.shape != (3,):
        raise ValueError(f"{name} must have 3 entries, got shape {point.shape}")
    if not np.isfinite(point).all():
        raise ValueError(f"{name} is NaN or infinite: {point}")
    return point


def _validate_scalar(value, name, minimum=None):
    if not is_real(value) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    if minimum is not None and value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value!r}")
    return float(value)


def softmax_of_costs(costs, scale):
    """`softmax(-costs / scale)`, shifted by the smallest cost so it never overflows."""
    costs = np.asarray(costs, dtype=float)
    weights = np.exp(-(costs - costs.min()) / scale)
    return weights / weights.sum()


def heading_angles(goals, position, heading):
    """Absolute angle (rad, in [0, pi]) between `heading` and the floor direction from
    `position` to each goal; 0 for a goal with no floor direction."""
    # Each coordinate's offset as a contiguous array, updated in place: the same numbers as
    # one (K, 2) offset, in about 60 % of its time at K = 10,000 (it is every tick's O(K)).
    dx = goals[:, 0] - position[0]
    dy = goals[:, 1] - position[1]
    directions = np.arctan2(dy, dx)
    directions -= heading
    angles = np.abs(np.angle(np.exp(1j * directions)))
    dx *= dx
    dy *= dy
    dx += dy
    angles[dx <= NO_BEARING * NO_BEARING] = 0.0  # no floor direction (a hypot's test)
    return angles


class Estimator(typing.NamedTuple):
    """One registry entry: the name `goal_estimator.method` spells, what it reads (`READS_*`,
    which picks its system), and for one that reads the position its function
    `probabilities(settings, goals (K, 3), position (3), heading, start (3), path_length)`
    -> K probabilities (the start and the path length since it: the system tracks them);
    for the others, the function that computes them (`computed_by`, for messages)."""

    name: str
    reads: str
    probabilities: typing.Optional[typing.Callable] = None
    computed_by: str = ""


def _angle(settings, goals, position, heading, start, path_length):
    heading = _validate_scalar(heading, "heading")
    return softmax_of_costs(heading_angles(goals, position, heading), settings.temperature)


def _nearest(settings, goals, position, heading, start, path_length):
    return softmax_of_costs(np.linalg.norm(goals - position, axis=1), settings.temperature)


def _bayesian(settings, goals, position, heading, start, path_length):
    if start is None:
        raise ValueError("the bayesian goal estimator needs start (the end effector's "
                         "position when estimation began)")
    start = validate_point(start, "start")
    path_length = _validate_scalar(path_length, "path_length", minimum=0.0)
    # Unnormalised `log P(g | S->Q)` (uniform prior): `-beta (C(S->Q) + |Q - g|) + beta |S - g|`.
    log_posterior = -settings.beta * (path_length + np.linalg.norm(goals - position, axis=1)
                                      - np.linalg.norm(goals - start, axis=1))
    weights = np.exp(log_posterior - log_posterior.max())
    return weights / weights.sum()


ESTIMATORS = {estimator.name: estimator for estimator in (
    Estimator("angle", READS_POSITION, _angle),
    Estimator("nearest", READS_POSITION, _nearest),
    Estimator("bayesian", READS_POSITION, _bayesian),
    Estimator("pose", READS_POSE,
              computed_by="pbp_drake.core.grasp_estimation.pose_probabilities"),
    Estimator("maxent_command", READS_COMMAND,
              computed_by="pbp_drake.core.hindsight_optimization.update_posterior"),
    Estimator("intent_filter", READS_INTENT,
              computed_by="pbp_drake.core.intent_filter.filter_step"),
)}
#: The shipped estimators that read the hand's position (`goal_probabilities`).
GOAL_ESTIMATION_METHODS = tuple(name for name, estimator in ESTIMATORS.items()
                                if estimator.reads == READS_POSITION)


def register_estimator(estimator):
    """Adds `estimator` (an `Estimator`) to `ESTIMATORS`; ValueError if its name is taken,
    or it reads the position without a probabilities function."""
    if not isinstance(estimator, Estimator):
        raise ValueError(f"estimator must be an Estimator, got {type(estimator).__name__}")
    if estimator.name in ESTIMATORS:
        raise ValueError(f"goal estimator {estimator.name!r} is already registered")
    if estimator.reads not in READS:
        raise ValueError(f"goal estimator {estimator.name!r}: reads {estimator.reads!r} is "
                         f"not one of {READS}")
    if (estimator.reads == READS_POSITION) != (estimator.probabilities is not None):
        raise ValueError(f"goal estimator {estimator.name!r}: a probabilities function is "
                         f"for (and needed by) an estimator that reads the position")
    ESTIMATORS[estimator.name] = estimator
    return estimator


def estimator_entry(name):
    """The `Estimator` called `name`; ValueError naming the choices and the nearest one."""
    if name not in ESTIMATORS:
        raise ValueError(unknown_choice("goal estimation method", name, ESTIMATORS))
    return ESTIMATORS[name]


def goal_probabilities(settings, goals, position, heading, start=None, path_length=0.0):
    """The K probabilities of `settings.method`, an estimator that reads the hand's
    position; `start` and `path_length` (the length of the path from `start` to
    `position`) are read by ``bayesian``."""
    goals = validate_goals(goals)
    position = validate_point(position, "position")
    estimator = estimator_entry(settings.method)
    if estimator.probabilities is None:
        raise ValueError(f"the {estimator.name} goal estimator reads more than the hand's "
                         f"position: call {estimator.computed_by}")
    return estimator.probabilities(settings, goals, position, heading, start, path_length)


def update_selection(probabilities, memory, margin, hold_steps):
    """The hysteresis step: the new `SelectionMemory` given this update's probabilities.

    With no memory (`None`) or a selection out of range, selects the most probable goal at
    once. Otherwise a challenger is counted while the most probable goal beats the
    selection by more than `margin`; the count resets as soon as none does, and at
    `hold_steps` the selection moves to the most probable goal.
    """
    probabilities = np.asarray(probabilities, dtype=float)
    best = int(np.argmax(probabilities))
    if memory is None or not 0 <= int(memory.selected) < len(probabilities):
        return SelectionMemory(best)
    selected = int(memory.selected)
    if best == selected or probabilities[best] - probabilities[selected] <= margin:
        return SelectionMemory(selected)
    count = int(memory.count) + 1
    if count >= hold_steps:
        return SelectionMemory(best)
    return SelectionMemory(selected, best, count)


def estimate(settings, goals, position, heading, memory=None, start=None, path_length=0.0):
    """One estimator update: `GoalEstimate(selected, probabilities, memory)`.

    Pass the returned `memory` to the next call; `memory=None` (the first call) selects the
    most probable goal without hysteresis.
    """
    probabilities = goal_probabilities(settings, goals, position, heading, start, path_length)
    memory = update_selection(probabilities, memory, settings.margin, settings.hold_steps)
    return GoalEstimate(memory.selected, probabilities, memory)
