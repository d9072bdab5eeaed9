"""A study's processes die with it: SIGKILL of the study leaves no worker, fork
server or resource tracker behind, and the same command then resumes the study. A study
whose trials fail with an error exits non-zero."""

import json
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from pbp_drake.builder import run_task
from pbp_drake.cli import main
from pbp_drake.studies import runners

pytestmark = pytest.mark.slow

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


@pytest.fixture
def task_file(tmp_path):
    path = tmp_path / "task.yaml"
    path.write_text(textwrap.dedent(TASK))
    return path


def study_command(task_file, output, trials):
    return [sys.executable, "-m", "pbp_drake", "study", str(task_file), "--methods", "teleop",
            "--trials", str(trials), "--jobs", "2", "--output", str(output)]


def _stat(pid):
    """(parent pid, state, start time) of a live process, else None."""
    try:
        text = pathlib.Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return None
    fields = text[text.rindex(")") + 2:].split()
    return int(fields[1]), fields[0], fields[19]


def descendants(root):
    """The processes under `root`, as {pid: start time}."""
    children = {}
    for entry in pathlib.Path("/proc").iterdir():
        if entry.name.isdigit() and (stat := _stat(int(entry.name))) is not None:
            children.setdefault(stat[0], []).append((int(entry.name), stat[2]))
    found, todo = {}, [root]
    while todo:
        for pid, started in children.get(todo.pop(), []):
            found[pid] = started
            todo.append(pid)
    return found


def alive(processes):
    return [pid for pid, started in processes.items()
            if (stat := _stat(pid)) is not None and stat[2] == started and stat[1] != "Z"]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigkill_of_the_study_ends_its_processes_and_the_study_resumes(task_file, tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    # Four trials on two jobs: killed when the first is written, two or three are left for
    # the resumed study.
    trials = 4
    expected_folder = tmp_path / "whole"
    subprocess.run(study_command(task_file, expected_folder, trials), env=env, check=True,
                   stdout=subprocess.DEVNULL)
    folder = tmp_path / "killed"
    study = subprocess.Popen(study_command(task_file, folder, trials), env=env,
                             stdout=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while not list((folder / "trials").glob("*/seed_*.json")):
        assert study.poll() is None and time.monotonic() < deadline, "no trial written"
        time.sleep(0.1)
    processes = descendants(study.pid)
    assert len(processes) >= 3  # the fork server, the resource tracker, the workers
    study.send_signal(signal.SIGKILL)
    study.wait()
    # Waited on, not slept: each ends as soon as it sees the study gone (one took over 5 s
    # on a machine loaded eight times over).
    deadline = time.monotonic() + 30
    while alive(processes) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert alive(processes) == []
    written = len(list((folder / "trials").glob("*/seed_*.json")))
    assert written < trials, "the study had finished before it was killed"
    time.sleep(1)  # nothing writes trials any more
    assert len(list((folder / "trials").glob("*/seed_*.json"))) == written

    resumed = subprocess.run(study_command(task_file, folder, trials), env=env, check=True,
                             capture_output=True, text=True)
    assert f"{written} were already on disk" in resumed.stdout
    assert ((folder / "summary.json").read_bytes()
            == (expected_folder / "summary.json").read_bytes())


def test_a_study_with_failed_trials_exits_1_after_writing_its_summary(task_file, tmp_path,
                                                                     capsys, monkeypatch):
    # The trial of seed 0 raises (one process: `--jobs 1` runs the trials here); seed 1 runs.
    def run_task_failing_seed_0(trial):
        if trial.scenario.seed == 0:
            raise RuntimeError("a trial that breaks")
        return run_task(trial)

    monkeypatch.setattr(runners, "run_task", run_task_failing_seed_0)
    output = tmp_path / "study"
    args = ["study", str(task_file), "--methods", "teleop", "--trials", "2", "--seed", "0",
            "--output", str(output)]
    assert main(args) == 1
    summary = json.loads((output / "summary.json").read_text())
    assert summary["methods"]["teleop"]["errors"] == 1
    err = capsys.readouterr().err
    assert "1 of 2 trials failed with an error" in err and str(output / "trials") in err
    record = json.loads((output / "trials" / "teleop" / "seed_0.json").read_text())
    assert record["error"] == "RuntimeError: a trial that breaks"
    assert json.loads((output / "trials" / "teleop" / "seed_1.json").read_text())["error"] is None
