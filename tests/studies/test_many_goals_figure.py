"""The many-goals page's figure and table (`pbp_drake_bench.many_goals_figure`) from the
summaries of the K sweep's studies: every line with its studies on disk (each estimator's
and each method's), time over teleop's of the same K."""

import json

import pytest

from pbp_drake_bench.many_goals_figure import (
    methods_study_name, plot_many_goals, study_name, sweep, write_sweep_table)


def summary(folder, methods):
    folder.mkdir(parents=True)
    (folder / "summary.json").write_text(json.dumps({"methods": {
        name: {"success_rate": success, "intervention_ratio": {"mean": ratio},
               "task_time": {"mean": time}} for name, (success, ratio, time) in methods.items()}}))


@pytest.mark.slow
def test_the_table_and_figure_hold_every_line_on_disk(tmp_path):
    outputs = tmp_path / "results"
    summary(outputs / study_name(100), {"pbp_alternated": (1.0, 0.9, 30.0),
                                         "teleop": (1.0, 0.92, 20.0)})
    summary(outputs / study_name(100, "angle"), {"pbp_alternated": (1.0, 0.18, 18.0)})
    summary(outputs / study_name(100, "intent_filter"), {"pbp_alternated": (0.9, 0.2, 24.0)})
    summary(outputs / methods_study_name(100), {"hop": (1.0, 0.85, 16.0)})
    table = tmp_path / "sweep.md"
    assert write_sweep_table(sweep(outputs), table)
    rows = {line.split(" | ")[0].strip("| "): line for line in table.read_text().splitlines()
            if line.startswith("| ") and "K = " not in line}
    assert set(rows) == {"PBP-Alt, one goal (angle)", "PBP-Alt, groups, angle",
                         "PBP-Alt, groups, intent_filter", "HOP", "teleop"}
    assert "| 100 %, 0.900, 1.50x |" in rows["PBP-Alt, one goal (angle)"]
    assert "| 90 %, 0.200, 1.20x |" in rows["PBP-Alt, groups, intent_filter"]
    assert "| 100 %, 0.850, 0.80x |" in rows["HOP"]
    assert rows["teleop"].endswith("| - | 100 %, 0.920, 1.00x | - |")
    figure = tmp_path / "sweep.png"
    assert plot_many_goals(sweep(outputs), figure) and figure.stat().st_size > 10_000


def test_no_study_on_disk_writes_nothing(tmp_path):
    assert not write_sweep_table(sweep(tmp_path), tmp_path / "sweep.md")
    assert not plot_many_goals(sweep(tmp_path), tmp_path / "sweep.png")
    assert not (tmp_path / "sweep.md").exists() and not (tmp_path / "sweep.png").exists()
