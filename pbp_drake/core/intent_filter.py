"""The ``intent_filter`` goal estimator, in pure NumPy: a recursive Bayesian posterior over
the K goals on what the operator does, with a hazard that keeps it from becoming certain for
good, and the hand's present heading read on top:

    log b_t(g) = log((1 - h) b_{t-1}(g) + h / K) + dt (move_rate m_g + turn_rate t_g)
    log P_t(g) = log b_t(g) + heading_weight h_g,

each normalised and clipped at `max_probability`; `h = 1 - exp(-switch_rate dt)`, the
features `m_g`, `t_g`, `h_g` in [-1, 1] (`IntentFeatures`). The model, its silent and
override terms, the fit of its rates: docs/concepts/goal-estimators.md, "What each one
reads"."""

import dataclasses
import math
import typing

import numpy as np

from pbp_drake.core.coordinates import is_real
from pbp_drake.core.grasp_task import approach_direction
from pbp_drake.core.quaternion import angle_between, exp_map, multiply


# A goal closer than this (m) to the hand on the floor plane has no bearing.
NO_BEARING = 1e-9


@dataclasses.dataclass
class IntentFilterSettings:
    """The ``intent_filter`` estimator's operator model (scenario files: the
    `goal_estimator` section's `intent_filter`). The rates are nats per second of evidence
    for a goal the feature points straight at (1) over one it points across (0), and as
    much against one it points away from (-1); all but `silence_rate`, `max_probability`
    and `min_speed` are `pbp_drake.studies.intent_fit`'s fit."""

    #: The weight of the operator's command (nats/s) while it acts.
    move_rate: float = 128.0
    #: The weight of where the hand points now (nats, not per second: an observation of
    #: the hand's present heading, which persists, is not new evidence every tick).
    heading_weight: float = 4.0
    #: The turn's weight (nats/s): turning the hand toward a goal.
    turn_rate: float = 8.0
    #: The weight (nats/s) of the robot's motion while the operator is silent (0: a silence
    #: is no evidence).
    silence_rate: float = 0.0
    #: The weight (nats/s) against the goal the robot shows while the operator acts: an
    #: operator takes over when the robot's intent is wrong (0: no evidence).
    override_rate: float = 0.0
    #: How often the operator changes its goal (1/s): the filter's hazard.
    switch_rate: float = 3.0
    #: No goal's probability goes above this (the clip against certainty).
    max_probability: float = 0.99
    #: A motion slower than this (m/s) has no direction.
    min_speed: float = 0.01

    def validate(self):
        """Raises ValueError naming the first field that cannot be used."""
        for name in ("move_rate", "heading_weight", "turn_rate", "silence_rate",
                     "override_rate", "switch_rate", "min_speed"):
            value = getattr(self, name)
            if not is_real(value) or not math.isfinite(value) or value < 0.0:
                raise ValueError(f"intent_filter.{name} must be a finite number >= 0, got "
                                 f"{value!r}")
        if not (is_real(self.max_probability) and 0.0 < self.max_probability <= 1.0):
            raise ValueError(f"intent_filter.max_probability must lie in (0, 1], got "
                             f"{self.max_probability!r}")


class IntentFeatures(typing.NamedTuple):
    """One tick's features per goal, each (K,) in [-1, 1]: `moves`, `headings`, `turns`;
    whether the operator `acts` (else the moves are the robot's); and the goal the robot
    shows while it acts (`overridden`, -1: none), which its intervention is against."""

    moves: np.ndarray
    headings: np.ndarray
    turns: np.ndarray
    acts: bool = True
    overridden: int = -1


class FilterUpdate(typing.NamedTuple):
    """One update: the new recursive `log_belief` (K,) (the state), the `probabilities`
    (K,) with the present heading read, and whether their clip was active (`clipped`)."""

    log_belief: np.ndarray
    probabilities: np.ndarray
    clipped: bool


