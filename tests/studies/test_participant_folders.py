"""`pbp-drake report` over participant folders written without simulating: what it counts
and says of a session stopped in practice, of answers whose run is damaged or missing, of
damaged files, and of pairs too few to test."""

import json
import shutil

import pytest

from pbp_drake.cli import main
from pbp_drake.studies.questionnaire import recorded_questions
from pbp_drake.studies.trial_files import (
    time_series_columns, trial_paths, trial_record, write_trial_files)

METHODS = ["pbp_alternated", "pbp_continuous", "teleop"]


def _csv(ticks=3):
    columns = time_series_columns(False)
    row = ",".join("0" if name in {"operator_active", "selected_goal", "target"} else "0.5"
                   for name in columns)
    return ",".join(columns) + "\n" + "".join(row + "\n" for _ in range(ticks))


def _session(folder, participant, ratio=0.5, tiredness=3, ease=4, seed=0):
    """A participant's complete session: each method run (intervention ratio `ratio` plus
    a tenth per method) and answered."""
    folder.mkdir(parents=True)
    study = {"study": "method_comparison", "format": 1, "scenario": "fake",
             "scenario_hash": "abc", "methods": METHODS, "trials": 1, "seed": seed,
             "participant": participant}
    (folder / "study.json").write_text(json.dumps(study))
    for place, method in enumerate(METHODS):
        record = trial_record("fake", "abc", method, 0, seed)
        record.update(success=True, task_time=10.0 + place, intervention_ratio=ratio + place / 10,
                      switches=1, collision_ratio=0.0, ticks=3, objects=[[1, 0, 0.7]],
                      targets=[0])
        write_trial_files(folder, record, _csv())
    answers = {m: {"tiredness": tiredness, "ease": max(0, ease - place)}
               for place, m in enumerate(METHODS)}
    (folder / "questionnaire.json").write_text(json.dumps(
        {"answers": answers, "questions": recorded_questions()}))
    return folder


def _report(study, capsys, code=0):
    capsys.readouterr()
    assert main(["report", str(study)]) == code
    return (study / "results.md").read_text(), capsys.readouterr().err


@pytest.mark.slow  # Fig. 8 is drawn
def test_one_damaged_file_is_counted_in_the_singular(tmp_path, capsys):
    for n, participant in enumerate(("P01", "P02", "P03")):
        _session(tmp_path / participant, participant, ratio=0.1 * n)
    trial_paths(tmp_path / "P02", "teleop", 0)[0].write_text("{bad")
    results, err = _report(tmp_path, capsys, code=1)
    assert "pbp-drake: 1 damaged file skipped (listed above)" in err
    assert "Skipped as damaged: 1 file" in results


def _practice_only(folder, participant):
    """A session stopped during its practice: practice/ alone, one practice run saved."""
    practice = _session(folder / "practice", participant, seed=1000)
    for method in METHODS[1:]:
        for path in trial_paths(practice, method, 1000):
            path.unlink()
    (practice / "questionnaire.json").unlink()  # no questions are asked after practice
    json_path = practice / "study.json"
    json_path.write_text(json.dumps({**json.loads(json_path.read_text()), "split": "practice"}))


@pytest.mark.slow  # Fig. 8 is drawn
def test_a_session_stopped_during_practice_is_named_as_incomplete(tmp_path, capsys):
    for n, participant in enumerate(("P01", "P02", "P03")):
        _session(tmp_path / participant, participant, ratio=0.1 * n)
    _practice_only(tmp_path / "P04", "P04")
    results, err = _report(tmp_path, capsys)
    # It was left out without a word: the report read as if P04 never came.
    assert "3 participants: P01, P02, P03." in results
    assert ("Incomplete: 1 session, each counted for the methods it has: P04 (stopped during "
            "practice: no method run or answered).") in results
    assert (f"pbp-drake: {tmp_path / 'P04'}: an incomplete session (stopped during practice: "
            "no method run or answered), counted for the methods it has") in err


def test_practice_runs_alone_are_nothing_to_report(tmp_path, capsys):
    _practice_only(tmp_path / "P04", "P04")
    assert main(["report", str(tmp_path)]) == 2
    assert (f"pbp-drake: {tmp_path}: P04 holds practice runs alone (practice/, never counted; a "
            "session stopped during its practice), and there is no other participant folder: "
            "nothing to report") in capsys.readouterr().err
    assert not (tmp_path / "results.md").exists()


def _rows(results, measure):
    """`{pair: n}` of one measure's Wilcoxon rows."""
    return {line.split(" | ")[1]: int(line.split(" | ")[2]) for line in results.splitlines()
            if line.startswith(f"| {measure} | ")}


@pytest.mark.slow  # Fig. 8 is drawn
def test_answers_whose_run_is_damaged_or_missing_are_counted_and_said(tmp_path, capsys):
    for n, participant in enumerate(("P01", "P02", "P03", "P04")):
        _session(tmp_path / participant, participant, ratio=0.1 * n, tiredness=n)
    trial_paths(tmp_path / "P02", "teleop", 0)[0].write_text("{bad")
    for path in trial_paths(tmp_path / "P03", "pbp_continuous", 0):
        path.unlink()  # as a hand-deleted run would leave it: its answers stay
    results, err = _report(tmp_path, capsys, code=1)
    # The answers stood for runs the report left out, and it said so nowhere.
    assert ("Answers counted without their run (in the answers' counts and tests, not in the "
            "trial measures'): P02 (Teleop: its trial file is damaged); P03 (PBP-Cont: not "
            "run).") in results
    assert "P03 (PBP-Cont not run)" in results  # incomplete, as before; a damaged run is not
    assert _rows(results, "tiredness (0-5)")["PBP-Alt vs Teleop"] == 4
    assert _rows(results, "intervention ratio")["PBP-Alt vs Teleop"] == 3
    assert _rows(results, "intervention ratio")["PBP-Cont vs Teleop"] == 2
    for name in ("P02", "P03"):  # complete sessions say nothing of the kind
        shutil.rmtree(tmp_path / name)
    results, _ = _report(tmp_path, capsys)
    assert "without their run" not in results
