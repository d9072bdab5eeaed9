"""Real trials carry the interaction metrics: a short reach study with the virtual
participant (PBP-Alt and teleop, two tuning seeds) and a few seconds of the grasping task.
Each trial file holds every metric within its range and in step with its own time series
(the idle ratio with the intervention ratio, the prediction accuracy and the turning input
with the CSV's rows); teleop, which shows no goal, has no prediction metrics. The summary
gives each a mean inside its 95 % interval, and the results table shows them."""

import dataclasses
import json

import numpy as np
import pytest

from pbp_drake.cli import main
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.studies.runners import run_trial
from pbp_drake.builder.time_series import HAND_ORIENTATION_COLUMNS
from pbp_drake.studies.trial_files import (
    INTERACTION_METRICS, load_task_result, read_time_series, trial_paths)

pytestmark = pytest.mark.slow

METHODS = ("pbp_alternated", "teleop")
PERIOD = 0.03


@pytest.fixture(scope="module")
def reach_study(tmp_path_factory, repo):
    output = tmp_path_factory.mktemp("reach") / "study"
    assert main(["study", str(repo / "diagrams/hsr_reach.yaml"), "--methods",
                 ",".join(METHODS), "--trials", "2", "--split", "tuning",
                 "--output", str(output)]) == 0
    return output


def _trial(output, method, seed):
    json_path, csv_path = trial_paths(output, method, seed)
    return json.loads(json_path.read_text()), read_time_series(csv_path)


def _check_operator_metrics(record, series):
    assert set(INTERACTION_METRICS) <= set(record)
    assert record["idle_ratio"] + record["intervention_ratio"] == pytest.approx(1.0, abs=1e-12)
    # On the task monitor's ticks, which count the tick that ended the task too.
    silent_rows = float(np.mean(series["operator_active"] == 0))
    assert abs(record["idle_ratio"] - silent_rows) <= 1.0 / record["ticks"] + 1e-12
    speeds = np.linalg.norm(np.column_stack(
        [series[c] for c in ("operator_vx", "operator_vy", "operator_vz")]), axis=1)
    assert 0.0 < record["input_integral"] <= speeds.max() * record["task_time"]
    assert record["turn_input_integral"] > 0.0
    assert -1.0 <= record["agreement"] <= 1.0


def _check_prediction_metrics(record, series):
    named = series["selected_goal"] == series["target"]
    assert record["prediction_accuracy"] == pytest.approx(named.mean(), abs=1e-12)
    latencies = record["time_to_prediction"]
    # The first target and each switch.
    assert len(latencies) == record["switches"] + 1
    got = [t for t in latencies if t is not None]
    assert all(0.0 <= t <= record["task_time"] for t in got)
    assert record["unpredicted_switches"] == len(latencies) - len(got)
    assert record["mean_time_to_prediction"] == (pytest.approx(np.mean(got)) if got else None)


@pytest.mark.parametrize("method", METHODS)
def test_each_reach_trial_holds_every_metric_in_its_range(reach_study, method):
    for seed in (0, 1):
        record, series = _trial(reach_study, method, seed)
        assert record["success"]
        _check_operator_metrics(record, series)
        if method == "teleop":
            # Under teleop the hand goes where the participant pushes it, and no goal is
            # shown (every tick's selected_goal -1): no prediction metrics.
            assert record["agreement"] > 0.9
            assert np.all(series["selected_goal"] == -1)
            assert all(record[name] is None for name in (
                "prediction_accuracy", "time_to_prediction", "mean_time_to_prediction",
                "unpredicted_switches"))
        else:
            _check_prediction_metrics(record, series)


def test_the_summary_and_the_results_give_each_metric_with_its_interval(reach_study):
    summary = json.loads((reach_study / "summary.json").read_text())
    for method in METHODS:
        entry = summary["methods"][method]
        for name in ("input_integral", "turn_input_integral", "idle_ratio", "agreement"):
            value = entry[name]
            assert value["count"] == 2
            low, high = value["interval"]
            assert low <= value["mean"] <= high, (method, name)
    teleop = summary["methods"]["teleop"]["prediction_accuracy"]
    assert teleop["count"] == 0 and teleop["interval"] is None
    latency = summary["methods"]["pbp_alternated"]["time_to_prediction"]
    assert latency["switches"] == sum(
        _trial(reach_study, "pbp_alternated", seed)[0]["switches"] + 1 for seed in (0, 1))
    results = (reach_study / "results.md").read_text()
    assert "| method | input (m) | turning input (rad) | idle ratio | agreement |" in results
    intervals = results.split("95 % confidence intervals")[1].splitlines()[2]
    assert "input (m)" in intervals and "time to prediction (s)" in intervals


def test_a_grasp_trial_counts_the_angular_velocitys_norm_as_its_turning(repo, tmp_path):
    path = repo / "diagrams" / "hsr_grasp.yaml"
    scenario = dataclasses.replace(load_scenario_file(path).scenario, duration=5.0)
    record = run_trial(scenario, "pbp_continuous", 0, 10000, tmp_path, digest=None)
    series = read_time_series(trial_paths(tmp_path, "pbp_continuous", 10000)[1])
    _check_operator_metrics(record, series)
    _check_prediction_metrics(record, series)
    angular = np.linalg.norm(np.column_stack(
        [series[c] for c in ("operator_wx", "operator_wy", "operator_wz")]), axis=1)
    acting = series["operator_active"] == 1
    assert record["turn_input_integral"] == pytest.approx(angular[acting].sum() * PERIOD,
                                                          rel=1e-12)
    # The hand's orientation is in the CSV, unit quaternions; a grasp trial written before it
    # was logged (the same CSV without those columns) still reads back, without it.
    result = load_task_result(tmp_path, "pbp_continuous", 10000)
    np.testing.assert_allclose(np.linalg.norm(result.hand_orientations, axis=1), 1.0,
                               atol=1e-9)
    csv_path = trial_paths(tmp_path, "pbp_continuous", 10000)[1]
    lines = csv_path.read_text().splitlines()
    kept = len(lines[0].split(",")) - len(HAND_ORIENTATION_COLUMNS)
    csv_path.write_text("".join(",".join(line.split(",")[:kept]) + "\n" for line in lines))
    older = load_task_result(tmp_path, "pbp_continuous", 10000)
    assert older.hand_orientations is None
    np.testing.assert_array_equal(older.angles_to_target, result.angles_to_target)