def intent_features(goals, position, motion, heading, yaw_rate, period, min_speed, acts=True):
    """The `IntentFeatures` of the K `goals` (K, 3) for the hand at `position` (3) heading
    `heading` (rad), the `motion` (3, m/s: the operator's command when it `acts`, else the
    hand's own velocity) and the operator's `yaw_rate` (rad/s) over one `period` (s)."""
    # Column by column: NumPy broadcasts `goals - position` over rows of 3, a loop per row,
    # where a column's subtraction is one loop (the same numbers, in a third of the time).
    offsets = np.empty_like(goals, dtype=float)
    for column in range(3):
        np.subtract(goals[:, column], position[column], out=offsets[:, column])
    moves = _moves(offsets, motion, period, min_speed)
    has_bearing, error = floor_bearings(offsets, heading)
    headings = _straightness(np.abs(error))
    headings[~has_bearing] = 1.0
    turn = yaw_rate * period
    if turn == 0.0:
        turns = np.zeros(len(goals))
    else:
        turns = turn_progress(has_bearing, error, turn)
    return IntentFeatures(moves, headings, turns, bool(acts))


def floor_bearings(offsets, heading):
    """Whether each goal at `offsets` (K, 2 or 3) from the hand has a bearing on the floor
    plane (K,), and its heading error `wrap(bearing - heading)` (K,) in rad."""
    # Each coordinate as a contiguous array, squared in place for the bearing's test (as
    # `goal_estimation.heading_angles`): the same numbers, in a fraction of hypot's time.
    dx, dy = offsets[:, 0].copy(), offsets[:, 1].copy()
    error = np.arctan2(dy, dx)
    error -= heading
    dx *= dx
    dy *= dy
    dx += dy
    return dx > NO_BEARING * NO_BEARING, _wrapped(error)


def turn_progress(has_bearing, error, turn):
    """`(|e_g| - |wrap(e_g - turn)|) / |turn|` (K,) of the `floor_bearings` and a `turn`
    (rad, not 0): +1 for a turn wholly toward a goal, -1 wholly away, 0 without a bearing."""
    turned = _wrapped(error - turn)
    np.abs(turned, out=turned)
    progress = np.abs(error)
    progress -= turned
    progress /= abs(turn)
    progress[~has_bearing] = 0.0
    return progress


def pose_intent_features(positions, orientations, position, orientation, velocity,
                         angular_velocity, period, min_speed, acts=True, forward_key=True,
                         shown=-1):
    """The `IntentFeatures` of K grasp poses (`positions` (K, 3), unit `orientations`
    (K, 4)) for the hand at `position` (3) with unit `orientation` (4), the motion
    `velocity` (3, m/s) and the operator's `angular_velocity` (3, rad/s, world frame; 0
    while silent) over one `period`; `shown` the goal the robot shows (-1: none), which an
    acting operator overrides (`overridden`). Without the `forward_key` the moves read the
    part of `g - p` across the approach axis (the features: docs/concepts/goal-estimators.md,
    "What each one reads")."""
    offsets = positions - position
    orientation = np.asarray(orientation, dtype=float)
    approach = approach_direction(orientation)
    across = offsets if forward_key or not acts else (
        offsets - np.outer(offsets @ approach, approach))
    moves = _moves(across, velocity, period, min_speed)
    angles = angle_between(orientations.T, orientation[:, np.newaxis])
    # Where the approach axis points: the 3-D form of the position task's heading.
    distances = np.sqrt(np.einsum("ij,ij->i", offsets, offsets))
    pointing = np.where(distances > NO_BEARING, _straightness(np.arccos(np.clip(
        offsets @ approach / np.maximum(distances, NO_BEARING), -1.0, 1.0))), 1.0)
    turn = float(np.linalg.norm(angular_velocity)) * period
    if turn == 0.0:
        turns = np.zeros(len(positions))
    else:
        turned = multiply(exp_map(np.asarray(angular_velocity, float) * period), orientation)
        turns = (angles - angle_between(orientations.T, turned[:, np.newaxis])) / turn
    overridden = int(shown) if acts and 0 <= shown < len(positions) else -1
    return IntentFeatures(moves, 0.5 * (pointing + _straightness(angles)), turns, bool(acts),
                          overridden)


def _moves(offsets, motion, period, min_speed):
    """The moves `m_g = 1 - 2 a_g / pi` of the goals at `offsets` (K, 3) from the hand."""
    speed = float(np.linalg.norm(motion))
    if speed < min_speed:
        return np.zeros(len(offsets))
    distances = np.sqrt(np.einsum("ij,ij->i", offsets, offsets))
    near = distances < min_speed * period
    cosines = offsets @ motion
    cosines /= np.maximum(distances, min_speed * period, out=distances) * speed
    moves = _straightness(np.arccos(np.clip(cosines, -1.0, 1.0, out=cosines), out=cosines))
    moves[near] = 0.0
    return moves


