"""Damaged study folders: `pbp-drake report` names every damaged or foreign file
and reports the rest; a 2-D study and a method comparison refuse each other's folders."""

import json
import os
import pathlib

import pytest

from pbp_drake.cli import main
from pbp_drake.studies.atomic_files import MOST_READ_BYTES
from pbp_drake.studies.trial_files import (
    DamagedFile, load_task_result, read_study, time_series_columns, trial_paths, trial_record,
    write_trial_files)

METHODS = ("teleop", "pbp_alternated")


def _csv(ticks=3):
    columns = time_series_columns(False)
    row = ",".join("0" if name in {"operator_active", "selected_goal", "target"} else "0.5"
                   for name in columns)
    return ",".join(columns) + "\n" + "".join(row + "\n" for _ in range(ticks))


def _study(folder, trials=2, methods=METHODS):
    """A method comparison's folder written without simulating: every trial succeeded."""
    study = {"study": "method_comparison", "format": 1, "scenario": "fake",
             "scenario_hash": "abc", "methods": list(methods), "trials": trials, "seed": 0}
    (folder / "study.json").write_text(json.dumps(study))
    for method in methods:
        for trial in range(trials):
            record = trial_record("fake", "abc", method, trial, trial)
            record.update(success=True, task_time=10.0 + trial, intervention_ratio=0.5,
                          switches=1, collision_ratio=0.0, ticks=3, objects=[[1, 0, 0.7]],
                          targets=[0])
            write_trial_files(folder, record, _csv())
    return folder


@pytest.mark.slow
def test_a_clean_folder_reports_without_complaint(tmp_path, capsys):
    assert main(["report", str(_study(tmp_path))]) == 0
    assert "damaged" not in capsys.readouterr().err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["damaged"] == []
    assert summary["methods"]["teleop"]["trials"] == 2


@pytest.mark.slow
def test_a_sweep_of_fixed_alphas_reports_its_ideal_alpha(tmp_path, capsys):
    folder = _study(tmp_path, methods=("fixed_alpha=0.2", "fixed_alpha=0.6", "teleop"))
    assert main(["report", str(folder)]) == 0
    arbitration = json.loads((folder / "summary.json").read_text())["arbitration"]
    assert arbitration["alphas"] == [0.2, 0.6]
    assert arbitration["ideal_alpha"] == 0.6  # every trial succeeded: the highest
    assert (f"Ideal fixed alpha: {arbitration['ideal_alpha']} ({arbitration['criterion']})."
            in (folder / "results.md").read_text())


@pytest.mark.slow
def test_report_names_each_damaged_file_and_reports_the_rest(tmp_path, capsys):
    folder = _study(tmp_path, trials=3)
    truncated = trial_paths(folder, "teleop", 0)[0]
    truncated.write_text(truncated.read_text()[:80])
    empty = trial_paths(folder, "pbp_alternated", 1)[1]
    empty.write_text("")
    wrong = trial_paths(folder, "teleop", 2)[0]
    record = json.loads(wrong.read_text())
    wrong.write_text(json.dumps({**record, "task_time": "ten"}))
    (folder / "study.json").write_text(json.dumps({"study": "alpha_study", "scenes": []}))

    # Exit 1: files were skipped; what could be read is still reported and written.
    assert main(["report", str(folder)]) == 1
    out, err = capsys.readouterr()
    assert f"{truncated}: truncated or invalid JSON" in err
    assert f"{empty}: empty CSV" in err
    assert f"{wrong}: field 'task_time' is str" in err
    assert f"{folder / 'study.json'}: a study.json of another kind ('alpha_study'" in err
    assert "Traceback" not in err
    summary = json.loads((folder / "summary.json").read_text())
    assert {d["file"] for d in summary["damaged"]} == {
        "study.json", "trials/teleop/seed_0.json", "trials/pbp_alternated/seed_1.csv",
        "trials/teleop/seed_2.json"}
    teleop, alternated = summary["methods"]["teleop"], summary["methods"]["pbp_alternated"]
    assert (teleop["trials"], teleop["damaged"], teleop["missing"]) == (1, 2, 0)
    assert (alternated["trials"], alternated["damaged"], alternated["missing"]) == (2, 1, 0)
    assert alternated["task_time"]["mean"] == 11.0  # seeds 0 and 2
    assert "1 (2 damaged)" in out
    assert "Skipped as damaged or foreign: 4 files (3 trials)" in (
        folder / "results.md").read_text()
    assert len(json.loads((folder / "trials.json").read_text())) == 3


