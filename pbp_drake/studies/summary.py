"""A study's summary, from its trial files only, and the one definition of the ideal alpha.
It holds only values from the trial files, in a fixed order, rounded: the same bytes for
any `--jobs` and either backend.
"""

import dataclasses
import math
import pathlib

import numpy as np

from pbp_drake.core.participant_impairment import ParticipantImpairment
from pbp_drake.scenarios import DynamicObstacles, parse_method_label
from pbp_drake.studies.intervals import INTERACTION_MEANS, mean_interval
from pbp_drake.studies.trial_files import METHOD_COMPARISON, trial_paths

# Collision-ratio histogram: 20 bins of 0.05 over [0, 1] (the last bin includes 1).
HISTOGRAM_EDGES = tuple(round(0.05 * i, 2) for i in range(21))
SIGNIFICANT_DIGITS = 12


# ---------------------------------------------------------------------------------------------
# The ideal alpha


def ideal_alpha(outcomes, does_task):
    """The paper's ideal arbitration (section IV-A): the highest alpha of `outcomes`
    (`(alpha, outcome)` pairs) whose outcome `does_task` (a lower one takes autonomy from
    the robot for nothing), or None when none does."""
    good = [alpha for alpha, outcome in outcomes if does_task(outcome)]
    return max(good) if good else None


# Doing the HSR task: this success rate, and where collisions are measured, most trials
# without any (the bar PBP has to meet in the obstacle task).
IDEAL_ALPHA_SUCCESS = 0.95
HSR_CRITERION = (f"highest alpha with success >= {IDEAL_ALPHA_SUCCESS:.0%} and, "
                 "where collisions are measured, most trials free of them")


def does_the_hsr_task(entry):
    """Whether a method's summary entry does the HSR task (see IDEAL_ALPHA_SUCCESS)."""
    ran = entry["trials"] - entry["errors"]
    does_task = (entry["success_rate"] is not None
                 and entry["success_rate"] >= IDEAL_ALPHA_SUCCESS)
    # Absent or None where the task measures no collisions (see measures_collisions).
    if entry.get("collision_free_trials") is not None:
        does_task = does_task and 2 * entry["collision_free_trials"] > ran
    return does_task


def collision_free(collision_ratio):
    """The 2-D alpha study's task: pass the obstacles without touching one."""
    return collision_ratio == 0.0


def arbitration(methods):
    """`{"alphas", "ideal_alpha", "criterion"}` over the `fixed_alpha=A` methods, or None."""
    swept = []
    for label, entry in methods.items():
        _, alpha = parse_method_label(label)
        if alpha is not None:  # a method with its weight, `fixed_alpha=A`
            swept.append((alpha, entry))
    if not swept:
        return None
    return {"alphas": sorted(alpha for alpha, _ in swept),
            "ideal_alpha": ideal_alpha(swept, does_the_hsr_task),
            "criterion": HSR_CRITERION}


# ---------------------------------------------------------------------------------------------
# The summary


def _round(value):
    if value is None or not math.isfinite(value):
        return None
    return float(f"{value:.{SIGNIFICANT_DIGITS}g}")


def mean_std(values):
    """`{"mean", "std"}` (population std) of the finite values, rounded; None for none, and
    "std" None for one (a single trial's spread is unknown, not 0)."""
    values = [v for v in values if v is not None and math.isfinite(v)]
    if not values:
        return {"mean": None, "std": None}
    mean = math.fsum(values) / len(values)
    if len(values) == 1:
        return {"mean": _round(mean), "std": None}
    variance = math.fsum((v - mean) ** 2 for v in values) / len(values)
    return {"mean": _round(mean), "std": _round(math.sqrt(variance))}


def max_mean(values):
    """`{"max", "mean"}` of the finite values, rounded; None for none."""
    values = [v for v in values if v is not None and math.isfinite(v)]
    if not values:
        return {"max": None, "mean": None}
    return {"max": _round(max(values)), "mean": _round(math.fsum(values) / len(values))}


def mean_with_interval(values, within):
    """`mean_std` of the finite values, their "count" and the "interval" of the mean
    (`intervals.mean_interval` within `within`; None for fewer than two), rounded."""
    values = [v for v in values if v is not None and math.isfinite(v)]
    entry = {**mean_std(values), "count": len(values)}
    interval = mean_interval(entry["mean"], entry["std"], len(values), within)
    entry["interval"] = None if interval is None else [_round(v) for v in interval]
    return entry


#: The trial field a summary entry is the mean of, where the two names differ (a trial's
#: `time_to_prediction` lists one latency per switch; its mean is the value summarized).
TRIAL_VALUE = {"time_to_prediction": "mean_time_to_prediction"}


def interaction_entries(ran):
    """The entries of the interaction metrics (`INTERACTION_MEANS`) that the records of a
    method's trials that ran hold, each `mean_with_interval`; `time_to_prediction` adds the
    count of `switches` and of those never named (`unpredicted_switches`)."""
    entries = {}
    for name, _, _, within in INTERACTION_MEANS:
        field = TRIAL_VALUE.get(name, name)
        if any(field in record for record in ran):
            entries[name] = mean_with_interval([r.get(field) for r in ran], within)
    if "time_to_prediction" in entries:
        lists = [r.get("time_to_prediction") for r in ran]
        lists = [latencies for latencies in lists if latencies is not None]
        entries["time_to_prediction"].update(
            switches=sum(len(latencies) for latencies in lists),
            unpredicted_switches=sum(t is None for latencies in lists for t in latencies))
    return entries


