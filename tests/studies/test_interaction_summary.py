"""The interaction metrics in a study's summary and results: each method's mean, std, count
and 95 % interval (Student's t, as SciPy computes it) over the trials with a value; the
switches never named summed over the trials; "-" for a method that names no goal (teleop)
and for trial files written before the metrics (no entry at all).

The study folder is written without simulating (the shipped reach scenario's study.json,
trial files of a few ticks with hand-made metrics), then rebuilt with `pbp-drake report`."""

import json

import numpy as np
import pytest
import scipy.stats

from pbp_drake.cli import main
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.studies.trial_files import (
    INTERACTION_METRICS, scenario_hash, time_series_columns, trial_record, write_study,
    write_trial_files)

# Its tests share fixtures that take seconds to make: `make test-fast` leaves it out.
pytestmark = pytest.mark.slow

METHODS = ("pbp_alternated", "teleop", "hop")
# Per trial of PBP-Alt: input (m), agreement, each switch's time to prediction (s).
INPUT = (0.2, 0.4, 0.6)
AGREEMENT = (0.5, -0.5, 1.0)
LATENCIES = ([0.3, None, 0.9], [0.6, 0.6, 0.6], [None, None, None])


def _csv(ticks=3):
    columns = time_series_columns(False)
    integers = {"operator_active", "selected_goal", "target"}
    row = ",".join("0" if name in integers else "0.5" for name in columns)
    return ",".join(columns) + "\n" + "".join(row + "\n" for _ in range(ticks))


def _metrics(method, trial):
    """PBP-Alt's hand-made metrics; teleop's, which names no goal; none for HOP (its trial
    files written before the metrics)."""
    if method == "hop":
        return None
    latencies = LATENCIES[trial] if method == "pbp_alternated" else None
    named = [t for t in latencies or () if t is not None]
    return {"input_integral": INPUT[trial], "turn_input_integral": 1.0,
            "idle_ratio": 0.6, "agreement": AGREEMENT[trial],
            "prediction_accuracy": None if latencies is None else 0.5,
            "time_to_prediction": latencies,
            "mean_time_to_prediction": sum(named) / len(named) if named else None,
            "unpredicted_switches": (None if latencies is None
                                     else sum(t is None for t in latencies))}


@pytest.fixture(scope="module")
def study(tmp_path_factory, repo):
    tmp_path = tmp_path_factory.mktemp("study")
    scenario = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    digest = scenario_hash(scenario)
    write_study(tmp_path, scenario, digest, METHODS, 3, 0, "tuning")
    for method in METHODS:
        for trial in range(3):
            record = trial_record(scenario.name, digest, method, trial, trial)
            record.update(success=True, task_time=12.0, intervention_ratio=0.4, switches=2,
                          collision_ratio=0.0, ticks=3, objects=[[1.6, 0.0, 0.7]],
                          targets=[0])
            metrics = _metrics(method, trial)
            for name in INTERACTION_METRICS:
                record.pop(name)
            record.update(metrics or {})
            write_trial_files(tmp_path, record, _csv())
    assert main(["report", str(tmp_path)]) == 0
    return tmp_path


def _expected(values, within=(0.0, np.inf)):
    values = np.array(values, float)
    low, high = scipy.stats.t.interval(0.95, len(values) - 1, loc=values.mean(),
                                       scale=scipy.stats.sem(values))
    return {"mean": values.mean(), "std": values.std(), "count": len(values),
            "interval": [max(within[0], low), min(within[1], high)]}


def _close(entry, expected):
    assert entry["count"] == expected["count"]
    for key in ("mean", "std"):
        assert entry[key] == pytest.approx(expected[key], abs=1e-11), key
    assert entry["interval"] == pytest.approx(expected["interval"], abs=1e-11)


def test_the_summary_gives_each_metrics_mean_and_interval_over_the_trials_with_one(study):
    methods = json.loads((study / "summary.json").read_text())["methods"]
    pbp = methods["pbp_alternated"]
    _close(pbp["input_integral"], _expected(INPUT))
    _close(pbp["agreement"], _expected(AGREEMENT, within=(-1.0, 1.0)))
    # The trials' means over the switches they named: 0.6 and 0.6; the third named none.
    latency = pbp["time_to_prediction"]
    assert latency["mean"] == pytest.approx(0.6) and latency["count"] == 2
    assert latency["switches"] == 9 and latency["unpredicted_switches"] == 4
    # All three trials' idle ratio is 0.6: an interval of no width.
    assert pbp["idle_ratio"]["interval"] == pytest.approx([0.6, 0.6])
    teleop = methods["teleop"]
    assert teleop["prediction_accuracy"] == {"mean": None, "std": None, "count": 0,
                                             "interval": None}
    assert teleop["time_to_prediction"]["switches"] == 0
    assert teleop["input_integral"]["count"] == 3
    assert not set(INTERACTION_METRICS) & set(methods["hop"])


def _cells(line):
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


def _rows(text, header_start):
    """{method label: {column: cell}} of the table whose header starts so."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header_start))
    header = _cells(lines[start])
    rows = {}
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        cells = _cells(line)
        rows[cells[0]] = dict(zip(header, cells))
    return rows


def test_the_results_give_the_metrics_and_a_dash_where_a_method_has_none(study):
    results = (study / "results.md").read_text()
    table = _rows(results, "| method | input (m)")
    assert table["PBP-Alt"]["input (m)"] == "0.400 ± 0.163"
    assert table["PBP-Alt"]["switches never named"] == "4 of 9"
    assert table["Teleop"]["prediction accuracy"] == "-"
    assert table["Teleop"]["switches never named"] == "-"
    assert table["HOP"]["agreement"] == "-"
    intervals = _rows(results.split("95 % confidence intervals")[1], "| method | success")
    low, high = _expected(INPUT)["interval"]
    assert intervals["PBP-Alt"]["input (m)"] == f"[{low:.3f}, {high:.3f}]"
    assert intervals["Teleop"]["prediction accuracy"] == "-"
    assert intervals["HOP"]["input (m)"] == "-"
