"""The ``maxent_command`` goal estimator's likelihood, in pure NumPy: HOP's maximum-entropy
goal posterior (`pbp_drake.core.hindsight_optimization`) made for PBP's operator, who
corrects, turns the hand to point at a goal, and otherwise lets the robot go on. Every
control tick each goal g gains `l_g = l_move_g + l_turn_g` (`move_evidence`,
`turn_evidence`), then the belief is normalised and clipped as HOP's posterior. The terms
and why: docs/concepts/goal-estimators.md, "What each one reads"; the constants are HOP's
(the scenario's `hop` section) and the task's nominal speed, none fitted."""

import math
import typing

import numpy as np

from pbp_drake.core.hindsight_optimization import (
    PosteriorUpdate, clip_log_belief, goal_minimum, log_normalised, target_geometry,
    target_values)
from pbp_drake.core.intent_filter import floor_bearings, turn_progress


class IntentEvidence(typing.NamedTuple):
    """One tick's evidence per goal: `moves` (K,) and `turns` (K,) (zeros without a turn
    or with orientations), in nats."""

    moves: np.ndarray
    turns: np.ndarray

    @property
    def total(self):
        return self.moves + self.turns


def move_evidence(settings, targets, position, velocity, orientation=None,
                  angular_velocity=None):
    """`l_move_g = V_g(x) - V_g(x + w dt)` (K,): each goal's value dropped by one step of
    the cost model under the implicit command `w` = (`velocity`, `angular_velocity`): the
    operator's while it acts, the hand's own while it is silent."""
    now, after = target_values(settings, target_geometry(
        settings, targets, position, velocity, orientation, angular_velocity))
    return goal_minimum(now, targets)[0] - goal_minimum(after, targets)[0]


def turn_evidence(settings, targets, position, heading, yaw_rate, speed):
    """`l_turn_g = (alpha + c0) s dt (|e_g| - |e'_g|) / |r dt|` (K,), `e_g` goal g's floor
    bearing minus the hand's `heading` (rad), `e'_g` the same after the operator's
    `yaw_rate` r (rad/s) for `dt`, `s` the nominal `speed` (m/s); zeros while r is 0."""
    position = np.asarray(position, dtype=float).reshape(-1)
    if position.shape != (3,) or not np.isfinite(position).all():
        raise ValueError(f"position must be 3 finite numbers, got {position.tolist()}")
    if not (math.isfinite(heading) and math.isfinite(yaw_rate)):
        raise ValueError(f"heading and yaw_rate must be finite, got {heading!r}, {yaw_rate!r}")
    if not (math.isfinite(speed) and speed > 0.0):
        raise ValueError(f"speed must be positive, got {speed!r}")
    turn = yaw_rate * settings.cost_time_step
    if turn == 0.0:
        return np.zeros(targets.goal_count)
    has_bearing, error = floor_bearings(targets.positions[:, :2] - position[:2], heading)
    per_target = turn_progress(has_bearing, error, turn)
    scale = (settings.translation_gain + settings.translation_constant) * speed * \
        settings.cost_time_step
    # A goal's turn evidence is its best target's (each goal has one in the position tasks).
    return -scale * goal_minimum(-per_target, targets)[0]


def intent_evidence(settings, targets, position, move_velocity, speed, heading=None,
                    yaw_rate=0.0, orientation=None, move_angular_velocity=None):
    """One tick's `IntentEvidence`: the moves under the implicit command (`move_velocity`,
    and with orientations `move_angular_velocity`; the caller passes the operator's command
    while the operator acts, the hand's executed velocity while silent) and, for targets
    without orientations and a `heading`, the turns of the operator's `yaw_rate`."""
    moves = move_evidence(settings, targets, position, move_velocity, orientation,
                          move_angular_velocity)
    if targets.orientations is not None or heading is None:
        return IntentEvidence(moves, np.zeros(targets.goal_count))
    return IntentEvidence(moves, turn_evidence(settings, targets, position, heading,
                                               yaw_rate, speed))


def update_intent_posterior(settings, targets, log_belief, evidence):
    """`log b_t = log b_{t-1} + l`, normalised, then clipped at `settings.max_probability`
    (a `PosteriorUpdate`, whose `costs` is None)."""
    log_belief = np.asarray(log_belief, dtype=float)
    if log_belief.shape != (targets.goal_count,) or not np.isfinite(log_belief).all():
        raise ValueError(f"log_belief must be {targets.goal_count} finite numbers, got "
                         f"{log_belief!r}")
    updated, clipped = clip_log_belief(log_normalised(log_belief + evidence.total),
                                       settings.max_probability)
    return PosteriorUpdate(updated, np.exp(updated), clipped, None)