def collision_histogram(ratios):
    """Counts of collision ratios in the bins of HISTOGRAM_EDGES (the last includes 1)."""
    counts = [0] * (len(HISTOGRAM_EDGES) - 1)
    for ratio in ratios:
        index = int(np.searchsorted(HISTOGRAM_EDGES, ratio, side="right")) - 1
        counts[min(max(index, 0), len(counts) - 1)] += 1
    return counts


def measures_collisions(study, records, output):
    """Whether the study's task measures collisions (the obstacle task; reaching records a
    collision ratio of 0 that means "not measured"): by the scenario study.json holds, else
    by an `in_collision` column in its trials' CSV files."""
    content = study.get("scenario_content")
    if isinstance(content, dict):
        task = content.get("task")
        return isinstance(task, dict) and task.get("!type") == DynamicObstacles.__name__
    for (method, _), record in records.items():
        if record is None or not record.get("time_series"):
            continue
        try:
            with open(trial_paths(output, method, record["seed"])[1]) as stream:
                return "in_collision" in stream.readline().strip().split(",")
        except OSError:
            continue
    return False


# An impairment field that matters only beside another: listed with it.
_GOES_WITH = {"command_noise_time": "command_noise", "mistake_time": "mistake_probability"}


def virtual_participant(study):
    """How the study's virtual participant was impaired, from its study.json: `{"condition":
    the `--participant-condition` or None, "impairment": the fields off their defaults and
    the times that go with them}`; None when it was not impaired."""
    content = study.get("scenario_content")
    operator = content.get("operator") if isinstance(content, dict) else None
    given = operator.get("impairment") if isinstance(operator, dict) else None
    condition = study.get("participant_condition")
    condition = condition if isinstance(condition, str) else None
    defaults = dataclasses.asdict(ParticipantImpairment())
    given = given if isinstance(given, dict) else {}
    changed = {name for name, value in given.items()
               if name in defaults and value != defaults[name]}
    acting = {name: given[name] for name in defaults
              if name in changed or _GOES_WITH.get(name) in changed}
    if not acting and condition is None:
        return None
    return {"condition": condition, "impairment": acting}


def summarize(study, records, damaged, output):
    """The summary.json of `read_study`'s result. Per method: the counts of trials, errors,
    missing and damaged; the success rate over the trials on disk; over those that ran
    without error, `mean_std` of intervention ratio and task time, `max_mean` of the peaks
    and, where recorded or measured, the posterior's clip, `interaction_entries` and the
    collision ratio; then the damaged files and the ideal alpha (`arbitration`)."""
    summary = {"study": METHOD_COMPARISON, "scenario": study["scenario"],
               "scenario_hash": study["scenario_hash"], "trials": study["trials"],
               "seed": study["seed"], "split": study.get("split"),
               "seeds": [study["seed"], study["seed"] + study["trials"] - 1]}
    participant = virtual_participant(study)
    if participant is not None:
        summary["virtual_participant"] = participant
    collisions = measures_collisions(study, records, output)
    summary["measures_collisions"] = collisions
    if collisions:
        summary["collision_histogram_edges"] = list(HISTOGRAM_EDGES)
    summary["methods"] = {}
    for method in study["methods"]:
        rows = [records[(method, trial)] for trial in range(study["trials"])]
        present = [r for r in rows if r is not None]
        broken = {d.key for d in damaged if d.key is not None and d.key[0] == method}
        ran = [r for r in present if r["error"] is None]
        summary["methods"][method] = entry = {
            "trials": len(present),
            "missing": len(rows) - len(present) - len(broken),
            "damaged": len(broken),
            "errors": len(present) - len(ran),
            "error_seeds": [r["seed"] for r in present if r["error"] is not None],
            "success_rate": _round(sum(bool(r["success"]) for r in present) / len(present))
            if present else None,
            "intervention_ratio": mean_std([r["intervention_ratio"] for r in ran]),
            "task_time": mean_std([r["task_time"] for r in ran]),
            "peak_hand_speed": max_mean([r.get("peak_hand_speed") for r in ran]),
            "peak_command_acceleration": max_mean(
                [r.get("peak_command_acceleration") for r in ran]),
        }
        entry.update(interaction_entries(ran))
        clipped = [r.get("posterior_clipped_ratio") for r in ran]
        if any(value is not None for value in clipped):
            entry["posterior_clipped_ratio"] = mean_std(clipped)
        if collisions:
            ratios = [r["collision_ratio"] for r in ran if r["collision_ratio"] is not None]
            entry["collision_ratio"] = {**mean_std(ratios),
                                        "histogram": collision_histogram(ratios)}
            entry["collision_free_trials"] = (sum(ratio == 0.0 for ratio in ratios)
                                              if ratios else None)
    summary["damaged"] = [{"file": str(pathlib.Path(d.path).relative_to(output)),
                           "problem": d.problem} for d in damaged]
    swept = arbitration(summary["methods"])
    if swept is not None:
        summary["arbitration"] = swept
    return summary
