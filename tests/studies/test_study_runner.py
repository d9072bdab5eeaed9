"""The method comparison study runner: the same bytes with any --jobs, resuming, failed and
crashed trials, the trial files read back, and `pbp-drake report` rebuilding from disk."""

import csv
import dataclasses
import io
import json
import importlib.util
import logging
import math
import os
import shutil
import socket
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from pbp_drake.cli import main
from pbp_drake.studies.comparison import run_method_comparison
from pbp_drake.studies.progress import ProgressBar
from pbp_drake.studies.report import BOX_FIGURES
from pbp_drake.studies.summary import (
    HISTOGRAM_EDGES, arbitration, collision_free, collision_histogram, does_the_hsr_task,
    ideal_alpha)
from pbp_drake.studies.trial_files import (
    StudyFolderError, load_task_result, read_time_series, trial_paths, write_trial)
from pbp_drake.scenarios import ScenarioError, load_scenario_file, resolve
from pbp_drake.builder.run import TaskResult, run_task

# Whole tasks, studies, notebooks, browsers or pip: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow

# Two objects drawn from each seed. 6 s of simulated time: each trial ends at its time
# limit, before the target (about 17 s in these scenes), a third of a whole task; what the
# tests here prove (the files, their bytes, resuming, the processes) holds of any trial.
TASK = """
scenario:
  name: two_random_objects
  method: pbp_alternated
  control_period: 0.03
  duration: 6.0
  robot: !Hsr {}
  task:
    object_count: [2, 2]
  operator: !VirtualParticipant {}
  seed: 0
"""
METHODS = ["pbp_alternated", "teleop"]


@pytest.fixture(scope="module")
def task_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("task") / "task.yaml"
    path.write_text(textwrap.dedent(TASK))
    return path


@pytest.fixture(scope="module")
def scenario(task_file):
    return load_scenario_file(task_file).scenario


def study_args(task_file, output, jobs):
    return ["study", str(task_file), "--methods", ",".join(METHODS), "--trials", "2",
            "--seed", "5", "--output", str(output), "--jobs", str(jobs)]


@pytest.fixture(scope="module")
def studies(task_file, tmp_path_factory):
    """The same study run with --jobs 1 and with --jobs 2 (real simulations)."""
    root = tmp_path_factory.mktemp("studies")
    assert main(study_args(task_file, root / "jobs1", 1)) == 0
    assert main(study_args(task_file, root / "jobs2", 2)) == 0
    return root / "jobs1", root / "jobs2"


def test_jobs_1_and_2_write_the_same_summary_bytes(studies):
    one, two = studies
    assert (one / "summary.json").read_bytes() == (two / "summary.json").read_bytes()
    assert (one / "results.md").read_bytes() == (two / "results.md").read_bytes()
    summary = json.loads((one / "summary.json").read_text())
    assert list(summary["methods"]) == METHODS
    for entry in summary["methods"].values():
        assert entry["trials"] == 2 and entry["errors"] == 0 and entry["missing"] == 0
        assert 0.0 <= entry["success_rate"] <= 1.0
        assert set(entry["intervention_ratio"]) == set(entry["task_time"]) == {"mean", "std"}
        # No obstacles: nothing measured collisions, so nothing reports them.
        assert "collision_ratio" not in entry and "collision_free_trials" not in entry
    assert summary["measures_collisions"] is False
    assert "collision_histogram_edges" not in summary
    # Reaching measures no collisions: no Fig. 7c, no collision column in the table.
    assert not (one / "fig7c_collisions.png").exists()
    assert "collision" not in (one / "results.md").read_text()
    # Seeds 5 and 6 lie below the default evaluation seeds (10,000): the tuning split.
    assert summary["split"] == "tuning" and summary["seeds"] == [5, 6]
    assert (one / "results.md").read_text().startswith("Seeds 5 to 6: tuning seeds")
    # Nothing that depends on the machine or the run.
    text = (one / "summary.json").read_text()
    assert str(one) not in text and "wall_time" not in text
    for method in METHODS:
        for seed in (5, 6):
            assert all(path.is_file() for path in trial_paths(one, method, seed))


