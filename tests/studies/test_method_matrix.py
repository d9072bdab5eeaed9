"""`pbp-drake study --pilots`: every method under every pilot in one folder. Its summary's
shape, the attentive pilot's entries equal to a study without --pilots, the report's
tables with their intervals and its figure, resuming after kill -9 to the same bytes, the
same bytes on Ray, and bad input refused with nothing written."""

import json
import math
import os
import pathlib
import re
import signal
import subprocess
import sys
import textwrap
import time
import importlib.util

import numpy as np
import pytest
import scipy.stats

from pbp_drake.builder.run import TaskResult
from pbp_drake.cli import main
from pbp_drake.studies.comparison import run_method_matrix
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.studies.trial_files import StudyFolderError, scenario_hash
from pbp_drake.studies.matrix import pilot_folder
from pbp_drake.studies.matrix_report import FIGURE, report_matrix

ROOT = pathlib.Path(__file__).resolve().parents[2]
# 6 s of simulated time: each trial ends at its time limit, before the target (about 17 s
# in these scenes), a third of a whole task; what the tests here prove (the files, their
# bytes, resuming, the processes) holds of any trial.
TASK = """
scenario:
  name: two_random_objects
  method: teleop
  control_period: 0.03
  duration: 6.0
  robot: !Hsr {}
  task:
    object_count: [2, 2]
  operator: !VirtualParticipant {}
  seed: 0
"""
METHODS = ["pbp_alternated", "teleop"]
PILOTS = ["attentive", "laggy"]
TRIALS = 2
SEED = 5


@pytest.fixture(scope="module")
def task_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("task") / "task.yaml"
    path.write_text(textwrap.dedent(TASK))
    return path


def study_args(task_file, output, *more):
    return ["study", str(task_file), "--methods", ",".join(METHODS), "--trials", str(TRIALS),
            "--seed", str(SEED), "--output", str(output), *more]


def matrix_args(task_file, output, *more):
    return study_args(task_file, output, "--pilots", ",".join(PILOTS), *more)


# ---------------------------------------------------------------------------------------------
# Bad input: refused before anything is written


@pytest.mark.parametrize("pilots, message", [
    ("attentive,nosy", "did you mean 'noisy'"),
    ("attentive,attentive", "names a pilot twice"),
    (",", "name at least one of attentive"),
])
def test_bad_pilots_are_refused_with_exit_2_and_nothing_written(task_file, tmp_path, capsys,
                                                                 pilots, message):
    output = tmp_path / "matrix"
    assert main(study_args(task_file, output, "--pilots", pilots)) == 2
    assert message in capsys.readouterr().err
    assert not output.exists()


def test_pilots_with_a_participant_condition_are_refused(task_file, tmp_path, capsys):
    output = tmp_path / "matrix"
    assert main(matrix_args(task_file, output, "--participant-condition", "noisy")) == 2
    assert "--participant-condition and --pilots" in capsys.readouterr().err
    assert not output.exists()


def test_a_matrix_is_never_mixed_with_a_study_or_another_scenario(task_file, tmp_path, capsys):
    study = tmp_path / "study"
    (study / "trials").mkdir(parents=True)
    assert main(matrix_args(task_file, study)) == 2
    assert "not a matrix of methods and pilots" in capsys.readouterr().err
    matrix = tmp_path / "matrix"
    matrix.mkdir()
    foreign = {"study": "method_matrix", "scenario": "other", "scenario_hash": "0" * 16,
               "pilots": PILOTS, "methods": METHODS, "trials": TRIALS, "seed": SEED}
    (matrix / "study.json").write_text(json.dumps(foreign))
    assert main(matrix_args(task_file, matrix)) == 2
    assert "holds a matrix of another scenario" in capsys.readouterr().err
    assert main(study_args(task_file, matrix)) == 2  # a study without --pilots, into a matrix
    assert "method_matrix" in capsys.readouterr().err
    assert sorted(p.name for p in matrix.iterdir()) == ["study.json"]


