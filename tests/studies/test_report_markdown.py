"""`pbp-drake report DIR --markdown FILE`: the study's table as a Markdown fragment for the
docs, after the command and seeds that made it, read off the study folder."""

import json
import re

import pytest

from pbp_drake.cli import main
from pbp_drake.studies.results_markdown import study_command

# Its tests share fixtures that take seconds to make: `make test-fast` leaves it out.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def hsr_study(tmp_path_factory):
    """One HSR reaching trial per method on the first evaluation seed."""
    repo = __import__("pathlib").Path(__file__).resolve().parents[2]
    output = tmp_path_factory.mktemp("hsr_study")
    assert main(["study", str(repo / "diagrams/hsr_reach.yaml"), "--methods",
                 "pbp_alternated,teleop", "--trials", "1", "--split", "evaluation",
                 "--output", str(output)]) == 0
    return output


def test_the_markdown_names_the_command_and_seeds_then_the_table(hsr_study, tmp_path, capsys):
    summary = (hsr_study / "summary.json").read_bytes()
    markdown = tmp_path / "new" / "folder" / "hsr_reach.md"
    assert main(["report", str(hsr_study), "--markdown", str(markdown)]) == 0
    assert f"wrote {markdown}" in capsys.readouterr().out
    lines = markdown.read_text().splitlines()
    assert lines[0].startswith("`pbp-drake study ")
    assert lines[0].endswith("diagrams/hsr_reach.yaml --methods pbp_alternated,teleop "
                             "--trials 1 --split evaluation` — evaluation seeds 10,000 to "
                             "10,000")
    rows = [line for line in lines if line.startswith("| ")]
    assert rows[0].startswith("| method | trials | success |")
    assert [row.split(" | ")[0] for row in rows[1:3]] == ["| PBP-Alt", "| Teleop"]
    # Below it, the interaction metrics, then each method's 95 % intervals (a single trial
    # has none for its means).
    assert rows[3].startswith("| method | input (m) | turning input (rad) | idle ratio |")
    assert [row.split(" | ")[0] for row in rows[4:6]] == ["| PBP-Alt", "| Teleop"]
    assert rows[6].startswith("| method | success | intervention ratio | task time (s) |")
    no_interval = " | -" * 8 + " |"
    assert rows[7:] == ["| PBP-Alt | [21, 100] %" + no_interval,
                        "| Teleop | [21, 100] %" + no_interval]
    # The table is results.md's; the summary is the same bytes as the study wrote.
    assert markdown.read_text().endswith((hsr_study / "results.md").read_text())
    assert (hsr_study / "summary.json").read_bytes() == summary


def test_a_single_trials_mean_is_shown_without_a_spread(hsr_study):
    # One trial's population std is 0: it read "0.921 ± 0.000", as if measured.
    summary = json.loads((hsr_study / "summary.json").read_text())
    for entry in summary["methods"].values():
        assert entry["intervention_ratio"]["std"] is None and entry["task_time"]["std"] is None
        assert entry["input_integral"]["std"] is None
    results = (hsr_study / "results.md").read_text()
    assert not re.search(r"\d ± \d", results)
    teleop = summary["methods"]["teleop"]["intervention_ratio"]["mean"]
    assert f"| Teleop | 1 | 100 % | {teleop:.3f} (n = 1) | " in results


def test_a_2d_study_gets_its_summary_as_a_table(tmp_path, repo):
    output = tmp_path / "alt_vs_cont"
    assert main(["study", str(repo / "diagrams/toy_alt_vs_cont.yaml"), "--output",
                 str(output)]) == 0
    markdown = tmp_path / "alt_vs_cont.md"
    assert main(["report", str(output), "--markdown", str(markdown)]) == 0
    text = markdown.read_text()
    assert text.startswith("`pbp-drake study ") and "toy_alt_vs_cont.yaml`" in text
    assert "| PBP-Alt |" in text and "| PBP-Cont |" in text
    assert f"Figure: `{output / 'fig4_alt_vs_cont.png'}`" in text
    # A damaged study.json: the table still, the command without the file it no longer names.
    (output / "study.json").write_text("{")
    assert main(["report", str(output), "--markdown", str(markdown)]) == 0
    assert markdown.read_text().startswith("`pbp-drake study <the scenario file of ")
    assert markdown.read_text().endswith(text.split("\n", 1)[1])


def test_a_2d_study_without_its_summary_is_named(tmp_path, capsys):
    (tmp_path / "study.json").write_text('{"study": "alt_vs_cont"}')
    assert main(["report", str(tmp_path), "--markdown", str(tmp_path / "study.md")]) == 2
    assert capsys.readouterr().err.startswith(
        f"pbp-drake: {tmp_path / 'summary.json'}: cannot be read (")
    assert not (tmp_path / "study.md").exists()


def test_a_2d_study_is_named_as_one_without_markdown(tmp_path, capsys):
    (tmp_path / "study.json").write_text('{"study": "alt_vs_cont"}')
    assert main(["report", str(tmp_path)]) == 2
    assert capsys.readouterr().err == (
        f"pbp-drake: {tmp_path} holds a 2-D study (alt_vs_cont), whose summary.json and figure "
        "`pbp-drake study` writes; report rebuilds a robot task's study from its trial files "
        "(--markdown FILE: a table of this one)\n")
    assert list(tmp_path.iterdir()) == [tmp_path / "study.json"]


def test_a_folder_is_refused_as_the_markdown_file(tmp_path, capsys):
    assert main(["report", str(tmp_path), "--markdown", str(tmp_path)]) == 2
    assert capsys.readouterr().err.startswith(f"pbp-drake: --markdown {tmp_path}: is a folder")


def test_without_the_split_seeds_the_command_names_the_first_seed():
    summary = {"scenario": "hsr_reach", "seed": 10005, "trials": 3, "split": "evaluation",
               "methods": {"teleop": {}}}
    assert study_command({"scenario_file": "diagrams/hsr_reach.yaml"}, summary) == (
        "pbp-drake study diagrams/hsr_reach.yaml --methods teleop --trials 3 --seed 10005")
    assert study_command({"split_seeds": {"tuning": 0, "evaluation": 10005}}, summary) == (
        "pbp-drake study <the scenario file of hsr_reach> --methods teleop --trials 3 "
        "--split evaluation")


@pytest.mark.parametrize("overrides, words", [
    ({"set": ["duration=5"], "scenario_text": None}, " --set duration=5"),
    ({"set": [5]}, ""),  # a study.json edited by hand: the command without them
    ({"set": ["no equals sign"]}, ""),
])
def test_the_command_names_the_recorded_overrides_it_can_read(overrides, words):
    summary = {"scenario": "hsr_reach", "seed": 10005, "trials": 3, "methods": {"teleop": {}}}
    study = {"scenario_file": "diagrams/hsr_reach.yaml", "overrides": overrides}
    assert study_command(study, summary) == (
        "pbp-drake study diagrams/hsr_reach.yaml --methods teleop --trials 3 --seed 10005"
        + words)
