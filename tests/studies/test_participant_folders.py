"""`pbp-drake report` over participant folders written without simulating: what it counts
and says of a session stopped in practice, of answers whose run is damaged or missing, of
damaged files, and of pairs too few to test."""

import json

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