def _straightness(angles):
    """`1 - 2 angle / pi`: 1 straight at a goal, 0 across, -1 straight away."""
    return 1.0 - (2.0 / math.pi) * angles


def _wrapped(angles):
    """`(angles + pi) % 2 pi - pi` (K,), the modulo taken only where it changes a value:
    the same numbers in a fifth of the time when most angles are within a turn."""
    shifted = np.asarray(angles) + np.pi
    outside = np.flatnonzero((shifted < 0.0) | (shifted >= 2.0 * np.pi))
    shifted[outside] = np.remainder(shifted[outside], 2.0 * np.pi)
    shifted -= np.pi
    return shifted


def switch_probability(settings, period):
    """`h = 1 - exp(-switch_rate dt)`: the chance the operator picks its goal anew in a tick."""
    return -math.expm1(-settings.switch_rate * period)


def filter_step(settings, log_belief, features, period):
    """One tick of the filter (the module docstring's update): the `FilterUpdate` from the
    last recursive `log_belief` (K,) and this tick's `IntentFeatures`."""
    weights = np.array([[settings.move_rate, settings.turn_rate, settings.silence_rate,
                         settings.heading_weight, settings.override_rate]])
    update = filter_update(np.asarray(log_belief, dtype=float)[np.newaxis], features,
                           weights, np.array([switch_probability(settings, period)]),
                           settings.max_probability, period)
    return FilterUpdate(update.log_belief[0], update.probabilities[0],
                        bool(update.clipped[0]))


def filter_update(log_beliefs, features, weights, hazards, max_probability, period):
    """`filter_step` for B operator models at once (the fit's sweep): `log_beliefs` (B, K)
    the recursive beliefs, `weights` (B, 4 or 5) the move, turn and silence rates, the
    heading's weight and (a fifth column) the override rate, `hazards` (B,) the switch
    probabilities. Returns a `FilterUpdate` of (B, K) arrays (`clipped` (B,))."""
    count = log_beliefs.shape[1]
    hazards = hazards[:, np.newaxis]
    with np.errstate(divide="ignore"):
        predicted = np.logaddexp(log_beliefs + np.log1p(-hazards), np.log(hazards / count))
    if features.acts:
        evidence = weights[:, 0:1] * features.moves + weights[:, 1:2] * features.turns
        if features.overridden >= 0 and weights.shape[1] > 4:
            evidence[:, features.overridden] -= weights[:, 4]
    else:  # silent: the robot's motion at the silence's rate
        evidence = weights[:, 2:3] * features.moves
    recursive, _ = clip_log_beliefs(_normalised(predicted + period * evidence),
                                    max_probability)
    pointed, clipped = clip_log_beliefs(
        _normalised(recursive + weights[:, 3:4] * features.headings), max_probability)
    return FilterUpdate(recursive, np.exp(pointed), clipped)


def _normalised(log_beliefs):
    largest = log_beliefs.max(axis=1, keepdims=True)
    return log_beliefs - (largest + np.log(np.exp(log_beliefs - largest).sum(axis=1,
                                                                           keepdims=True)))


def clip_log_beliefs(log_beliefs, max_probability):
    """`hindsight_optimization.clip_log_belief` row by row of (B, K) normalised log
    beliefs: each row's largest probability set to `max_probability` when above it, the
    excess spread evenly over the row's other goals. Returns the rows and which were
    clipped (B,); one goal alone is never clipped."""
    rows, count = log_beliefs.shape
    best = np.argmax(log_beliefs, axis=1)
    top = log_beliefs[np.arange(rows), best]
    clipped = (top > math.log(max_probability)) & (count > 1)
    if not clipped.any():
        return log_beliefs, clipped
    log_beliefs = log_beliefs.copy()
    excess = np.exp(top[clipped]) - max_probability
    with np.errstate(divide="ignore"):
        share = np.log(excess / (count - 1))[:, np.newaxis]
    log_beliefs[clipped] = np.logaddexp(log_beliefs[clipped], share)
    log_beliefs[np.flatnonzero(clipped), best[clipped]] = math.log(max_probability)
    return log_beliefs, clipped
