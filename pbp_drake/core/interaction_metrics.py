"""How an operator and a shared-control method worked together over one task, from the
task's per-tick series (`InteractionMetrics` defines each metric): how much the operator
gave, how well the hand did what it asked, how early and how often the method named the
target. `InteractionMeter` takes the series whole or chunk by chunk (a streamed run);
`interaction_metrics` is the same on whole arrays."""

import dataclasses
import math

import numpy as np

from pbp_drake.core.hand_over import check_limit

# Below this speed (m/s) a command or the hand's motion has no direction to compare.
STILL_SPEED = 1e-3


def idle_ratio(intervention_ratio):
    """The share of the task's ticks with no operator input, counted on the ticks the task
    monitor counts for `intervention_ratio` (every control tick from the first to the one
    that ended the task): `1 - intervention_ratio`, None when that is None."""
    return None if intervention_ratio is None else 1.0 - float(intervention_ratio)


@dataclasses.dataclass(frozen=True)
class InteractionMetrics:
    """The interaction metrics of one task (each defined in docs/tasks/studies.md, "How the
    operator and the method worked together").

    - `input_integral` (m): `sum_k active_k |v_k| control_period`; `turn_input_integral`
      (rad) the same of its turning (the yaw rate's magnitude, or the angular velocity's).
    - `agreement`: while the operator acts, the mean cosine between its commanded velocity
      `v_k` and the hand's executed `(p_{k+1} - p_k) / control_period`, ticks where either
      is slower than `STILL_SPEED` (and the last) left out; None when none is left.
    - `prediction_accuracy`: the share of the ticks whose named goal is the current target;
      None when no tick names a goal (a method that shows no intent).
    - `time_to_prediction` (s): per target switch, the first target included, the time to
      the first tick from which the named goal is the new target up to the next switch or
      the end; None for a switch never so named, or as a whole when no tick names a goal.
    """

    input_integral: float
    turn_input_integral: float
    agreement: float | None
    prediction_accuracy: float | None
    time_to_prediction: tuple | None

    @property
    def mean_time_to_prediction(self):
        """The mean of `time_to_prediction` over the switches that got one, or None."""
        named = [t for t in self.time_to_prediction or () if t is not None]
        return math.fsum(named) / len(named) if named else None

    @property
    def unpredicted_switches(self):
        """How many switches the method never named, or None where no tick names a goal."""
        if self.time_to_prediction is None:
            return None
        return sum(t is None for t in self.time_to_prediction)

    def fields(self):
        """The metrics by name, the derived two included, as plain Python values (a list
        for `time_to_prediction`)."""
        latencies = self.time_to_prediction
        return {"input_integral": self.input_integral,
                "turn_input_integral": self.turn_input_integral,
                "agreement": self.agreement,
                "prediction_accuracy": self.prediction_accuracy,
                "time_to_prediction": None if latencies is None else list(latencies),
                "mean_time_to_prediction": self.mean_time_to_prediction,
                "unpredicted_switches": self.unpredicted_switches}