@pytest.mark.slow
def test_one_damaged_file_is_counted_in_the_singular(tmp_path, capsys):
    folder = _study(tmp_path)
    trial_paths(folder, "teleop", 1)[0].write_text("{bad")
    assert main(["report", str(folder)]) == 1
    assert "pbp-drake: 1 damaged or foreign file skipped (listed above and in " in (
        capsys.readouterr().err)
    assert "Skipped as damaged or foreign: 1 file (1 trial); see summary.json." in (
        folder / "results.md").read_text()


@pytest.mark.parametrize("text, problem", [
    ("time,ee_x\n1,2\n", "malformed CSV: its header"),
    (_csv().rsplit("\n", 2)[0] + "\n", "truncated CSV: 2 rows"),
    (_csv().replace("0.5", "x", 1), "malformed CSV: column"),
    (_csv()[:-5] + "\n", "malformed CSV: line 4"),
])
def test_a_malformed_csv_is_named(tmp_path, text, problem):
    folder = _study(tmp_path, trials=1)
    trial_paths(folder, "teleop", 0)[1].write_text(text)
    _, records, damaged = read_study(folder)
    assert records[("teleop", 0)] is None and records[("pbp_alternated", 0)] is not None
    assert [(d.key, problem in d.problem) for d in damaged] == [(("teleop", 0), True)]


@pytest.mark.parametrize("study, problem", [
    ([], "holds a list, not a study"),
    ({"methods": []}, "field 'methods' is not a list of method names"),
    ({"trials": "2"}, "field 'trials' is str, not int"),
    ({"trials": 0}, "field 'trials' is 0, not a positive number"),
    ({"split": 3}, "field 'split' is int, not str"),
    ({"scenario_hash": 5}, "field 'scenario_hash' is int, not str"),
])
def test_a_bad_study_json_is_named_and_the_trials_on_disk_read(tmp_path, study, problem):
    folder = _study(tmp_path, trials=1)
    held = json.loads((folder / "study.json").read_text())
    (folder / "study.json").write_text(json.dumps({**held, **study} if study else study))
    _, records, damaged = read_study(folder)
    assert [d.problem for d in damaged] == [f"{problem}; reporting the trials on disk"]
    assert None not in records.values()


@pytest.mark.parametrize("method, change, problem", [
    ("teleop", lambda record: [record], "holds a list, not a trial record"),
    ("teleop", lambda record: {**record, "format": 0}, "a trial of format 0, not 1"),
    ("pbp_alternated", lambda record: {**record, "method": "teleop"},
     "holds the trial of 'teleop', seed 0"),
])
def test_a_trial_record_of_another_shape_is_named(tmp_path, method, change, problem):
    folder = _study(tmp_path, trials=1)
    path = trial_paths(folder, method, 0)[0]
    path.write_text(json.dumps(change(json.loads(path.read_text()))))
    _, records, damaged = read_study(folder)
    assert [(d.path, d.problem) for d in damaged] == [(str(path), problem)]
    assert records[(method, 0)] is None


