"""An HSR task streamed to a CSV file gives the run `run_task` gives: the same metrics and
peaks (the interaction metrics up to their sums' rounding), and the file holds the rows
`run_task`'s series would (its loggers emptied as it goes), the grasping task's too (the
rows of a study's trial CSV). The soak keeps memory flat over several minutes of runs."""

import dataclasses

import pytest
from pydrake.geometry import Meshcat, MeshcatParams

from pbp_drake.builder import run_task, run_task_streamed
from pbp_drake.builder.time_series import time_series_csv
from pbp_drake.cli import main
from pbp_drake.scenarios import load_scenario_file, resolve
from pbp_drake_bench.soak import run_soak
from pbp_drake.studies.runners import run_trial
from pbp_drake.studies.trial_files import load_task_result, read_time_series, trial_paths

# Whole tasks: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow

METRICS = ("success", "task_time", "intervention_ratio", "switches", "collision_ratio",
           "peak_hand_speed", "peak_command_acceleration",
           # The grasping task's (None in the others).
           "peak_command_angular_change", "final_angle_to_target",
           # Read off the station's state at the end (a list: [] when none).
           "joints_at_limits")


@pytest.mark.parametrize("file_name, duration", [
    ("hsr_reach.yaml", None),  # to success, target switches
    ("hsr_obstacles.yaml", None),  # the in_collision column
    ("hsr_reach.yaml", 3.0),  # stopped by the time limit
    ("hsr_grasp.yaml", 5.0),  # the hand's pose logged, the orientation columns
])
def test_a_streamed_run_matches_the_in_memory_run(repo, tmp_path, file_name, duration):
    scenario = load_scenario_file(repo / "diagrams" / file_name).scenario
    if duration is not None:
        scenario = dataclasses.replace(scenario, duration=duration)
    resolved = resolve(scenario)
    in_memory = run_task(resolved)
    log = tmp_path / "run.csv"
    # Chunks of 0.7 s: many chunk boundaries, none on a whole second.
    streamed = run_task_streamed(resolved, log, chunk_seconds=0.7)

    assert in_memory.success == (duration is None)
    for metric in METRICS:
        assert getattr(streamed, metric) == getattr(in_memory, metric), metric
    assert streamed.peak_hand_speed is not None
    # The interaction metrics, summed chunk by chunk: the same up to the sums' rounding.
    for metric in ("input_integral", "turn_input_integral", "idle_ratio", "agreement",
                   "prediction_accuracy", "mean_time_to_prediction"):
        assert getattr(streamed, metric) == pytest.approx(getattr(in_memory, metric),
                                                          rel=1e-12, abs=1e-15), metric
    assert streamed.time_to_prediction == in_memory.time_to_prediction
    assert streamed.unpredicted_switches == in_memory.unpredicted_switches
    # Row for row what a study would write for the in-memory run, and readable as a trial's.
    assert log.read_text() == time_series_csv(in_memory)
    assert len(read_time_series(log, len(in_memory.times))["time"]) == len(in_memory.times)
    # The series are in the file, not in the result, which holds on to no chunk of them
    # (a run after run soak would keep every run's last chunk).
    series = [streamed.times, streamed.ee_positions, streamed.headings, streamed.commands,
              streamed.operator_active, streamed.operator_commands, streamed.selected_goals,
              streamed.targets]
    if in_memory.angles_to_target is not None:
        assert streamed.final_angle_to_target is not None
        series += [streamed.angles_to_target, streamed.command_angular_velocities,
                   streamed.operator_twists]
    assert all(len(array) == 0 for array in series)
    assert all((array if array.base is None else array.base).nbytes == 0 for array in series)


# Three simulated minutes (about 30 s): the first the baseline, two more of runs against it
# (`make soak` runs sixty).
SOAK_MINUTES = 2


def test_a_short_soak_keeps_memory_flat_and_logs_every_tick(tmp_path):
    meshcat = Meshcat(MeshcatParams(host="localhost", port=None))
    soak = run_soak(SOAK_MINUTES, tmp_path, meshcat)

    minutes = [simulated / 60 for simulated, _, _ in soak.samples]
    assert len(minutes) == SOAK_MINUTES and minutes[0] >= 1.0
    assert minutes[-1] == pytest.approx(SOAK_MINUTES, abs=0.01)
    assert soak.growth_percent < 10.0
    assert all(result.success for result in soak.results[:-1])
    period = 0.03
    for path, result in zip(soak.log_paths, soak.results):
        times = read_time_series(path)["time"]
        # One row per tick, none missing or repeated: t_k = k * period.
        assert times == pytest.approx([k * period for k in range(len(times))])
        if result.success:  # to the tick before the one that reached the target, as run_task
            assert times[-1] + period == pytest.approx(result.task_time)
    total = sum(len(read_time_series(path)["time"]) for path in soak.log_paths)
    assert total == pytest.approx(SOAK_MINUTES * 60 / period, abs=len(soak.results) + 1)


def test_run_log_writes_the_rows_and_refuses_a_file_it_did_not_write(repo, tmp_path, capsys):
    scenario = str(repo / "diagrams" / "hsr_reach.yaml")
    notes = tmp_path / "notes.csv"
    notes.write_text("my notes\n")
    assert main(["run", scenario, "--operator", "virtual", "--headless", "--duration", "2",
                 "--log", str(notes)]) == 2
    assert "--log" in capsys.readouterr().err and notes.read_text() == "my notes\n"

    log = tmp_path / "run.csv"
    assert main(["run", scenario, "--operator", "virtual", "--headless", "--duration", "2",
                 "--log", str(log)]) == 1  # 2 s is too short to reach the target
    assert f"per-tick rows in {log}" in capsys.readouterr().out
    # As run_task: rows of ticks 0..67 (a 2 s limit is 67 ticks; the run goes one tick past).
    assert len(read_time_series(log)["time"]) == 68
    # A time series it wrote may be overwritten.
    assert main(["run", scenario, "--operator", "virtual", "--headless", "--duration", "1",
                 "--log", str(log)]) == 1
    assert len(read_time_series(log)["time"]) == 34


def test_run_log_of_the_grasping_task_writes_the_rows_of_a_study_trial(repo, tmp_path, capsys):
    path = repo / "diagrams" / "hsr_grasp.yaml"
    scenario = dataclasses.replace(load_scenario_file(path).scenario, duration=4.0)
    method, seed = "pbp_continuous", 10000
    study = tmp_path / "study"
    run_trial(scenario, method, 0, seed, study, digest=None)

    log = tmp_path / "logs" / "run.csv"  # its folder is made
    assert main(["run", str(path), "--operator", "virtual", "--no-meshcat", "--duration", "4",
                 "--method", method, "--seed", str(seed), "--log", str(log)]) == 1
    # Byte for byte the trial's CSV: the same columns (the orientation ones too) and rows.
    assert log.read_bytes() == trial_paths(study, method, seed)[1].read_bytes()
    # The result line of a run without --log (the trial's, read back), then the file.
    out = capsys.readouterr().out
    summary = load_task_result(study, method, seed).summary_line()
    assert f"seed {seed}]: {summary}; per-tick rows in {log}" in out
    # A grasp time series it wrote may be overwritten, as a reach one.
    assert main(["run", str(path), "--operator", "virtual", "--no-meshcat", "--duration", "1",
                 "--log", str(log)]) == 1
    assert len(read_time_series(log)["angle_to_target"]) == 34