def test_report_rebuilds_summary_and_figures_from_the_trial_files(studies, capsys):
    one, _ = studies
    expected = (one / "summary.json").read_bytes()
    for name in ("summary.json", "results.md", "trials.json", *BOX_FIGURES):
        (one / name).unlink()
    capsys.readouterr()
    assert main(["report", str(one)]) == 0
    out = capsys.readouterr().out
    assert "| PBP-Alt |" in out and "| Teleop |" in out
    assert (one / "summary.json").read_bytes() == expected
    for name in BOX_FIGURES:
        assert (one / name).stat().st_size > 5_000
    trials = json.loads((one / "trials.json").read_text())
    assert [(t["method"], t["seed"]) for t in trials] == [
        ("pbp_alternated", 5), ("pbp_alternated", 6), ("teleop", 5), ("teleop", 6)]


def test_the_time_series_read_back_equals_the_task_result(studies, scenario):
    one, _ = studies
    direct = run_task(dataclasses.replace(scenario, method="teleop", seed=6))
    loaded = load_task_result(one, "teleop", 6)
    # Read off the robot when a run ends, for its failure line; trial files do not hold it.
    assert direct.joints_at_limits == [] and loaded.joints_at_limits is None
    for field in dataclasses.fields(TaskResult):
        if field.name == "joints_at_limits":
            continue
        expected, actual = getattr(direct, field.name), getattr(loaded, field.name)
        if isinstance(expected, np.ndarray):
            np.testing.assert_array_equal(actual, expected, err_msg=field.name)
            assert actual.dtype.kind == expected.dtype.kind, field.name
        else:
            assert actual == expected, field.name
    record = json.loads(trial_paths(one, "teleop", 6)[0].read_text())
    assert record["scenario"] == "two_random_objects" and record["error"] is None
    np.testing.assert_array_equal(record["objects"], direct.objects)
    assert len(record["targets"]) == 3 and record["ticks"] == len(direct.times)
    # The run's own peaks are those of its CSV columns.
    speed, acceleration = _peaks_from_csv(trial_paths(one, "teleop", 6)[1],
                                          scenario.control_period)
    assert direct.peak_hand_speed == pytest.approx(speed, rel=1e-12)
    assert direct.peak_command_acceleration == pytest.approx(acceleration, rel=1e-12)


def _peaks_from_csv(path, control_period):
    """Peak hand speed and peak command acceleration recomputed from a trial's CSV alone:
    the largest step between consecutive rows of ee_x..ee_z, and of command_vx..command_vz,
    over the control period."""
    with open(path, newline="") as stream:
        rows = list(csv.DictReader(stream))

    def peak(columns):
        points = [[float(row[column]) for column in columns] for row in rows]
        return max(math.dist(a, b) for a, b in zip(points, points[1:])) / control_period

    return peak(("ee_x", "ee_y", "ee_z")), peak(("command_vx", "command_vy", "command_vz"))


def test_each_trial_records_the_peaks_of_its_csv_columns(studies, scenario):
    one, _ = studies
    for method in METHODS:
        for seed in (5, 6):
            json_path, csv_path = trial_paths(one, method, seed)
            record = json.loads(json_path.read_text())
            speed, acceleration = _peaks_from_csv(csv_path, scenario.control_period)
            assert speed > 0.0 and acceleration > 0.0
            assert record["peak_hand_speed"] == pytest.approx(speed, rel=1e-12)
            assert record["peak_command_acceleration"] == pytest.approx(acceleration,
                                                                        rel=1e-12)


def test_summary_and_results_give_each_methods_peak_max_and_mean(studies):
    one, _ = studies
    summary = json.loads((one / "summary.json").read_text())
    table = (one / "results.md").read_text()
    assert "peak hand speed (m/s), max / mean" in table
    assert "peak command acceleration (m/s²), max / mean" in table
    for method, label in zip(METHODS, ("PBP-Alt", "Teleop")):
        records = [json.loads(trial_paths(one, method, seed)[0].read_text())
                   for seed in (5, 6)]
        row = next(line for line in table.splitlines() if line.startswith(f"| {label} |"))
        for field, digits in (("peak_hand_speed", 3), ("peak_command_acceleration", 2)):
            values = [record[field] for record in records]
            peak, mean = max(values), sum(values) / len(values)
            entry = summary["methods"][method][field]
            assert entry["max"] == pytest.approx(peak, rel=1e-11)
            assert entry["mean"] == pytest.approx(mean, rel=1e-11)
            assert f"| {peak:.{digits}f} / {mean:.{digits}f} |" in row
    trials = json.loads((one / "trials.json").read_text())
    assert all(t["peak_hand_speed"] > 0 and t["peak_command_acceleration"] > 0
               for t in trials)


