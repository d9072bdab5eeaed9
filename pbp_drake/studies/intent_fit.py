"""Fits the ``intent_filter`` estimator's operator model (`pbp_drake.core.intent_filter`) on
recorded trials: `python -m pbp_drake.studies.intent_fit FOLDER...`.

It replays the filter over the teleop trials of study folders (pilots' sub-folders
included) and scores a model by the mean log probability it gives the participant's target
at each tick; the fitted parameters are chosen over `GRIDS` by coordinate ascent (`fit`).
The defaults of `IntentFilterSettings` are its output on the tuning studies `make results`
runs; docs/concepts/goal-estimators.md says which, and why each source is fitted alone.
"""

import argparse
import dataclasses
import pathlib
import sys
import typing

import numpy as np

from pbp_drake.core.intent_filter import (
    IntentFeatures, IntentFilterSettings, filter_update, intent_features)
from pbp_drake.studies.trial_files import load_task_result, trial_seed

#: The values each fitted parameter is chosen from.
GRIDS = {"move_rate": (0.0, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0),
         "heading_weight": (0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 16.0),
         "turn_rate": (0.0, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0),
         "switch_rate": (0.003, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0)}
# The evidence sources, each fitted alone.
SOURCES = ("move_rate", "heading_weight", "turn_rate")
# The method whose trials are read: the operator's own motions alone.
TELEOP = "teleop"
MAX_ROUNDS = 6


class Replay(typing.NamedTuple):
    """One trial ready to replay: its features (each (T, K); `acts` (T,)), the target
    index at each tick (T,), and the control period (s)."""

    features: IntentFeatures
    targets: np.ndarray
    period: float


def teleop_trials(folders):
    """The (output folder, seed) of every teleop trial under `folders` (pilots included)."""
    found = []
    for folder in folders:
        folder = pathlib.Path(folder)
        if not folder.is_dir():
            raise ValueError(f"{folder}: no such folder")
        for record in sorted(folder.glob(f"**/trials/{TELEOP}/seed_*.json")):
            if (seed := trial_seed(record)) is not None:
                found.append((record.parents[2], seed))
    if not found:
        raise ValueError(f"no teleop trials under {', '.join(map(str, folders))} (a study "
                         "folder of `pbp-drake study --methods teleop`)")
    return found


def replay_of(result, min_speed):
    """A `Replay` of a trial's `TaskResult`: the motion is the operator's command while it
    acts and the hand's own velocity (from its positions) while it is silent."""
    times, positions = result.times, result.ee_positions
    period = float(np.median(np.diff(times)))
    hand_velocities = np.vstack([np.zeros(3), np.diff(positions, axis=0) / period])
    commands = result.operator_commands
    ticks = []
    for tick in range(len(times)):
        active = bool(result.operator_active[tick])
        motion = commands[tick, :3] if active else hand_velocities[tick]
        ticks.append(intent_features(result.objects, positions[tick], motion,
                                     float(result.headings[tick]),
                                     float(commands[tick, 3]) if active else 0.0, period,
                                     min_speed, active))
    # Teleop shows no goal: nothing is overridden.
    moves, headings, turns, acts, _ = zip(*ticks)
    return Replay(IntentFeatures(np.array(moves), np.array(headings), np.array(turns),
                                 np.array(acts)), np.asarray(result.targets, dtype=int), period)


def scores(replays, models):
    """Each `IntentFilterSettings` of `models`' mean log probability of the target (nats)."""
    weights = np.array([[m.move_rate, m.turn_rate, m.silence_rate, m.heading_weight]
                        for m in models])
    totals = np.zeros(len(models))
    for replay in replays:
        count = replay.features.moves.shape[1]
        hazards = np.array([-np.expm1(-m.switch_rate * replay.period) for m in models])
        log_beliefs = np.full((len(models), count), -np.log(count))
        score, ticks = np.zeros(len(models)), 0
        for tick, target in enumerate(replay.targets):
            features = IntentFeatures(*(values[tick] for values in replay.features[:4]))
            update = filter_update(log_beliefs, features, weights, hazards,
                                   models[0].max_probability, replay.period)
            log_beliefs = update.log_belief
            if 0 <= target < count:
                score += np.log(update.probabilities[:, target])
                ticks += 1
        totals += score / max(ticks, 1)
    return totals / len(replays)


def ascend(replays, start, names, log=None, label=""):
    """`(settings, score)`: coordinate ascent from `start` over the `GRIDS` of `names`, one
    parameter's grid at a time in one batched replay, until a round changes nothing."""
    best = dataclasses.replace(start)
    best_score = float(scores(replays, [best])[0])
    for round_number in range(1, MAX_ROUNDS + 1):
        changed = False
        for name in names:
            models = [dataclasses.replace(best, **{name: value}) for value in GRIDS[name]]
            values = scores(replays, models)
            index = int(np.argmax(values))
            if log:
                print(f"{label}round {round_number} {name}: " + ", ".join(
                    f"{value:g}: {score:.4f}" for value, score in zip(GRIDS[name], values)),
                    file=log)
            if values[index] > best_score + 1e-12:
                best, best_score, changed = models[index], float(values[index]), True
        if not changed:
            break
    return best, best_score


def fit(replays, log=None):
    """`(settings, score)`: each of `SOURCES` fitted alone (the motion and the turns each
    with a switch rate of its own), then the switch rate with all of them."""
    fitted = {}
    for source in SOURCES:
        alone = dataclasses.replace(IntentFilterSettings(), **{name: 0.0 for name in SOURCES})
        names = (source,) if source == "heading_weight" else (source, "switch_rate")
        settings, _ = ascend(replays, alone, names, log, f"{source} alone: ")
        fitted[source] = getattr(settings, source)
    return ascend(replays, dataclasses.replace(IntentFilterSettings(), **fitted),
                  ("switch_rate",), log, "all: ")


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m pbp_drake.studies.intent_fit",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+", help="study folders whose teleop trials the "
                        "model is fitted on")
    args = parser.parse_args(argv)
    defaults = IntentFilterSettings()
    try:
        trials = teleop_trials(args.folders)
        replays = [replay_of(load_task_result(output, TELEOP, seed), defaults.min_speed)
                   for output, seed in trials]
    except ValueError as error:
        print(f"intent_fit: {error}", file=sys.stderr)
        return 2
    print(f"{len(replays)} teleop trials, {sum(len(r.targets) for r in replays)} ticks")
    fitted, score = fit(replays, log=sys.stdout)
    uniform = float(np.mean([-np.log(r.features.moves.shape[1]) for r in replays]))
    print(f"mean log probability of the target: {score:.4f} nats (uniform: {uniform:.4f}; "
          f"the shipped defaults: {float(scores(replays, [defaults])[0]):.4f})")
    print("intent_filter: {" + ", ".join(f"{name}: {getattr(fitted, name):g}"
                                        for name in GRIDS) + "}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
