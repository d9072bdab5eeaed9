"""`pbp-drake report STUDY_DIR` over participant folders, as the paper reports its user study:
three real sessions of the virtual operator with fixed answers, the Wilcoxon table checked
against scipy.stats.wilcoxon computed straight from the trial and questionnaire files, Fig. 8,
practice runs left out, and the folders the report refuses."""

import itertools
import json
import re
import shutil

import matplotlib.image
import pytest
import scipy.stats

from pbp_drake.cli import main
from pbp_drake.scenarios import METHOD_NAMES

pytestmark = pytest.mark.slow  # nine short tasks and their reports (about 20 s)

TASK = "diagrams/hsr_reach.yaml"
METHODS = ["pbp_alternated", "pbp_continuous", "teleop"]
DURATION = "4"  # short runs: every method still gives real intervention ratios
SESSIONS = {  # participant: (seed, fixed answers)
    "P01": (1, "tiredness=3,ease=4,teleop:tiredness=1,pbp_continuous:ease=2"),
    "P02": (2, "tiredness=4,ease=3,teleop:tiredness=2,teleop:ease=4"),
    "P03": (3, "tiredness=5,ease=5,teleop:tiredness=1,pbp_continuous:tiredness=2"),
}
ROW = re.compile(r"^\| (intervention ratio|task time \(s\)|tiredness \(0-5\)|ease \(0-5\)) \| "
                 r"(\S+) vs (\S+) \| (\d+) \| (\S+) \| (\S+)")


def session(repo, study, participant, *extra, duration=DURATION):
    seed, answers = SESSIONS.get(participant, (0, "tiredness=3,ease=3"))
    return main(["run", str(repo / TASK), "--headless", "--operator", "virtual",
                 "--participant", participant, "--seed", str(seed), "--answers", answers,
                 "--duration", duration, "--output", str(study / participant), *extra])


@pytest.fixture(scope="module")
def study(repo, tmp_path_factory):
    study = tmp_path_factory.mktemp("user_study")
    for participant in SESSIONS:
        practice = ["--practice"] if participant == "P01" else []
        assert session(repo, study, participant, *practice) in (0, 1)  # 1: a run failed
    return study


def from_files(study):
    """`{measure: {method: {participant: value}}}` read straight from the files."""
    values = {m: {method: {} for method in METHODS}
              for m in ("intervention ratio", "task time (s)", "tiredness (0-5)",
                        "ease (0-5)")}
    for folder in sorted(p for p in study.iterdir() if p.is_dir()):
        answers = json.loads((folder / "questionnaire.json").read_text())["answers"]
        for method in METHODS:
            (trial,) = (folder / "trials" / method).glob("seed_*.json")
            record = json.loads(trial.read_text())
            values["intervention ratio"][method][folder.name] = record["intervention_ratio"]
            values["task time (s)"][method][folder.name] = record["task_time"]
            values["tiredness (0-5)"][method][folder.name] = answers[method]["tiredness"]
            values["ease (0-5)"][method][folder.name] = answers[method]["ease"]
    return values


def test_the_wilcoxon_table_is_scipys_on_the_files(study, capsys):
    assert main(["report", str(study)]) == 0
    results = (study / "results.md").read_text()
    assert capsys.readouterr().out.startswith(results)
    assert "significant when p < 0.05 / 3 = 0.01667" in results
    rows = {}
    for line in results.splitlines():
        if match := ROW.match(line):
            measure, first, second, n, statistic, p = match.groups()
            rows[(measure, first, second)] = (int(n), statistic, p)
    values = from_files(study)
    assert len(rows) == 4 * 3
    for measure, (first, second) in itertools.product(values, itertools.combinations(
            METHODS, 2)):
        x = [values[measure][first][p] for p in SESSIONS]
        y = [values[measure][second][p] for p in SESSIONS]
        n, statistic, p = rows[(measure, METHOD_NAMES[first], METHOD_NAMES[second])]
        assert n == 3
        # Every difference zero, or all but one (SciPy drops the zeros, leaving one value):
        # nothing to test, and the row says so in words.
        if sum(a != b for a, b in zip(x, y)) < 2:
            assert (statistic, p) == ("-", "n/a"), (measure, first, second)
            continue
        expected = scipy.stats.wilcoxon(x, y)
        assert float(statistic) == pytest.approx(float(expected.statistic))
        assert p == f"{expected.pvalue:.4g}", (measure, first, second)
    # The answers the sessions gave, as a person reads them in the table of counts.
    assert "| Teleop | How tired did you feel? | 0 | 2 | 1 | 0 | 0 | 0 |" in results


