"""`pbp-drake study FILE --participant-condition noisy|late|mistaken`: the condition impairs
the scenario's virtual participant, study.json records it and the results name it; a
scenario without the virtual participant, or a 2-D study, refuses it in one line. (One
teleop trial each way: about a second.)"""

import json

import pytest

from pbp_drake.cli import main
from pbp_drake.core.participant_impairment import PARTICIPANT_CONDITIONS

REACH = "diagrams/hsr_reach.yaml"


def test_an_unknown_condition_is_refused_when_parsed(repo, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["study", str(repo / REACH), "--participant-condition", "sleepy",
              "--output", str(tmp_path / "out")])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert "--participant-condition: invalid choice: 'sleepy'" in err
    assert "'noisy', 'late', 'mistaken'" in err


def test_a_scenario_without_the_virtual_participant_refuses_it(repo, tmp_path, capsys):
    text = (repo / REACH).read_text()
    start = text.index("  operator: !VirtualParticipant")
    end = text.index("  seed: 0")
    path = tmp_path / "no_operator.yaml"
    path.write_text(text[:start] + "  operator: !NoOperator {}\n" + text[end:])
    assert main(["study", str(path), "--participant-condition", "late", "--trials", "1",
                 "--output", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert (f"pbp-drake: --participant-condition late: {path}'s scenario.operator is "
            "!NoOperator, not the virtual participant") in err
    assert not (tmp_path / "out" / "study.json").exists()


def test_a_two_d_study_refuses_it(repo, tmp_path, capsys):
    assert main(["study", str(repo / "diagrams/toy_alt_vs_cont.yaml"),
                 "--participant-condition", "noisy", "--output", str(tmp_path / "out")]) == 2
    assert "is a 2-D study, which has no virtual participant" in capsys.readouterr().err
    assert not (tmp_path / "out" / "summary.json").exists()


@pytest.mark.slow
def test_the_condition_runs_is_recorded_and_named_in_the_results(repo, tmp_path, capsys):
    plain, late = tmp_path / "plain", tmp_path / "late"
    common = ["--methods", "teleop", "--trials", "1", "--split", "tuning"]
    assert main(["study", str(repo / REACH), *common, "--output", str(plain)]) == 0
    assert main(["study", str(repo / REACH), *common, "--participant-condition", "late",
                 "--output", str(late)]) == 0
    out = capsys.readouterr().out
    assert "the late virtual participant" in out
    assert "Virtual participant: the late condition (command_delay 0.3 s)." in out
    study = json.loads((late / "study.json").read_text())
    assert study["participant_condition"] == "late"
    impairment = study["scenario_content"]["operator"]["impairment"]
    assert impairment["command_delay"] == PARTICIPANT_CONDITIONS["late"].command_delay
    assert "participant_condition" not in json.loads((plain / "study.json").read_text())
    assert "Virtual participant" not in (plain / "results.md").read_text()
    assert ("Virtual participant: the late condition (command_delay 0.3 s)."
            in (late / "results.md").read_text())
    summary = json.loads((late / "summary.json").read_text())
    assert summary["virtual_participant"] == {"condition": "late",
                                              "impairment": {"command_delay": 0.3}}
    # The late participant's first command reaches the robot 0.3 s (10 ticks) later than
    # the plain one's (which first watches the still robot for its serve_patience).
    header, *rows = (late / "trials/teleop/seed_0.csv").read_text().splitlines()
    active = header.split(",").index("operator_active")
    plain_rows = (plain / "trials/teleop/seed_0.csv").read_text().splitlines()[1:]

    def first_active(lines):
        return next(i for i, line in enumerate(lines) if line.split(",")[active] == "1")

    assert 0 < first_active(plain_rows) < 15
    assert first_active(rows) == first_active(plain_rows) + 10
    # The docs' table names the command that made it, condition and all.
    markdown = tmp_path / "late.md"
    assert main(["report", str(late), "--markdown", str(markdown)]) == 0
    assert markdown.read_text().startswith(
        f"`pbp-drake study {repo / REACH} --methods teleop --trials 1 --split tuning "
        "--participant-condition late`")
    # The same folder resumed without the condition is another study: refused, saying so.
    capsys.readouterr()
    assert main(["study", str(repo / REACH), *common, "--output", str(late)]) == 2
    assert "it was run with --participant-condition late" in capsys.readouterr().err
