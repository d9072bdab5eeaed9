"""Collisions are reported only where the task measures them: a reach study's
results and printed table have no collision columns and no Fig. 7c, an obstacle study's
have both, and the obstacle task's one-line result gives its collision ratio.

The study folders are written without simulating (a real study.json of the shipped
scenario, trial files of a few ticks), then rebuilt with `pbp-drake report`, as a user
rebuilds a folder."""

import json

import numpy as np
import pytest

from pbp_drake.builder.run import TaskResult
from pbp_drake.cli import main
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.studies.trial_files import (
    scenario_hash, time_series_columns, trial_record, write_study, write_trial_files)

METHODS = ("pbp_alternated", "teleop")
TRIALS = 2


def _csv(has_collision, ticks=3):
    columns = time_series_columns(has_collision)
    integers = {"operator_active", "selected_goal", "target", "in_collision"}
    row = ",".join("0" if name in integers else "0.5" for name in columns)
    return ",".join(columns) + "\n" + "".join(row + "\n" for _ in range(ticks))


def _study(folder, scenario_path, with_study_json=True):
    """A finished study of the scenario file's task, every trial a success; the obstacle
    task's second trial spent a quarter of its ticks in collision."""
    scenario = load_scenario_file(scenario_path).scenario
    digest = scenario_hash(scenario)
    obstacles = "obstacles" in scenario_path.name
    if with_study_json:
        write_study(folder, scenario, digest, METHODS, TRIALS, 0, "tuning")
    for method in METHODS:
        for trial in range(TRIALS):
            record = trial_record(scenario.name, digest, method, trial, trial)
            # A reach trial records 0: the ratio of a monitor with nothing to measure.
            record.update(success=True, task_time=12.0 + trial, intervention_ratio=0.4,
                          switches=0, collision_ratio=0.25 * trial if obstacles else 0.0,
                          ticks=3, objects=[[1.6, 0.0, 0.7]], targets=[0])
            write_trial_files(folder, record, _csv(obstacles))
    return folder


def _header(results):
    return next(line for line in results.splitlines() if line.startswith("| method"))


@pytest.mark.slow
def test_a_reach_study_reports_no_collisions(tmp_path, repo, capsys):
    folder = _study(tmp_path, repo / "diagrams" / "hsr_reach.yaml")
    assert main(["report", str(folder)]) == 0
    out = capsys.readouterr().out
    results = (folder / "results.md").read_text()
    assert "collision" not in results
    assert "| intervention ratio | task time (s) | peak hand speed" in _header(results)
    assert "collision" not in out
    assert not (folder / "fig7c_collisions.png").exists()
    for name in ("fig7a_intervention.png", "fig7b_task_time.png"):
        assert f"wrote {folder / name}" in out and (folder / name).stat().st_size > 5_000
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["measures_collisions"] is False
    assert "collision_histogram_edges" not in summary
    assert all("collision_ratio" not in entry for entry in summary["methods"].values())


@pytest.mark.slow
def test_an_obstacle_study_reports_its_collisions(tmp_path, repo, capsys):
    folder = _study(tmp_path, repo / "diagrams" / "hsr_obstacles.yaml")
    assert main(["report", str(folder)]) == 0
    out = capsys.readouterr().out
    results = (folder / "results.md").read_text()
    assert ("| task time (s) | collision ratio | collision-free trials | peak hand speed"
            in _header(results))
    # Trials of 0 and 0.25: mean 0.125, std 0.125; one of the two is collision-free.
    assert "| 0.125 ± 0.125 | 1 |" in results
    assert "| 0.125 ± 0.125 | 1 |" in out
    assert f"wrote {folder / 'fig7c_collisions.png'}" in out
    assert (folder / "fig7c_collisions.png").stat().st_size > 5_000
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["measures_collisions"] is True
    assert summary["methods"]["teleop"]["collision_free_trials"] == 1


@pytest.mark.slow
def test_a_stale_collision_figure_is_neither_kept_nor_claimed(tmp_path, repo, capsys):
    folder = _study(tmp_path, repo / "diagrams" / "hsr_reach.yaml")
    # An older version drew Fig. 7c for reaching too.
    (folder / "fig7c_collisions.png").write_bytes(b"an old figure")
    assert main(["report", str(folder)]) == 0
    assert "fig7c" not in capsys.readouterr().out
    assert not (folder / "fig7c_collisions.png").exists()


@pytest.mark.slow
@pytest.mark.parametrize("task, measured", [("hsr_reach", False), ("hsr_obstacles", True)])
def test_a_folder_without_study_json_is_judged_by_its_time_series(tmp_path, repo, capsys,
                                                                 task, measured):
    folder = _study(tmp_path, repo / "diagrams" / f"{task}.yaml", with_study_json=False)
    # Exit 1: the missing study.json is named, and the trials are still reported.
    assert main(["report", str(folder)]) == 1
    capsys.readouterr()
    assert ("collision ratio" in (folder / "results.md").read_text()) is measured
    assert (folder / "fig7c_collisions.png").exists() is measured


def _result(in_collision):
    ticks = 4
    return TaskResult(
        success=True, task_time=12.5, intervention_ratio=0.4, switches=0,
        times=np.arange(ticks) * 0.03, ee_positions=np.zeros((ticks, 3)),
        headings=np.zeros(ticks), commands=np.zeros((ticks, 7)),
        operator_active=np.zeros(ticks, bool), operator_commands=np.zeros((ticks, 4)),
        selected_goals=np.zeros(ticks, int), targets=np.zeros(ticks, int),
        objects=np.zeros((1, 3)),
        collision_ratio=0.0 if in_collision is None else float(np.mean(in_collision)),
        in_collision=in_collision, peak_hand_speed=0.2, peak_command_acceleration=1.0)


def test_the_obstacle_tasks_one_line_result_gives_its_collision_ratio():
    line = _result(np.array([False, True, False, False])).summary_line()
    assert line.startswith("success in 12.50 s, intervention ratio 0.400, "
                           "collision ratio 0.250, 0 target switches")
    assert "collision" not in _result(None).summary_line()