@pytest.mark.parametrize("text, problem", [
    (None, "cannot be read as a matrix's study"),
    ('{"study": "method_matrix", ', "cannot be read as a matrix's study"),
    ('{"study": "method_matrix", "pilots": "laggy"}', "not the study.json of a matrix"),
    ('{"study": "method_comparison", "pilots": []}', "not the study.json of a matrix"),
])
def test_report_matrix_names_a_study_json_that_is_not_a_matrix_s(tmp_path, text, problem):
    if text is not None:
        (tmp_path / "study.json").write_text(text)
    with pytest.raises(StudyFolderError, match=problem) as error:
        report_matrix(tmp_path)
    assert str(error.value).startswith(f"{tmp_path / 'study.json'}: ")
    assert [path.name for path in tmp_path.iterdir()] == ([] if text is None else ["study.json"])


def test_report_names_a_damaged_matrix_study_json_as_the_folder_s_problem(tmp_path, capsys):
    (tmp_path / "study.json").write_text('{"study": "method_matrix", "pilots": "laggy"}')
    assert main(["report", str(tmp_path)]) == 2
    error = capsys.readouterr().err
    assert error.startswith(f"pbp-drake: {tmp_path / 'study.json'}: ")
    assert "not the study.json of a matrix" in error and "--paired-with" not in error


def test_a_pilot_folder_of_another_pilot_is_refused_before_anything_is_written(
        task_file, tmp_path, capsys):
    # The matrix's scenario, but its laggy folder holds a study of another scenario (as
    # after a change to the pilot): refused, and not one file written.
    digest = scenario_hash(load_scenario_file(task_file).scenario)
    matrix = tmp_path / "matrix"
    laggy = pilot_folder(matrix, "laggy")
    laggy.mkdir(parents=True)
    (matrix / "study.json").write_text(json.dumps({
        "study": "method_matrix", "scenario": "two_random_objects", "scenario_hash": digest,
        "pilots": PILOTS, "methods": METHODS, "trials": TRIALS, "seed": SEED}))
    (laggy / "study.json").write_text(json.dumps({
        "study": "method_comparison", "scenario": "two_random_objects",
        "scenario_hash": "0" * 16, "methods": METHODS, "trials": TRIALS, "seed": SEED}))
    before = {path: path.read_bytes() for path in matrix.rglob("*") if path.is_file()}
    assert main(matrix_args(task_file, matrix)) == 2
    assert f"{laggy} holds a study of another scenario" in capsys.readouterr().err
    assert {path: path.read_bytes() for path in matrix.rglob("*") if path.is_file()} == before


def process_run(resolved):
    """A trial's result without a simulation, its task time the id of the process that
    ran it (a little later, so that both workers take trials)."""
    time.sleep(0.2)
    ticks = 3
    return TaskResult(
        success=True, task_time=float(os.getpid()), intervention_ratio=0.5, switches=0,
        times=0.03 * np.arange(ticks), ee_positions=np.zeros((ticks, 3)),
        headings=np.zeros(ticks), commands=np.zeros((ticks, 7)),
        operator_active=np.zeros(ticks, bool), operator_commands=np.zeros((ticks, 4)),
        selected_goals=np.zeros(ticks, int), targets=np.zeros(ticks, int),
        objects=np.zeros((2, 3)), collision_ratio=0.0, in_collision=np.zeros(ticks, bool))


@pytest.mark.slow
def test_every_pilots_trials_run_in_one_pool_of_workers(task_file, tmp_path):
    # Three pilots' trials on --jobs 2: two worker processes in all, each taking trials of
    # more than one pilot (pilot by pilot, each pilot would have had workers of its own).
    scenario = load_scenario_file(task_file).scenario
    pilots = ["attentive", "noisy", "laggy"]
    run_method_matrix(scenario, ["teleop"], pilots, 2, SEED, tmp_path, jobs=2,
                      run=process_run)
    ran_by = {}
    for pilot in pilots:
        for seed in (SEED, SEED + 1):
            record = json.loads((pilot_folder(tmp_path, pilot) / "trials" / "teleop"
                                 / f"seed_{seed}.json").read_text())
            ran_by.setdefault(int(record["task_time"]), set()).add(pilot)
    assert len(ran_by) <= 2 and os.getpid() not in ran_by
    assert max(len(taken) for taken in ran_by.values()) >= 2


# ---------------------------------------------------------------------------------------------
# Whole matrices (real simulations)