@pytest.mark.parametrize("change, error, problem", [
    (lambda text: text[:80], DamagedFile, "truncated or invalid JSON"),
    (lambda text: json.dumps({**json.loads(text), "task_time": "ten"}), DamagedFile,
     "field 'task_time' is str"),
    (lambda text: json.dumps({**json.loads(text), "error": "RuntimeError: it broke"}),
     ValueError, "the trial failed: RuntimeError: it broke"),
])
def test_load_task_result_names_a_trial_it_cannot_give(tmp_path, change, error, problem):
    path = trial_paths(_study(tmp_path, trials=1), "teleop", 0)[0]
    path.write_text(change(path.read_text()))
    with pytest.raises(error, match=problem) as raised:
        load_task_result(tmp_path, "teleop", 0)
    assert str(raised.value).startswith(f"{path}: ")


@pytest.mark.timeout(60)
@pytest.mark.parametrize("kind, problem", [
    ("pipe", "unreadable (a device or a pipe, not a regular file)"),
    ("huge", f"unreadable (holds more than {MOST_READ_BYTES:,} bytes)"),
])
@pytest.mark.parametrize("which", ["study", "trial"])
def test_a_json_file_that_is_a_pipe_or_huge_is_named_unread(tmp_path, which, kind, problem):
    # A named pipe's read waited for ever; /dev/zero or a huge file was read whole.
    folder = _study(tmp_path, trials=1)
    path = folder / "study.json" if which == "study" else trial_paths(folder, "teleop", 0)[0]
    path.unlink()
    if kind == "pipe":
        os.mkfifo(path)
    else:
        path.touch()
        os.truncate(path, MOST_READ_BYTES + 1)  # sparse: nothing written
    _, records, damaged = read_study(folder)
    tail = "; reporting the trials on disk" if which == "study" else ""
    assert [(d.path, d.problem) for d in damaged] == [(str(path), problem + tail)]


@pytest.mark.timeout(60)
@pytest.mark.parametrize("kind, problem", [
    ("pipe", "a device or a pipe, not a regular file"),
    ("huge", f"holds more than {MOST_READ_BYTES:,} bytes, not a trial's time series"),
    ("not UTF-8", "malformed CSV ('utf-8' codec can't decode byte 0xff"),
    ("a long line", "malformed CSV (field larger than field limit"),
])
def test_a_csv_that_is_a_pipe_huge_or_not_text_is_named(tmp_path, kind, problem):
    # A pipe was named missing (and its read waited for ever), the others were tracebacks.
    folder = _study(tmp_path, trials=1)
    csv = trial_paths(folder, "teleop", 0)[1]
    csv.unlink()
    if kind == "pipe":
        os.mkfifo(csv)
    elif kind == "huge":
        csv.touch()
        os.truncate(csv, MOST_READ_BYTES + 1)  # sparse: nothing written
    else:
        csv.write_bytes(b"\xff" + _csv().encode() if kind == "not UTF-8"
                        else b"x" * (1 << 20) + b"\n")
    _, records, damaged = read_study(folder)
    assert [(d.path, d.problem.startswith(problem)) for d in damaged] == [(str(csv), True)]
    assert records[("teleop", 0)] is None


def test_a_trial_without_its_csv_is_named(tmp_path):
    folder = _study(tmp_path, trials=1)
    csv = trial_paths(folder, "teleop", 0)[1]
    csv.unlink()
    _, records, damaged = read_study(folder)
    assert [(d.path, d.problem) for d in damaged] == [
        (str(csv), "missing: the trial's time series CSV is not on disk")]
    assert records[("teleop", 0)] is None


@pytest.mark.slow
def test_a_folder_with_errored_trials_reports_them_and_exits_1(tmp_path, capsys):
    folder = _study(tmp_path, trials=3)
    record = trial_record("fake", "abc", "teleop", 1, 1)
    record["error"] = "RuntimeError: the solver failed"
    trial_paths(folder, "teleop", 1)[1].unlink()
    write_trial_files(folder, record, None)

    # Exit 1, as `pbp-drake study` exits on the same trials; the summary is still written.
    assert main(["report", str(folder)]) == 1
    out, err = capsys.readouterr()
    assert "1 of 6 trials failed with an error" in err
    assert "teleop: 1 trial failed with an error (seeds [1])" in out
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["methods"]["teleop"]["errors"] == 1