def test_trials_written_without_the_peaks_still_count_and_report_n_a(studies, scenario,
                                                                     tmp_path, capsys):
    folder = tmp_path / "older"
    shutil.copytree(studies[0], folder)
    for seed in (5, 6):  # teleop's trials as written before the peaks were recorded
        path = trial_paths(folder, "teleop", seed)[0]
        record = json.loads(path.read_text())
        del record["peak_hand_speed"], record["peak_command_acceleration"]
        path.write_text(json.dumps(record, indent=1) + "\n")
    ran = []
    run_method_comparison(scenario, METHODS, 2, 5, folder,
                          progress=lambda done, total, record, elapsed: ran.append(record))
    assert ran == []  # still done: nothing runs again
    capsys.readouterr()
    assert main(["report", str(folder)]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines()
               if line.startswith("| Teleop |"))
    # The rest of the row as before; the two peak cells say n/a.
    before = next(line for line in (studies[0] / "results.md").read_text().splitlines()
                  if line.startswith("| Teleop |")).split(" | ")
    assert row.split(" | ") == before[:-3] + ["n/a", "n/a"] + before[-1:]
    summary = json.loads((folder / "summary.json").read_text())
    teleop = summary["methods"]["teleop"]
    assert teleop["trials"] == 2 and teleop["missing"] == 0 and teleop["errors"] == 0
    assert teleop["peak_hand_speed"] == {"max": None, "mean": None}
    assert teleop["peak_command_acceleration"] == {"max": None, "mean": None}
    original = json.loads((studies[0] / "summary.json").read_text())
    assert summary["methods"]["pbp_alternated"] == original["methods"]["pbp_alternated"]
    trials = [t for t in json.loads((folder / "trials.json").read_text())
              if t["method"] == "teleop"]
    assert [t["peak_hand_speed"] for t in trials] == [None, None]
    assert load_task_result(folder, "teleop", 5).peak_hand_speed is None


def test_an_interrupted_study_runs_only_the_missing_trial(studies, task_file, scenario,
                                                          tmp_path):
    folder = tmp_path / "resumed"
    shutil.copytree(studies[0], folder)
    expected = (folder / "summary.json").read_bytes()
    for path in trial_paths(folder, "teleop", 6):
        path.unlink()
    # What an interrupted write leaves: a temporary file, never a half trial file.
    (folder / "trials" / "teleop" / ".seed_6.json.999.tmp").write_text("{")
    kept = {path: path.stat().st_mtime_ns for path in (folder / "trials").rglob("seed_*")}
    ran = []
    run_method_comparison(scenario, METHODS, 2, 5, folder,
                          progress=lambda done, total, record, elapsed: ran.append(
                              (record["method"], record["seed"], total)))
    assert ran == [("teleop", 6, 1)]
    assert {path: path.stat().st_mtime_ns for path in kept} == kept
    assert (folder / "summary.json").read_bytes() == expected
    assert not list(folder.rglob("*.tmp"))


# Fake runs: no simulation, a TaskResult drawn from the seed. Module level, so that worker
# processes can import them.
def fake_run(resolved):
    scenario = resolved.scenario
    rng = np.random.default_rng(scenario.seed)
    ticks = 5
    in_collision = rng.random(ticks) < 0.4
    return TaskResult(
        success=bool(scenario.seed % 2), task_time=float(rng.uniform(5, 20)),
        intervention_ratio=float(rng.random()), switches=2,
        times=0.03 * np.arange(ticks), ee_positions=rng.normal(size=(ticks, 3)),
        headings=rng.normal(size=ticks), commands=rng.normal(size=(ticks, 7)),
        operator_active=rng.random(ticks) < 0.5, operator_commands=rng.normal(size=(ticks, 4)),
        selected_goals=rng.integers(0, 2, ticks), targets=rng.integers(0, 2, ticks),
        objects=rng.normal(size=(2, 3)), collision_ratio=float(in_collision.mean()),
        in_collision=in_collision)