def test_fig8_shows_the_answers(study):
    assert main(["report", str(study)]) == 0
    image = matplotlib.image.imread(study / "fig8_questionnaire.png")
    assert image.shape[0] > 200 and image.shape[1] > 600


def test_practice_runs_are_kept_apart_and_not_counted(study):
    practice = study / "P01" / "practice"
    assert json.loads((practice / "study.json").read_text())["split"] == "practice"
    assert len(list((practice / "trials").rglob("seed_*.json"))) == 3
    assert main(["report", str(study)]) == 0
    results = (study / "results.md").read_text()
    for method in METHODS:  # three participants, one recorded run each
        assert re.search(rf"^\| {re.escape(METHOD_NAMES[method])} \| 3 \| \d of 3 \|",
                         results, re.M)
    assert "3 participants: P01, P02, P03." in results


def test_a_folder_without_participants_is_refused(tmp_path, capsys):
    (tmp_path / "notes").mkdir()
    assert main(["report", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pbp-drake: {tmp_path} has no study.json")
    assert "and no participant folders" in err and "nothing to report" in err


def test_a_participant_of_another_scenario_is_refused(repo, study, tmp_path, capsys):
    mixed = tmp_path / "mixed"
    for participant in ("P01", "P02"):
        shutil.copytree(study / participant, mixed / participant)
    assert session(repo, mixed, "P09", "--methods", "teleop", duration="3") in (0, 1)
    capsys.readouterr()
    assert main(["report", str(mixed)]) == 2
    err = capsys.readouterr().err
    assert f"{mixed / 'P09'} is a session of another scenario" in err
    assert "; duration 4.0 in the others, 3.0 in this one): move it out" in err
    assert not (mixed / "results.md").exists()



def test_a_folder_of_studies_is_not_read_as_participants(repo, study, tmp_path, capsys):
    # `report outputs/` with the studies in it: each study's first trial was reported as a
    # participant's session, exit 0. A study of more trials, or of another kind, is refused.
    folder = tmp_path / "outputs"
    shutil.copytree(study / "P01", folder / "P01")
    assert main(["study", str(repo / TASK), "--methods", "teleop", "--trials", "2",
                 "--set", "duration=2", "--output", str(folder / "teleop_study")]) in (0, 1)
    capsys.readouterr()
    assert main(["report", str(folder)]) == 2
    assert (f"pbp-drake: {folder / 'teleop_study'} is a study of 2 trials a method, not a "
            "participant's session") in capsys.readouterr().err
    shutil.rmtree(folder / "teleop_study")
    (folder / "matrix").mkdir()
    (folder / "matrix" / "study.json").write_text(json.dumps({"study": "method_matrix"}))
    assert main(["report", str(folder)]) == 2
    assert (f"pbp-drake: {folder / 'matrix'} holds a study of kind 'method_matrix', not a "
            "participant's session") in capsys.readouterr().err
    assert not (folder / "results.md").exists()

def test_markdown_is_refused_for_a_user_study(study, tmp_path, capsys):
    assert main(["report", str(study), "--markdown", str(tmp_path / "study.md")]) == 2
    assert (f"--markdown: {study} is a user study's folder; --markdown takes a `pbp-drake "
            "study` folder") in capsys.readouterr().err
    assert not (tmp_path / "study.md").exists()


def test_a_damaged_trial_is_skipped_and_counted(study, tmp_path, capsys):
    damaged = tmp_path / "damaged"
    for participant in SESSIONS:
        shutil.copytree(study / participant, damaged / participant)
    (trial,) = (damaged / "P02" / "trials" / "teleop").glob("seed_*.json")
    trial.write_text(trial.read_text()[:40])
    assert main(["report", str(damaged)]) == 1
    err = capsys.readouterr().err
    assert f"{trial}: truncated or invalid JSON" in err
    assert "pbp-drake: 1 damaged file skipped (listed above)" in err
    assert ("Skipped as damaged: 1 file (named by `pbp-drake report`)."
            in (damaged / "results.md").read_text())


def test_a_trial_of_another_scenario_in_a_participant_folder_is_refused(study, tmp_path,
                                                                          capsys):
    mixed = tmp_path / "mixed"
    for participant in SESSIONS:
        shutil.copytree(study / participant, mixed / participant)
    (trial,) = (mixed / "P03" / "trials" / "teleop").glob("seed_*.json")
    trial.write_text(json.dumps({**json.loads(trial.read_text()), "scenario_hash": "0" * 16}))
    assert main(["report", str(mixed)]) == 2
    err = capsys.readouterr().err
    assert f"{trial} is a trial of another scenario" in err
    assert f"participant folder {mixed / 'P03'} mixes scenarios; move it out of {mixed}" in err
    assert not (mixed / "results.md").exists()


def test_an_answer_outside_0_to_5_is_refused(study, tmp_path, capsys):
    edited = tmp_path / "edited"
    shutil.copytree(study / "P02", edited / "P02")
    path = edited / "P02" / "questionnaire.json"
    held = json.loads(path.read_text())
    held["answers"]["teleop"]["ease"] = 7  # as a hand edit of the file would
    path.write_text(json.dumps(held))
    assert main(["report", str(edited)]) == 2
    err = capsys.readouterr().err
    assert (f"{path}: teleop ease: the answer 7 is outside 0 to 5 (0 = very hard to 5 = very "
            "easy)") in err


def test_answers_of_the_older_form_without_the_questions_report_as_before(study, tmp_path):
    assert main(["report", str(study)]) == 0
    expected = (study / "results.md").read_text()
    older = tmp_path / "older"
    for participant in SESSIONS:
        shutil.copytree(study / participant, older / participant)
        path = older / participant / "questionnaire.json"
        answers = json.loads(path.read_text())["answers"]
        path.write_text(json.dumps(answers, indent=1, sort_keys=True) + "\n")  # as written once
    assert main(["report", str(older)]) == 0
    assert (older / "results.md").read_text() == expected


def test_one_participant_gets_plain_words_instead_of_tests(study, tmp_path, capsys):
    alone = tmp_path / "alone"
    shutil.copytree(study / "P01", alone / "P01")
    assert main(["report", str(alone)]) == 0
    results = (alone / "results.md").read_text()
    assert "1 participant: P01." in results
    rows = [line for line in results.splitlines() if ROW.match(line)]
    assert len(rows) == 4 * 3
    for row in rows:
        who = "answered" if row.startswith(("| tiredness", "| ease")) else "ran"
        assert (f"| 1 | - | n/a (a test needs at least 2 participants who {who} both; 1 "
                "did) | - | - |") in row
    assert "observations" not in results
    # One participant's measures have no spread: each mean stands alone, not "± 0.000".
    assert "±" not in results and "(n = 1) |" in results


def test_an_incomplete_session_is_named_and_counted_for_what_it_has(study, tmp_path, capsys):
    partial = tmp_path / "partial"
    for participant in SESSIONS:
        shutil.copytree(study / participant, partial / participant)
    # P03 stopped after its second method: no teleop run, no teleop answers.
    for path in (partial / "P03" / "trials" / "teleop").glob("seed_*"):
        path.unlink()
    path = partial / "P03" / "questionnaire.json"
    held = json.loads(path.read_text())
    del held["answers"]["teleop"]
    path.write_text(json.dumps(held))
    capsys.readouterr()
    assert main(["report", str(partial)]) == 0
    # It was listed among the participants as any other, its lack said nowhere.
    assert (f"pbp-drake: {partial / 'P03'}: an incomplete session (Teleop not run; Teleop not "
            "answered), counted for the methods it has") in capsys.readouterr().err
    results = (partial / "results.md").read_text()
    assert ("Incomplete: 1 session, each counted for the methods it has: P03 (Teleop not run; "
            "Teleop not answered).") in results
    assert re.search(r"^\| Teleop \| 2 \| \d of 2 \|", results, re.M)
    assert main(["report", str(study)]) == 0
    assert "Incomplete" not in (study / "results.md").read_text()
    assert "incomplete" not in capsys.readouterr().err


@pytest.mark.parametrize("copy, recorded", [("P01_again", True), ("p01", False)])
def test_two_folders_of_one_participant_are_refused(study, tmp_path, capsys, copy, recorded):
    twice = tmp_path / "twice"
    for participant in SESSIONS:
        shutil.copytree(study / participant, twice / participant)
    # The same ID run again into another folder (recorded in study.json), or an older
    # folder's name differing only in case: one person counted as two in every test.
    shutil.copytree(study / "P01", twice / copy)
    if not recorded:
        for name in ("P01", copy):
            path = twice / name / "study.json"
            held = json.loads(path.read_text())
            held.pop("participant", None)  # a folder without a recorded ID
            path.write_text(json.dumps(held))
    assert main(["report", str(twice)]) == 2
    held = "both P01" if recorded else f"P01 and {copy}"
    assert (f"pbp-drake: {twice / 'P01'} and {twice / copy} hold sessions of one participant "
            f"({held}), who would be counted twice") in capsys.readouterr().err
    assert not (twice / "results.md").exists()
