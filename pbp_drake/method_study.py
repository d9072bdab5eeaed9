"""Comparing methods on the same seeded HSR scenes: `pbp-drake study diagrams/hsr_reach.yaml`."""

import dataclasses
import json
import pathlib
import time

import numpy as np

from pbp_drake.task_run import run_task

TRIAL_FIELDS = ("method", "trial", "seed", "success", "task_time", "intervention_ratio",
                "switches", "error")


def run_method_comparison(scenario, methods, trials, seed, output, progress=None):
    """Runs `trials` scenes (seeds `seed`, `seed + 1`, ...) with each method and writes
    `output/summary.json`, `output/trials.json` and `output/fig_reach_study.png`.

    Every method sees the same scenes and the same participant noise: trial i draws both
    from seed `seed + i`. A trial that raises is recorded as failed with its error.
    Returns the summary dict.
    """
    output = pathlib.Path(output)
    output.mkdir(parents=True, exist_ok=True)
    records = []
    started = time.monotonic()
    total = len(methods) * trials
    for method in methods:
        for trial in range(trials):
            trial_seed = seed + trial
            record = {"method": method, "trial": trial, "seed": trial_seed, "error": None}
            try:
                result = run_task(dataclasses.replace(scenario, method=method, seed=trial_seed))
                record.update(success=result.success, task_time=result.task_time,
                              intervention_ratio=result.intervention_ratio,
                              switches=result.switches)
            except Exception as error:  # a broken trial must not lose the study
                record.update(success=False, task_time=float("nan"),
                              intervention_ratio=float("nan"), switches=0,
                              error=f"{type(error).__name__}: {error}")
            records.append(record)
            if progress is not None:
                progress(len(records), total, record, time.monotonic() - started)
    summary = summarize(records, methods, scenario, trials, seed)
    (output / "trials.json").write_text(json.dumps(records, indent=1) + "\n")
    (output / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    from pbp_drake.figures import plot_method_comparison

    plot_method_comparison(records, methods, output / "fig_reach_study.png")
    return summary


def summarize(records, methods, scenario, trials, seed):
    """Per method: success rate, and mean and std of intervention ratio and task time over
    all trials (a failed trial counts with the time it ran, the time limit)."""
    summary = {"study": "method_comparison", "scenario": scenario.name, "trials": trials,
               "seed": seed, "methods": {}}
    for method in methods:
        rows = [r for r in records if r["method"] == method]
        entry = {"success_rate": float(np.mean([r["success"] for r in rows])),
                 "errors": sum(r["error"] is not None for r in rows)}
        for field in ("intervention_ratio", "task_time"):
            values = np.array([r[field] for r in rows], float)
            values = values[np.isfinite(values)]
            entry[field] = {"mean": float(values.mean()) if len(values) else float("nan"),
                            "std": float(values.std()) if len(values) else float("nan")}
        summary["methods"][method] = entry
    return summary
