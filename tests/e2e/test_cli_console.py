"""The command line around a run: `--version`, `--no-meshcat` (no server, no
URL), the progress line, and a closed pipe (`pbp-drake report DIR | head -1`) or Ctrl-C that
end the command quietly."""

import json
import signal
import subprocess
import sys
import time

import pytest

from pbp_drake import __version__
from pbp_drake.cli import main
from pbp_drake.studies.trial_files import time_series_columns, trial_record, write_trial_files

QUICK = "diagrams/toy_alt_vs_cont.yaml"


def test_version(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out == f"pbp-drake {__version__}\n"


@pytest.mark.slow
def test_no_meshcat_runs_without_a_server(repo, capsys):
    assert main(["run", str(repo / QUICK), "--no-meshcat"]) == 0
    out = capsys.readouterr().out
    assert "Meshcat" not in out and "http://" not in out
    # In fixed point: the end's y of about -5e-11 was printed "-4.785e-11".
    assert "toy_alt_vs_cont [pbp_alternated]: final position [1.000, 0.000], " in out
    # Not a terminal: the progress line is a line of its own.
    assert "t = 3.0 s of 3 s, " in out


def test_no_meshcat_refuses_a_person_at_the_page(repo, capsys):
    assert main(["run", str(repo / "diagrams/hsr_reach.yaml"), "--no-meshcat",
                 "--operator", "keyboard"]) == 2
    assert "--no-meshcat: a keyboard or gamepad is read in the page" in capsys.readouterr().err


def _study(folder):
    """A small method comparison written without simulating (two methods, one trial)."""
    folder.mkdir()
    methods = ["teleop", "pbp_alternated"]
    (folder / "study.json").write_text(json.dumps({
        "study": "method_comparison", "format": 1, "scenario": "fake", "scenario_hash": "abc",
        "methods": methods, "trials": 1, "seed": 0}))
    columns = time_series_columns(False)
    row = ",".join("0" if name in {"operator_active", "selected_goal", "target"} else "0.5"
                   for name in columns)
    for method in methods:
        record = trial_record("fake", "abc", method, 0, 0)
        record.update(success=True, task_time=10.0, intervention_ratio=0.5, switches=1,
                      collision_ratio=0.0, ticks=3, objects=[[1, 0, 0.7]], targets=[0])
        write_trial_files(folder, record, ",".join(columns) + "\n" + (row + "\n") * 3)
    return folder


@pytest.mark.slow  # a whole study and its report in processes: 2.5 s
@pytest.mark.timeout(120)
def test_a_closed_pipe_ends_report_quietly(repo, tmp_path):
    folder = _study(tmp_path / "study")
    piped = subprocess.run(f"'{sys.executable}' -m pbp_drake report '{folder}' | head -1",
                           shell=True, cwd=repo, capture_output=True, text=True, timeout=100)
    assert piped.stdout.count("\n") == 1
    assert "Traceback" not in piped.stderr and "BrokenPipe" not in piped.stderr
    # A reader that is gone before the first line: every write meets a closed pipe.
    process = subprocess.Popen([sys.executable, "-m", "pbp_drake", "report", str(folder)],
                               cwd=repo, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.close()
    err = process.communicate(timeout=100)[1].decode()
    assert "Traceback" not in err and "Exception ignored" not in err, err
    assert process.returncode == 1


@pytest.mark.slow  # a run in a process, interrupted: 2 s
@pytest.mark.timeout(60)
def test_ctrl_c_ends_a_run_without_a_traceback(repo):
    # As from a terminal: a suite started in the background (`make test &`) has SIGINT
    # ignored, and a child inherits that; the run must get the person's Ctrl-C.
    process = subprocess.Popen([sys.executable, "-m", "pbp_drake", "run", QUICK], cwd=repo,
                               stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert process.stdout.readline().startswith("Meshcat: http://")
    time.sleep(0.5)  # into the 3 s of the scene, run at real time
    process.send_signal(signal.SIGINT)
    err = process.communicate(timeout=30)[1]
    assert process.returncode == 130
    assert "pbp-drake: interrupted" in err and "Traceback" not in err, err