def raising_run(resolved):
    if resolved.scenario.seed == 6 and resolved.scenario.method == "teleop":
        raise RuntimeError("the simulator gave up")
    return fake_run(resolved)


def crashing_run(resolved):
    if resolved.scenario.seed == 6 and resolved.scenario.method == "teleop":
        os._exit(3)  # the worker process dies
    return fake_run(resolved)


def test_a_trial_that_raises_is_recorded_and_the_study_goes_on(scenario, tmp_path):
    summary = run_method_comparison(scenario, METHODS, 3, 5, tmp_path, run=raising_run)
    record = json.loads(trial_paths(tmp_path, "teleop", 6)[0].read_text())
    assert record["success"] is False
    assert record["error"] == "RuntimeError: the simulator gave up"
    assert record["time_series"] is None and not trial_paths(tmp_path, "teleop", 6)[1].exists()
    assert summary["methods"]["teleop"]["errors"] == 1
    assert summary["methods"]["teleop"]["error_seeds"] == [6]
    assert summary["methods"]["teleop"]["trials"] == 3
    assert summary["methods"]["pbp_alternated"]["errors"] == 0
    for method, seed in [("teleop", 5), ("teleop", 7), ("pbp_alternated", 6)]:
        assert json.loads(trial_paths(tmp_path, method, seed)[0].read_text())["error"] is None
    # Resuming keeps the failed trial; retry_errors runs it (and only it) again.
    ran = []

    def progress(done, total, record, elapsed):
        ran.append((record["method"], record["seed"]))

    run_method_comparison(scenario, METHODS, 3, 5, tmp_path, progress, run=fake_run)
    assert ran == []
    summary = run_method_comparison(scenario, METHODS, 3, 5, tmp_path, progress, run=fake_run,
                                    retry_errors=True)
    assert ran == [("teleop", 6)]
    assert summary["methods"]["teleop"]["errors"] == 0


def test_a_crashed_worker_process_fails_only_its_trial(scenario, tmp_path):
    summary = run_method_comparison(scenario, METHODS, 3, 5, tmp_path, jobs=2,
                                    run=crashing_run)
    record = json.loads(trial_paths(tmp_path, "teleop", 6)[0].read_text())
    assert record["error"].startswith("BrokenProcessPool")
    assert summary["methods"]["teleop"]["error_seeds"] == [6]
    assert summary["methods"]["pbp_alternated"]["errors"] == 0
    assert summary["methods"]["teleop"]["trials"] == 3
    assert not list(tmp_path.rglob("*.running"))


def test_in_collision_round_trips_through_the_csv(scenario, tmp_path):
    result = fake_run(resolve(dataclasses.replace(scenario, seed=11)))
    run_method_comparison(scenario, ["pbp_alternated"], 1, 11, tmp_path, run=fake_run)
    loaded = load_task_result(tmp_path, "pbp_alternated", 11)
    np.testing.assert_array_equal(loaded.in_collision, result.in_collision)
    np.testing.assert_array_equal(loaded.commands, result.commands)
    assert loaded.collision_ratio == result.collision_ratio
    series = read_time_series(trial_paths(tmp_path, "pbp_alternated", 11)[1])
    assert list(series)[-1] == "in_collision"


def test_a_folder_of_another_scenario_is_refused(scenario, tmp_path):
    run_method_comparison(scenario, METHODS, 1, 0, tmp_path, run=fake_run)
    other = dataclasses.replace(scenario, duration=7.0)
    with pytest.raises(StudyFolderError, match="another scenario"):
        run_method_comparison(other, METHODS, 1, 0, tmp_path, run=fake_run)
    # Without study.json the trial files themselves tell.
    (tmp_path / "study.json").unlink()
    with pytest.raises(StudyFolderError, match="another scenario"):
        run_method_comparison(other, METHODS, 1, 0, tmp_path, run=fake_run)


def test_without_output_the_study_goes_to_its_default_folder(repo, tmp_path, monkeypatch,
                                                            capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "outputs").mkdir()
    (tmp_path / "outputs" / "hsr_reach-teleop").write_text("notes")  # in the way: refused
    assert main(["study", str(repo / "diagrams" / "hsr_reach.yaml"), "--methods", "teleop"]
                ) == 2
    assert "--output outputs/hsr_reach-teleop: is a file" in capsys.readouterr().err


