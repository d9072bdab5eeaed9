"""Runaway confidence, measured: `python -m pbp_drake_bench.runaway`.

A scripted operator (Aronson and Short's test) first heads for a wrong object for `hold`
seconds, driving the hand at it and pointing the hand at it, and then turns the hand to its
true target and drives there. Every recursive estimator is replayed on the same script
(pure NumPy, tick by tick): the ``intent_filter`` (`pbp_drake.core.intent_filter`, the
shipped settings), PBP's ``maxent_command`` (`pbp_drake.core.maxent_command`, HOP's
constants) and HOP's published posterior (`hindsight_optimization.update_posterior`). For
each hold, the table gives the recovery time (from the turn until the target is the most
probable goal for good) and the share of the ticks the posterior sat at its clip. A belief
that runs away takes longer to recover the longer the operator held the wrong goal; the
intent filter's hazard bounds the time.

The scene: the hand starts at the origin at 0.7 m pointing along +x; ten objects lie on the
line x = 1.2 m, 0.2 m apart (y from -0.9 to 0.9 m), the wrong one at y = 0.3 m, the target
at y = -0.3 m. The operator moves at 0.12 m/s and turns at 0.8 rad/s (the reaching task's
virtual participant's speeds), 30 ticks a second (the task's control period), and stays
still and silent once within 5 cm of the object it heads for.
"""

import argparse
import math
import typing

import numpy as np

from pbp_drake.core.hindsight_optimization import (
    HopSettings, hop_targets, uniform_log_belief, update_posterior)
from pbp_drake.core.intent_filter import IntentFilterSettings, filter_step, intent_features
from pbp_drake.core.maxent_command import intent_evidence, update_intent_posterior

PERIOD = 0.03
SPEED = 0.12
YAW_RATE = 0.8
ARRIVED = 0.05
OBJECTS = np.column_stack([np.full(10, 1.2), np.linspace(-0.9, 0.9, 10), np.full(10, 0.7)])
WRONG, TARGET = 6, 3  # y = 0.3 and y = -0.3
START = np.array([0.0, 0.0, 0.7])
HOLDS = (2.0, 5.0, 10.0, 20.0)
# After the turn the script runs this long (s) at most: the target is reached well before.
AFTER = 15.0
ESTIMATORS = ("intent_filter", "maxent_command", "hop")


class Tick(typing.NamedTuple):
    """One tick of the script: the hand's `position` and `heading`, the operator's
    `command` (3, m/s) and `yaw_rate`, whether it `acts`, and the `goal` it heads for."""

    position: np.ndarray
    heading: float
    command: np.ndarray
    yaw_rate: float
    acts: bool
    goal: int


def script(hold):
    """The ticks of the script with the wrong object held `hold` seconds."""
    position, heading, ticks = START.copy(), 0.0, []
    for step in range(int(round((hold + AFTER) / PERIOD))):
        goal = WRONG if step * PERIOD < hold else TARGET
        offset = OBJECTS[goal] - position
        bearing = math.atan2(offset[1], offset[0])
        error = (bearing - heading + math.pi) % (2 * math.pi) - math.pi
        yaw_rate = float(np.clip(error / PERIOD, -YAW_RATE, YAW_RATE))
        distance = float(np.linalg.norm(offset))
        command = (SPEED * offset / distance if distance > ARRIVED else np.zeros(3))
        acts = bool(distance > ARRIVED or yaw_rate != 0.0)
        ticks.append(Tick(position.copy(), heading, command, yaw_rate, acts, goal))
        position = position + command * PERIOD
        heading += yaw_rate * PERIOD
    return ticks


def replay(estimator, ticks):
    """`(probabilities (T, K), clipped (T,))` of `estimator` over the ticks: the hand's own
    velocity is the operator's command (nothing else moves it here)."""
    hop = HopSettings()
    settings = IntentFilterSettings()
    targets = hop_targets(OBJECTS)
    log_belief = uniform_log_belief(len(OBJECTS))
    probabilities, clipped = [], []
    for tick in ticks:
        if estimator == "intent_filter":
            update = filter_step(settings, log_belief, intent_features(
                OBJECTS, tick.position, tick.command, tick.heading, tick.yaw_rate, PERIOD,
                settings.min_speed, tick.acts), PERIOD)
        elif estimator == "maxent_command":
            update = update_intent_posterior(hop, targets, log_belief, intent_evidence(
                hop, targets, tick.position, tick.command, SPEED, tick.heading,
                tick.yaw_rate))
        else:
            update = update_posterior(hop, targets, log_belief, tick.position, tick.command)
        log_belief = update.log_belief
        probabilities.append(update.probabilities)
        clipped.append(update.clipped)
    return np.array(probabilities), np.array(clipped)


class Recovery(typing.NamedTuple):
    """What one replay measured: `recovery` (s from the turn until the target is the most
    probable goal for good; None if never) and `clipped_share` (of all ticks)."""

    recovery: typing.Optional[float]
    clipped_share: float


def measure(estimator, hold):
    """The `Recovery` of `estimator` with the wrong object held `hold` seconds."""
    ticks = script(hold)
    probabilities, clipped = replay(estimator, ticks)
    turn = int(round(hold / PERIOD))
    wrong_after = np.flatnonzero(np.argmax(probabilities[turn:], axis=1) != TARGET)
    if len(wrong_after) and wrong_after[-1] == len(ticks) - turn - 1:
        recovery = None
    else:
        recovery = (wrong_after[-1] + 1 if len(wrong_after) else 0) * PERIOD
    return Recovery(recovery, float(clipped.mean()))


def table(holds=HOLDS, estimators=ESTIMATORS):
    """The Markdown table of every estimator at every hold."""
    lines = ["| estimator | " + " | ".join(f"held {hold:g} s" for hold in holds) + " |",
             "|---|" + "---|" * len(holds)]
    for estimator in estimators:
        cells = []
        for hold in holds:
            result = measure(estimator, hold)
            recovery = ("never" if result.recovery is None else f"{result.recovery:.2f} s")
            cells.append(f"{recovery} ({100 * result.clipped_share:.0f} % clipped)")
        lines.append(f"| {estimator} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m pbp_drake_bench.runaway",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--holds", default=",".join(f"{hold:g}" for hold in HOLDS),
                        help="seconds the wrong object is held, comma-separated")
    args = parser.parse_args(argv)
    try:
        holds = tuple(float(hold) for hold in args.holds.split(","))
    except ValueError:
        parser.error(f"--holds must be numbers separated by commas, got {args.holds!r}")
    if any(not (math.isfinite(hold) and hold >= 0.0) for hold in holds):
        parser.error(f"--holds must be finite numbers >= 0, got {args.holds!r}")
    print(table(holds))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