@pytest.fixture(scope="module")
def folders(task_file, tmp_path_factory):
    """The matrix with --jobs 2, and the study of the same methods and seeds without
    --pilots."""
    root = tmp_path_factory.mktemp("matrix")
    assert main(matrix_args(task_file, root / "matrix", "--jobs", "2")) == 0
    assert main(study_args(task_file, root / "study")) == 0
    return root / "matrix", root / "study"


@pytest.mark.slow
def test_the_summary_holds_every_method_under_every_pilot(folders):
    matrix, study = folders
    summary = json.loads((matrix / "summary.json").read_text())
    plain = json.loads((study / "summary.json").read_text())
    assert summary["study"] == "method_matrix" and "methods" not in summary
    assert list(summary["pilots"]) == PILOTS
    assert summary["seeds"] == plain["seeds"] == [SEED, SEED + TRIALS - 1]
    for pilot in PILOTS:
        assert list(summary["pilots"][pilot]["methods"]) == METHODS
        for entry in summary["pilots"][pilot]["methods"].values():
            assert entry["trials"] == TRIALS and entry["errors"] == 0
    # Without --pilots the shape is a study's; the attentive pilot is that study.
    assert "pilots" not in plain and list(plain["methods"]) == METHODS
    assert summary["pilots"]["attentive"]["methods"] == plain["methods"]
    assert summary["pilots"]["attentive"]["scenario_hash"] == plain["scenario_hash"]
    # The laggy pilot is another scenario, with a hash of its own, on the same scenes.
    assert summary["pilots"]["laggy"]["scenario_hash"] != plain["scenario_hash"]
    for method in METHODS:
        for seed in range(SEED, SEED + TRIALS):
            attentive, laggy = (
                json.loads((pilot_folder(matrix, pilot) / "trials" / method
                            / f"seed_{seed}.json").read_text()) for pilot in PILOTS)
            assert attentive["objects"] == laggy["objects"]
            assert attentive["targets"] == laggy["targets"]
    trials = json.loads((matrix / "trials.json").read_text())
    assert len(trials) == len(PILOTS) * len(METHODS) * TRIALS
    assert {t["pilot"] for t in trials} == set(PILOTS)


def _t_interval(values):
    """The 95 % t interval of a mean, from its definition."""
    n = len(values)
    mean = sum(values) / n
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))
    half = scipy.stats.t.ppf(0.975, n - 1) * sd / math.sqrt(n)
    return mean - half, mean + half


def _trial_values(matrix, pilot, method, field):
    return [json.loads((pilot_folder(matrix, pilot) / "trials" / method
                        / f"seed_{seed}.json").read_text())[field]
            for seed in range(SEED, SEED + TRIALS)]


@pytest.mark.slow
def test_report_writes_the_tables_with_intervals_paired_with_pbp_alt_and_one_figure(
        folders, task_file, tmp_path, capsys):
    matrix, _ = folders
    expected = (matrix / "summary.json").read_bytes()
    for name in ("summary.json", "results.md", "trials.json", FIGURE):
        (matrix / name).unlink()
    markdown = tmp_path / "docs" / "matrix.md"
    assert main(["report", str(matrix), "--markdown", str(markdown)]) == 0
    capsys.readouterr()
    assert (matrix / "summary.json").read_bytes() == expected
    assert (matrix / FIGURE).stat().st_size > 10_000
    text = (matrix / "results.md").read_text()
    # Each table under its bold title: {title: the table's lines}.
    sections = dict(re.findall(r"^\*\*([^*\n]+)\*\*.*\n\n((?:\|.*\n)+)", text, re.M))
    header = "| method | " + " | ".join(PILOTS) + " |"
    for metric in ("success", "intervention ratio", "task time (s)"):
        assert sections[metric].startswith(header)
        assert sections[f"{metric}, against PBP-Alt"].startswith(header)
    # A cell of the intervention ratio: its mean and its interval from the trial files.
    rows = {line.split(" | ")[0][2:]: line.split(" | ")[1:]
            for line in sections["intervention ratio"].splitlines()[2:]}
    values = _trial_values(matrix, "laggy", "teleop", "intervention_ratio")
    low, high = _t_interval(values)
    assert rows["Teleop"][1].rstrip(" |") == (
        f"{sum(values) / TRIALS:.3f} [{max(low, 0):.3f}, {min(high, 1):.3f}]")
    # Teleop against PBP-Alt under the laggy pilot, paired by seed.
    differences = [b - a for a, b in zip(
        _trial_values(matrix, "laggy", "pbp_alternated", "intervention_ratio"), values)]
    low, high = _t_interval(differences)
    paired = {line.split(" | ")[0][2:]: line.split(" | ")[1:]
              for line in sections["intervention ratio, against PBP-Alt"].splitlines()[2:]}
    assert paired["Teleop"][1].rstrip(" |") == (
        f"{sum(differences) / TRIALS:+.3g} [{low:+.3g}, {high:+.3g}] ({TRIALS})")
    first, rest = markdown.read_text().split("\n\n", 1)
    assert rest == text
    assert first == (f"`pbp-drake study {task_file} --methods {','.join(METHODS)} --trials "
                     f"{TRIALS} --seed {SEED} --pilots {','.join(PILOTS)}`")