def test_a_damaged_study_json_is_named_and_written_again(scenario, tmp_path, capsys):
    first = run_method_comparison(scenario, METHODS, 1, 0, tmp_path, run=fake_run)
    study = (tmp_path / "study.json").read_bytes()
    (tmp_path / "study.json").write_text('{"study": ')
    assert run_method_comparison(scenario, METHODS, 1, 0, tmp_path, run=fake_run) == first
    assert (f"pbp-drake: damaged: {tmp_path / 'study.json'}: truncated or invalid JSON"
            in capsys.readouterr().err)
    assert (tmp_path / "study.json").read_bytes() == study


def warning_run(resolved):
    logging.getLogger("drake").warning("differential IK is stuck")  # as Drake logs it
    return fake_run(resolved)


def test_drake_s_warnings_are_counted_in_the_record_not_printed(scenario, tmp_path, capsys):
    handlers = list(logging.getLogger("drake").handlers)
    run_method_comparison(scenario, ["teleop"], 1, 0, tmp_path, run=warning_run)
    record = json.loads(trial_paths(tmp_path, "teleop", 0)[0].read_text())
    assert record["drake_warnings"] == 1
    assert "differential IK" not in capsys.readouterr().err
    assert logging.getLogger("drake").handlers == handlers  # given back after the trial


def test_write_trial_leaves_no_temporary_files(tmp_path):
    record = {"method": "teleop", "seed": 1, "format": 1, "error": "X: y"}
    write_trial(tmp_path, record)
    assert [p.name for p in tmp_path.rglob("*") if p.is_file()] == ["seed_1.json"]


@pytest.mark.parametrize("jobs", [0, -2])
def test_jobs_must_be_positive(task_file, tmp_path, capsys, scenario, jobs):
    assert main(study_args(task_file, tmp_path, jobs)) == 2
    assert f"--jobs {jobs}" in capsys.readouterr().err
    with pytest.raises(ScenarioError, match="jobs"):
        run_method_comparison(scenario, METHODS, 1, 0, tmp_path, jobs=jobs, run=fake_run)


def test_more_jobs_than_trials_is_fine(scenario, tmp_path):
    summary = run_method_comparison(scenario, ["teleop"], 1, 3, tmp_path, jobs=4, run=fake_run)
    assert summary["methods"]["teleop"]["trials"] == 1


def test_report_of_a_folder_without_a_study(tmp_path, capsys):
    assert main(["report", str(tmp_path)]) == 2
    assert "no study.json" in capsys.readouterr().err


def test_collision_histogram_bins():
    counts = collision_histogram([0.0, 0.0, 0.049, 0.05, 0.5, 0.99, 1.0])
    assert len(counts) == len(HISTOGRAM_EDGES) - 1 == 20
    assert counts[0] == 3 and counts[1] == 1 and counts[10] == 1 and counts[19] == 2


def _entry(success_rate, collision_free, trials=10, errors=0):
    return {"trials": trials, "errors": errors, "success_rate": success_rate,
            "collision_free_trials": collision_free}


def test_ideal_alpha_is_the_highest_that_still_does_the_task():
    # The paper's choice: the most autonomy that still lets the operator do the task.
    reach = {"teleop": _entry(1.0, 10), "fixed_alpha=0.2": _entry(1.0, 10),
             "fixed_alpha=0.9": _entry(0.9, 10), "fixed_alpha=0.5": _entry(1.0, 10)}
    assert arbitration(reach)["ideal_alpha"] == 0.5
    assert arbitration(reach)["alphas"] == [0.2, 0.5, 0.9]
    # Collisions measured: most trials (of those that ran) must be free of them.
    obstacles = {"fixed_alpha=0.1": _entry(1.0, 6), "fixed_alpha=0.3": _entry(1.0, 5),
                 "fixed_alpha=0.6": _entry(1.0, 5, errors=1)}
    assert arbitration(obstacles)["ideal_alpha"] == 0.6
    assert arbitration({"fixed_alpha=0.3": _entry(1.0, 2)})["ideal_alpha"] is None
    assert arbitration({"teleop": _entry(1.0, 10)}) is None