@pytest.mark.slow
def test_a_folder_with_trials_that_did_not_run_exits_1(tmp_path, capsys):
    folder = _study(tmp_path, trials=3)
    for path in trial_paths(folder, "pbp_alternated", 2):
        path.unlink()
    assert main(["report", str(folder)]) == 1
    err = capsys.readouterr().err
    assert "0 of 6 trials failed with an error" in err and "and 1 did not run" in err
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["methods"]["pbp_alternated"]["missing"] == 1


def test_nothing_to_report_exits_2(tmp_path, capsys):
    (tmp_path / "study.json").write_text("{")
    assert main(["report", str(tmp_path)]) == 2
    assert "no trial files" in capsys.readouterr().err


def test_a_missing_folder_is_named(tmp_path, capsys):
    assert main(["report", str(tmp_path / "none")]) == 2
    assert capsys.readouterr().err == f"pbp-drake: {tmp_path / 'none'}: no such folder\n"


@pytest.mark.parametrize("argv, message", [
    (["report", "{study}/study.json"], "{study}/study.json: is a file, not a folder"),
    (["report", "{study}/study.json", "--markdown", "{tmp}/x.md"],
     "{study}/study.json: is a file, not a folder"),
    (["compare", "{study}", "{study}/study.json"], "{study}/study.json: is a file, not a folder"),
])
def test_a_file_is_refused_as_a_study_folder(tmp_path, capsys, argv, message):
    folder = _study(tmp_path)
    argv = [arg.format(study=folder, tmp=tmp_path) for arg in argv]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"pbp-drake: {message.format(study=folder)}; give a `pbp-drake study` --output "
        "folder\n")
    assert not (tmp_path / "x.md").exists()


def test_compare_names_a_missing_folder(tmp_path, capsys):
    assert main(["compare", str(_study(tmp_path)), str(tmp_path / "none")]) == 2
    assert capsys.readouterr().err == f"pbp-drake: {tmp_path / 'none'}: no such folder\n"


@pytest.mark.parametrize("argv, message", [
    (["report", ""], "report: the folder's path is empty"),
    (["compare", "", "B"], "compare: the first folder's path is empty"),
    (["compare", "A", ""], "compare: the second folder's path is empty"),
])
def test_an_empty_folder_path_is_named(tmp_path, capsys, monkeypatch, argv, message):
    monkeypatch.chdir(_study(tmp_path))  # not the current folder's study, in silence
    (pathlib.Path("A") / "x").mkdir(parents=True)
    (pathlib.Path("B") / "x").mkdir(parents=True)
    listed = sorted(path.name for path in pathlib.Path().iterdir())
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pbp-drake: {message}; give a `pbp-drake study` --output folder")
    assert len(err.splitlines()) == 1
    assert sorted(path.name for path in pathlib.Path().iterdir()) == listed


def test_a_2d_study_refuses_a_method_comparison_folder(tmp_path, repo, capsys):
    folder = _study(tmp_path)
    before = (folder / "study.json").read_text()
    assert main(["study", str(repo / "diagrams/toy_alpha_study.yaml"), "--output",
                 str(folder)]) == 2
    out, err = capsys.readouterr()
    assert "holds a study of kind 'method_comparison', not a 2-D alpha_study" in err
    assert "wrote" not in out and "Traceback" not in err
    assert not (folder / "summary.json").exists()
    assert (folder / "study.json").read_text() == before


def test_a_method_comparison_refuses_a_2d_study_folder(tmp_path, repo, capsys):
    (tmp_path / "summary.json").write_text(json.dumps({"study": "alt_vs_cont"}))
    assert main(["study", str(repo / "diagrams/hsr_reach.yaml"), "--trials", "1",
                 "--methods", "teleop", "--output", str(tmp_path)]) == 2
    assert "holds a study of kind 'alt_vs_cont', not a method comparison" in capsys.readouterr().err
    assert not (tmp_path / "trials").exists()
