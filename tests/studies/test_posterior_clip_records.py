"""How often HOP's goal posterior sat at its clip, as a study records and reports it: each
hop trial's record holds `posterior_clipped_ratio`, the summary and the table give its mean
and 95 % interval for the methods that have one, and trial files written without the
field (every older study, every other method) still report, with no such column."""

import json
import shutil

import pytest

from pbp_drake.cli import main

# Its tests share fixtures that take seconds to make: `make test-fast` leaves it out.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def baseline_study(tmp_path_factory, repo):
    output = tmp_path_factory.mktemp("baselines") / "reach"
    assert main(["study", str(repo / "diagrams/hsr_reach.yaml"), "--methods",
                 "hop,teleop", "--trials", "2", "--split", "tuning",
                 "--output", str(output)]) == 0
    return output


def test_each_hop_trial_records_its_clip_ratio(baseline_study):
    for seed in (0, 1):
        hop = json.loads((baseline_study / f"trials/hop/seed_{seed}.json").read_text())
        teleop = json.loads((baseline_study / f"trials/teleop/seed_{seed}.json").read_text())
        assert 0.0 <= hop["posterior_clipped_ratio"] <= 1.0
        assert "posterior_clipped_ratio" not in teleop
    trials = json.loads((baseline_study / "trials.json").read_text())
    assert {row["method"]: row["posterior_clipped_ratio"] is None for row in trials} == {
        "hop": False, "teleop": True}


def test_the_table_gives_the_clip_ratio_and_its_interval(baseline_study):
    summary = json.loads((baseline_study / "summary.json").read_text())
    assert "posterior_clipped_ratio" in summary["methods"]["hop"]
    assert "posterior_clipped_ratio" not in summary["methods"]["teleop"]
    table = (baseline_study / "results.md").read_text()
    header, _, hop_row, teleop_row = [line for line in table.splitlines()
                                      if line.startswith("|")][:4]
    column = header.split(" | ").index("posterior at its clip")
    assert " ± " in hop_row.split(" | ")[column]
    assert teleop_row.split(" | ")[column] == "-"
    intervals = table.split("95 % confidence intervals")[1]
    assert "posterior at its clip" in intervals.splitlines()[2]


def test_trials_written_without_the_field_still_report(baseline_study, tmp_path, capsys):
    older = tmp_path / "older"
    shutil.copytree(baseline_study, older)
    for path in (older / "trials" / "hop").glob("*.json"):
        record = json.loads(path.read_text())
        del record["posterior_clipped_ratio"]
        path.write_text(json.dumps(record))
    assert main(["report", str(older)]) == 0
    summary = json.loads((older / "summary.json").read_text())
    assert "posterior_clipped_ratio" not in summary["methods"]["hop"]
    assert "posterior at its clip" not in (older / "results.md").read_text()