def test_one_ideal_alpha_serves_the_hsr_comparison_and_the_2d_alpha_study():
    # The HSR method comparison: summary entries judged by success and collisions.
    swept = [(0.2, _entry(1.0, 10)), (0.9, _entry(0.9, 10)), (0.5, _entry(1.0, 10))]
    assert ideal_alpha(swept, does_the_hsr_task) == 0.5
    # The 2-D alpha study: collision ratios, the task is to touch no obstacle.
    ratios = [(0.0, 0.0), (0.3, 0.0), (0.4, 0.02), (0.6, 0.0), (1.0, 0.4)]
    assert ideal_alpha(ratios, collision_free) == 0.6
    assert ideal_alpha([(0.5, 0.1), (1.0, 0.3)], collision_free) is None
    assert ideal_alpha([], collision_free) is None


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_bar_on_a_terminal_and_in_a_log():
    ok = {"success": True, "error": None, "method": "teleop", "seed": 0}
    bad = {"success": False, "error": "RuntimeError: x", "method": "teleop", "seed": 1}
    terminal = Terminal()
    bar = ProgressBar(terminal)
    bar(1, 2, ok, 10.0)
    bar(2, 2, bad, 20.0)
    text = terminal.getvalue()
    assert text.startswith("\r[") and text.count("\r") == 2 and text.endswith("\n")
    assert "1/2 trials" in text and "ETA 10s" in text and "1 failed (1 errors)" in text
    log = io.StringIO()
    bar = ProgressBar(log, every=2)
    for done in range(1, 5):
        bar(done, 4, ok, float(done))
    lines = log.getvalue().splitlines()
    assert len(lines) == 2 and "2/4 trials" in lines[0] and "4/4 trials" in lines[1]
    assert "\r" not in log.getvalue()
    # Minutes and hours, as a long study takes them: 75 s a trial, 99 trials to go.
    assert ProgressBar(io.StringIO()).line(1, 100, 75.0).endswith(
        "1m15s elapsed, ETA 2h03m")


# ---------------------------------------------------------------------------------------------
# --backend ray (a local Ray of --jobs CPUs; about 4 s to start here)

needs_ray = pytest.mark.skipif(importlib.util.find_spec("ray") is None,
                               reason="ray is not installed: pip install 'pbp_drake[ray]'")


@needs_ray
def test_ray_backend_writes_the_same_files_as_local_processes(studies, task_file, tmp_path):
    one, _ = studies
    folder = tmp_path / "ray"
    started = time.monotonic()
    assert main(study_args(task_file, folder, 2) + ["--backend", "ray"]) == 0
    print(f"ray study: {time.monotonic() - started:.1f} s")
    for name in ("summary.json", "results.md", "trials.json"):
        assert (folder / name).read_bytes() == (one / name).read_bytes(), name
    for method in METHODS:
        for seed in (5, 6):
            local_json, local_csv = trial_paths(one, method, seed)
            ray_json, ray_csv = trial_paths(folder, method, seed)
            assert ray_csv.read_bytes() == local_csv.read_bytes()
            ours, theirs = json.loads(ray_json.read_text()), json.loads(local_json.read_text())
            ours.pop("wall_time"), theirs.pop("wall_time")
            # Only a Ray trial says where it ran: this machine, the local Ray's one node.
            assert ours.pop("host") == socket.gethostname() and ours.pop("ray_node")
            assert ours == theirs
    assert not [p for p in folder.rglob("*") if p.suffix in (".tmp", ".running")]
    import ray
    assert not ray.is_initialized()  # the Ray it started is shut down


@needs_ray
def test_ray_backend_records_a_trial_that_raises_and_resumes(scenario, tmp_path):
    summary = run_method_comparison(scenario, METHODS, 3, 5, tmp_path, jobs=2,
                                    run=raising_run, backend="ray")
    record = json.loads(trial_paths(tmp_path, "teleop", 6)[0].read_text())
    assert record["error"] == "RuntimeError: the simulator gave up"
    assert record["time_series"] is None and not trial_paths(tmp_path, "teleop", 6)[1].exists()
    assert summary["methods"]["teleop"]["error_seeds"] == [6]
    assert summary["methods"]["pbp_alternated"]["errors"] == 0
    local = tmp_path / "local"
    assert run_method_comparison(scenario, METHODS, 3, 5, local, run=raising_run) == summary
    assert (local / "summary.json").read_bytes() == (tmp_path / "summary.json").read_bytes()
    # Resuming keeps the failed trial and runs nothing (retry_errors is the same code as
    # with local processes; not run here, to start Ray once).
    ran = []
    run_method_comparison(scenario, METHODS, 3, 5, tmp_path, run=fake_run, backend="ray",
                          progress=lambda done, total, record, elapsed: ran.append(record))
    assert ran == []