class InteractionMeter:
    """`InteractionMetrics` of a series fed whole or in consecutive chunks (`add`): what
    crosses a chunk boundary (the last tick's hand position and command, the current
    switch and how long its target has been named) is carried over."""

    def __init__(self, control_period):
        self._period = check_limit(control_period, "control_period", "s")
        self._input = self._turn = 0.0
        self._cosines, self._cosine_count = 0.0, 0
        self._last = None  # (position, velocity command, active) of the last tick fed
        self._ticks = self._named_ticks = 0
        self._shown = False
        self._target = None
        self._switch_time = None
        self._named_since = None  # when the target began to be named without a break
        self._latencies = []

    def add(self, times, operator_velocity, operator_turn, operator_active, hand_positions,
            predicted_goals, targets):
        """Feeds the next ticks' series (as `interaction_metrics` takes them)."""
        times = _series("times", times, np.size(times)).reshape(-1)
        if len(times) == 0:
            return
        velocity = _series("operator_velocity", operator_velocity, len(times)).reshape(
            len(times), -1)
        turn = _series("operator_turn", operator_turn, len(times))
        turn = np.abs(turn) if turn.ndim == 1 else np.linalg.norm(turn, axis=1)
        active = _series("operator_active", operator_active, len(times)).astype(bool).reshape(-1)
        positions = _series("hand_positions", hand_positions, len(times)).reshape(
            len(times), -1)
        if positions.shape[1] != velocity.shape[1]:
            raise ValueError(f"hand_positions has {positions.shape[1]} axes and "
                             f"operator_velocity {velocity.shape[1]}; expected the same axes")
        for name, goals in (("predicted_goals", predicted_goals), ("targets", targets)):
            _series(name, goals, len(times))
        speeds = np.linalg.norm(velocity, axis=1)
        self._input += float(speeds[active].sum()) * self._period
        self._turn += float(turn[active].sum()) * self._period
        self._add_agreement(velocity, active, positions)
        self._add_predictions(times, np.asarray(predicted_goals, int).reshape(-1),
                              np.asarray(targets, int).reshape(-1))

    def _add_agreement(self, velocity, active, positions):
        if self._last is not None:
            position, command, acting = self._last
            positions = np.vstack([position, positions])
            velocity = np.vstack([command, velocity])
            active = np.concatenate([[acting], active])
        self._last = (positions[-1].copy(), velocity[-1].copy(), bool(active[-1]))
        # Tick k's command against the hand's motion from t_k to t_{k+1}.
        hand = np.diff(positions, axis=0) / self._period
        command = velocity[:-1]
        hand_speed = np.linalg.norm(hand, axis=1)
        command_speed = np.linalg.norm(command, axis=1)
        used = active[:-1] & (hand_speed >= STILL_SPEED) & (command_speed >= STILL_SPEED)
        cosines = (np.einsum("ij,ij->i", command[used], hand[used])
                   / (command_speed[used] * hand_speed[used]))
        self._cosines += math.fsum(cosines)
        self._cosine_count += int(used.sum())

    def _add_predictions(self, times, predicted, targets):
        named = predicted == targets
        self._ticks += len(times)
        self._named_ticks += int(named.sum())
        self._shown = self._shown or bool(np.any(predicted >= 0))
        before = np.concatenate([[-1 if self._target is None else self._target], targets[:-1]])
        switches = np.flatnonzero(targets != before)
        if self._target is None:
            switches = np.union1d([0], switches)
        starts = set(switches.tolist())
        bounds = sorted(starts | {0, len(times)})
        for begin, end in zip(bounds, bounds[1:]):
            if begin in starts:
                self._close_switch()
                self._target, self._switch_time, self._named_since = (
                    int(targets[begin]), float(times[begin]), None)
            missed = np.flatnonzero(~named[begin:end])
            if len(missed) == 0:
                if self._named_since is None:
                    self._named_since = float(times[begin])
            else:
                after = begin + int(missed[-1]) + 1
                self._named_since = float(times[after]) if after < end else None

    def _close_switch(self):
        if self._switch_time is not None:
            self._latencies.append(self._latency())

    def _latency(self):
        return None if self._named_since is None else self._named_since - self._switch_time

    def metrics(self):
        """The `InteractionMetrics` of every tick fed so far."""
        latencies = None
        if self._shown:
            latencies = tuple(self._latencies) + (
                (self._latency(),) if self._switch_time is not None else ())
        return InteractionMetrics(
            input_integral=self._input, turn_input_integral=self._turn,
            agreement=(self._cosines / self._cosine_count if self._cosine_count else None),
            prediction_accuracy=(self._named_ticks / self._ticks
                                 if self._shown and self._ticks else None),
            time_to_prediction=latencies)


def _series(name, values, ticks):
    """`values` as a float array; ValueError naming `name` unless it holds one row of finite
    numbers per tick (`ticks`): a series of another length would be read against the wrong
    ticks, and a NaN would make its metric NaN without a word."""
    values = np.asarray(values, float)
    rows = len(values) if values.ndim else 1
    if rows != ticks:
        raise ValueError(f"{name} has {rows} rows; expected one per tick of times ({ticks})")
    if not np.isfinite(values).all():
        raise ValueError(f"{name} holds NaN or infinite values; expected finite numbers")
    return values


def interaction_metrics(times, control_period, operator_velocity, operator_turn,
                        operator_active, hand_positions, predicted_goals, targets):
    """The `InteractionMetrics` of one task's whole series, one row per control tick of
    `control_period` s, the command of tick k held until tick k + 1: `times` (T,) s, the
    operator's translational command (T, 3) m/s (world frame) and turning (T,) (a yaw
    rate) or (T, 3) (an angular velocity) rad/s, whether it acted (T,), the hand's
    positions (T, 3) m, the named goal (T,) (-1: none) and the target (T,)."""
    meter = InteractionMeter(control_period)
    meter.add(times, operator_velocity, operator_turn, operator_active, hand_positions,
              predicted_goals, targets)
    return meter.metrics()