@pytest.mark.slow
def test_report_refuses_to_pair_with_a_method_the_matrix_did_not_run(folders, capsys):
    matrix, _ = folders
    results = (matrix / "results.md").read_bytes()
    assert main(["report", str(matrix), "--paired-with", "pbp_continuous"]) == 2
    assert capsys.readouterr().err == (
        "pbp-drake: --paired-with: the matrix ran pbp_alternated, teleop, not pbp_continuous\n")
    assert (matrix / "results.md").read_bytes() == results


@pytest.mark.slow
def test_run_with_the_pilot_and_the_seed_runs_a_matrix_trial_again(folders, task_file,
                                                                   tmp_path):
    # To watch (or log) the trial a matrix's table points at: the same per-tick rows.
    matrix, _ = folders
    log = tmp_path / "laggy.csv"
    seed = SEED + TRIALS - 1
    assert main(["run", str(task_file), "--pilot", "laggy", "--method", "pbp_alternated",
                 "--seed", str(seed), "--no-meshcat", "--log", str(log)]) in (0, 1)
    trial = pilot_folder(matrix, "laggy") / "trials" / "pbp_alternated" / f"seed_{seed}.csv"
    assert log.read_bytes() == trial.read_bytes()

@pytest.mark.slow
def test_compare_names_a_matrix_and_one_of_its_pilots_studies(folders, capsys):
    # A matrix read as a study said "no study.json of a method comparison ... and no trial
    # files: is it the --output folder of a `pbp-drake study`?" of a study's own folder.
    matrix, study = folders
    assert main(["compare", str(study), str(matrix)]) == 2
    pilot = sorted((matrix / "pilots").iterdir())[0]
    assert capsys.readouterr().err == (
        f"pbp-drake: compare: {matrix} holds a study of kind 'method_matrix', not a method "
        f"comparison: compare one pilot's study in it, e.g. {pilot}\n")
    assert main(["compare", str(study), str(pilot)]) in (0, 1)

@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_kill_9_mid_matrix_then_the_same_command_resumes_to_the_same_summary(
        folders, task_file, tmp_path):
    matrix, _ = folders
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    folder = tmp_path / "killed"
    command = [sys.executable, "-m", "pbp_drake",
               *matrix_args(task_file, folder, "--jobs", "2")]
    study = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while not list(folder.glob("pilots/*/trials/*/seed_*.json")):
        assert study.poll() is None and time.monotonic() < deadline, "no trial written"
        time.sleep(0.1)
    study.send_signal(signal.SIGKILL)
    study.wait()
    time.sleep(1)  # the workers end with the study
    written = len(list(folder.glob("pilots/*/trials/*/seed_*.json")))
    total = len(PILOTS) * len(METHODS) * TRIALS
    assert written < total, "the matrix had finished before it was killed"
    resumed = subprocess.run(command, env=env, check=True, capture_output=True, text=True)
    assert f"{written} were already on disk" in resumed.stdout
    assert (folder / "summary.json").read_bytes() == (matrix / "summary.json").read_bytes()


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("ray") is None,
                    reason="ray is not installed: pip install 'pbp_drake[ray]'")
def test_the_matrix_on_ray_writes_the_same_summary(folders, task_file, tmp_path):
    matrix, _ = folders
    folder = tmp_path / "ray"
    assert main(matrix_args(task_file, folder, "--jobs", "2", "--backend", "ray")) == 0
    assert (folder / "summary.json").read_bytes() == (matrix / "summary.json").read_bytes()