def test_ray_backend_without_ray_says_how_to_install_it(task_file, tmp_path, capsys,
                                                        monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError
    assert main(study_args(task_file, tmp_path / "out", 2) + ["--backend", "ray"]) == 2
    assert "pip install 'pbp_drake[ray]'" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("options, message", [
    ({"trials": 0}, "trials must be at least 1, got 0"),
    ({"backend": "dask"}, "backend must be one of local, ray, got 'dask'"),
    ({"ray_address": "auto"}, "ray_address needs backend='ray'"),
    ({"jobs": 2, "run": lambda resolved: None}, "cannot be sent to worker processes"),
])
def test_run_method_comparison_refuses_bad_options_before_any_folder(scenario, tmp_path,
                                                                      options, message):
    arguments = {"trials": 1, **options}
    trials = arguments.pop("trials")
    with pytest.raises(ScenarioError, match=message):
        run_method_comparison(scenario, METHODS, trials, 0, tmp_path / "out", **arguments)
    assert not (tmp_path / "out").exists()


def test_ray_address_needs_the_ray_backend(task_file, tmp_path, capsys):
    assert main(study_args(task_file, tmp_path, 1) + ["--ray-address", "auto"]) == 2
    assert "--ray-address needs --backend ray" in capsys.readouterr().err


@pytest.mark.parametrize("study, section, argv, message", [
    ("toy_alt_vs_cont.yaml", "", [], "{file}: has no `study:` section to run"),
    ("hsr_reach.yaml", "study: !AltVsCont {}\n", [],
     "{file}: study !AltVsCont varies a 2-D scene; a robot task takes study: "
     "!MethodComparison"),
    ("hsr_reach.yaml", "study: !AlphaStudy {scenes: [{name: a}]}\n", [],
     "{file}: study !AlphaStudy varies a 2-D scene; a robot task takes study: "
     "!MethodComparison"),
    ("hsr_reach.yaml", None, ["--methods", "teleop,teleop"],
     "--methods teleop,teleop names a method twice"),
    # The file's own methods, or --set's: not blamed on a --methods never given.
    ("hsr_reach.yaml", "study: !MethodComparison {methods: [teleop, teleop]}\n", [],
     "{file}: study.methods ['teleop', 'teleop'] names a method twice"),
    ("hsr_reach.yaml", None, ["--set", "study.methods=[teleop, teleop]"],
     "{file} with --set 'study.methods=[teleop, teleop]': study.methods ['teleop', 'teleop'] "
     "names a method twice"),
    # The flag named, not the study.methods or study.trials it replaces.
    ("hsr_reach.yaml", None, ["--methods", ","], "--methods ',' names no method; give them "
     "comma-separated, e.g. pbp_alternated,teleop"),
    ("hsr_reach.yaml", None, ["--trials", "0"], "--trials must be at least 1, got 0"),
    # A seed no trial can take: not a folder of failed trials.
    ("hsr_reach.yaml", None, ["--seed", "-1", "--trials", "1"],
     "--seed -1 cannot seed the random draws; expected a non-negative integer"),
    # Tuning runs on seeds kept for evaluation (or the reverse): refused, not run and
    # labelled "mixed" or "evaluation" in silence.
    *[("hsr_reach.yaml", None, ["--split", split, "--seed", seed, "--trials", "2", "--set",
                                "duration=1"],
       f"--split {split}: seeds {seed} to {int(seed) + 1} are not all {split} seeds "
       f"({seeds}) but {label}: give --seed and --trials within them, or --seed without "
       f"--split to run these seeds, labelled {label}")
      for split, seed, seeds, label in [("tuning", "9999", "0 to 9999", "mixed"),
                                        ("evaluation", "5", "from 10000 on", "tuning")]],
    ("hsr_reach.yaml", "study: !MethodComparison\n  split: tuning\n  trials: 3\n"
     "  evaluation_seed: 2\n", ["--set", "duration=1"],
     "{file}'s study.split tuning: seeds 0 to 2 are not all tuning seeds (0 to 1) but "
     # No --split to leave out: --seed alone runs them.
     "mixed: give --seed and --trials within them, or --seed without --split to run these "
     "seeds, labelled mixed"),
    # A flag of the HSR tasks' studies on a 2-D study: refused, not left unused in silence.
    *[("toy_alpha_study.yaml", None, [flag, value], f"{flag}: {{file}} is a 2-D study, whose "
       "runs its `study:` section sets; the HSR tasks' studies take it")
      for flag, value in [("--methods", "teleop"), ("--trials", "0"), ("--split", "tuning"),
                          ("--seed", "-1"), ("--jobs", "0"), ("--retry-errors", None)]],
])
def test_a_study_the_file_cannot_run_is_refused(repo, tmp_path, capsys, study, section, argv,
                                                message):
    text = (repo / "diagrams" / study).read_text()
    if section is not None:  # the file's study section, replaced
        text = text.split("\nstudy:")[0] + "\n" + section
    scenario = tmp_path / study
    scenario.write_text(text)
    argv = [arg for arg in argv if arg is not None]
    assert main(["study", str(scenario), "--output", str(tmp_path / "out"), *argv]) == 2
    assert capsys.readouterr().err == f"pbp-drake: {message.format(file=scenario)}\n"
    assert not (tmp_path / "out").exists()


def test_the_local_backend_does_not_import_ray(scenario, tmp_path):
    code = textwrap.dedent("""
        import sys
        from pbp_drake.cli import main
        from pbp_drake.studies.comparison import run_method_comparison
        from pbp_drake.scenarios import load_scenario_file

        def run(scenario):
            raise RuntimeError("no simulation")

        scenario = load_scenario_file(sys.argv[1]).scenario
        summary = run_method_comparison(scenario, ["teleop"], 1, 0, sys.argv[2], run=run)
        assert summary["methods"]["teleop"]["errors"] == 1
        assert "ray" not in sys.modules, "ray was imported"
    """)
    task = tmp_path / "task.yaml"
    task.write_text(textwrap.dedent(TASK))
    subprocess.run([sys.executable, "-c", code, str(task), str(tmp_path / "out")], check=True,
                   timeout=120)


@needs_ray
def test_a_ray_address_where_nothing_answers_is_named_at_once(task_file, tmp_path, capsys):
    with socket.socket() as probe:  # a port of this host that nothing listens on once closed
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    started = time.monotonic()
    args = study_args(task_file, tmp_path, 1) + ["--backend", "ray",
                                                 "--ray-address", f"127.0.0.1:{port}"]
    assert main(args) == 2
    # Ray's own driver retried such an address for minutes, printing only its warnings.
    assert time.monotonic() - started < 10
    message = capsys.readouterr().err
    assert f"could not connect to Ray at 127.0.0.1:{port}: nothing answers at" in message
    assert "ray start --head" in message
    assert not list(tmp_path.glob("trials/*/*.json"))


def test_a_study_that_leaves_out_trials_of_its_folder_says_which(scenario, tmp_path, capsys):
    # Run again with fewer methods or seeds, the folder's summary covers the new selection
    # alone: the trials it leaves out are named, and their files stay.
    run_method_comparison(scenario, METHODS, 3, 5, tmp_path, run=fake_run)
    files = sorted(tmp_path.glob("trials/*/*.json"))
    capsys.readouterr()
    summary = run_method_comparison(scenario, ["teleop"], 2, 5, tmp_path, run=fake_run)
    assert list(summary["methods"]) == ["teleop"]
    left_out = (
        f"pbp-drake: {tmp_path} holds trials this summary leaves out: pbp_alternated (3 "
        f"trials); 1 trial of the others outside seeds 5 to 6; their files stay in "
        f"{tmp_path / 'trials'}, and a study of them all (its --methods, --trials and --seed) "
        "reports them together\n")
    assert capsys.readouterr().err == left_out
    assert sorted(tmp_path.glob("trials/*/*.json")) == files
    # Reported later, the folder says the same.
    assert main(["report", str(tmp_path)]) == 0
    assert capsys.readouterr().err == left_out
    # A selection that covers every trial file leaves nothing out: nothing is said.
    run_method_comparison(scenario, METHODS, 3, 5, tmp_path, run=fake_run)
    assert capsys.readouterr().err == ""
