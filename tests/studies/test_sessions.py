"""A participant's session: its order, the questionnaire's answers and files, practice runs,
resuming after an interruption without asking or overwriting anything again, the bad input
a session or its report refuses (exit 2, the problem named, before Meshcat starts), and an
unattended session on the grasping task with its report."""

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from pbp_drake.builder.run import run_task
from pbp_drake.cli import main
from pbp_drake.console.questionnaire import FixedAnswers
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.studies.questionnaire import (
    QuestionnaireError, parse_answers, read_answers, save_answer)
from pbp_drake.studies.sessions import PRACTICE_SEED_OFFSET, run_session, session_order
from pbp_drake.studies.trial_files import trial_paths

TASK = "diagrams/hsr_reach.yaml"
METHODS = ["pbp_alternated", "pbp_continuous", "teleop"]
ANSWERS = "tiredness=3,ease=4,teleop:tiredness=1"


@pytest.fixture(scope="module")
def short_task(repo):
    """hsr_reach with a 1.5 s limit: every run is short, its files are real."""
    return dataclasses.replace(load_scenario_file(repo / TASK).scenario, duration=1.5)


def session_files(output, methods):
    """Bytes and modification time of each method's trial files."""
    files = {}
    for method in methods:
        for path in trial_paths(output, method, 0):
            files[path] = (path.read_bytes(), path.stat().st_mtime_ns)
    return files


def test_the_order_rotates_with_the_participant_number():
    orders = [session_order(METHODS, f"P{n:02d}") for n in range(3)]
    assert orders == [METHODS, METHODS[1:] + METHODS[:1], METHODS[2:] + METHODS[:2]]
    for place in range(3):  # each method once in each place over three participants
        assert sorted(order[place] for order in orders) == sorted(METHODS)
    # An ID without digits is placed by a hash of it that every run computes the same.
    assert session_order(METHODS, "alice") == METHODS[1:] + METHODS[:1]
    assert session_order(METHODS, "carol") == METHODS[2:] + METHODS[:2]


def test_fixed_answers_hold_for_every_method_unless_a_method_overrides_them():
    answers = parse_answers(ANSWERS, METHODS)
    assert answers == {"pbp_alternated": {"tiredness": 3, "ease": 4},
                       "pbp_continuous": {"tiredness": 3, "ease": 4},
                       "teleop": {"tiredness": 1, "ease": 4}}


@pytest.mark.parametrize("text, message", [
    ("tiredness=6,ease=4", "the answer 6 is outside 0 to 5 (0 = very tired to 5 = not tired "
     "at all)"),
    ("tiredness=3,ease=-1", "the answer -1 is outside 0 to 5 (0 = very hard to 5 = very easy)"),
    ("tiredness=3", "no ease for pbp_alternated"),
    ("tiredness=3,ease=four", "'four' is not a whole number 0 to 5 (0 = very hard to 5 = very "
     "easy)"),
    ("tired=3,ease=4", "unknown question 'tired'"),
    ("fixed_alpha:tiredness=3,ease=4", "'fixed_alpha' is not one of the participant's methods"),
    ("tiredness 3,ease=4", "'tiredness 3' is not "),  # not [METHOD:]QUESTION=VALUE
    # An answer given twice: was the last one, in silence.
    ("tiredness=3,ease=4,tiredness=1", "--answers: tiredness is answered twice"),
    ("teleop:ease=1,tiredness=3,ease=4,teleop:ease=2", "--answers: teleop:ease is answered twice"),
])
def test_bad_fixed_answers_are_named(text, message):
    with pytest.raises(QuestionnaireError, match=message.replace("(", r"\(").replace(")", r"\)")):
        parse_answers(text, METHODS)


def test_a_saved_answer_is_never_overwritten(tmp_path):
    save_answer(tmp_path, "teleop", "tiredness", 2)
    with pytest.raises(QuestionnaireError, match="already answered"):
        save_answer(tmp_path, "teleop", "tiredness", 5)
    with pytest.raises(QuestionnaireError, match="outside 0"):
        save_answer(tmp_path, "teleop", "ease", 9)
    assert read_answers(tmp_path) == {"teleop": {"tiredness": 2}}


@pytest.mark.parametrize("argv, message", [
    (["--participant", "lab/P07", "--answers", ANSWERS], "holds a path separator"),
    (["--participant", "..", "--answers", ANSWERS], "not only dots"),
    (["--participant", "P07", "--answers", "tiredness=7,ease=4"],
     "the answer 7 is outside 0 to 5 (0 = very tired to 5 = not tired at all)"),
    (["--participant", "P07"], "a --headless session needs --answers"),
    (["--participant", "P07", "--answers", ANSWERS, "--operator", "keyboard"],
     "--answers stands in for a person's answers"),
    (["--answers", ANSWERS], "belong to a session: add --participant ID"),
    (["--participant", "P07", "--answers", ANSWERS, "--log", "run.csv"],
     "a session saves every run under --output"),
    (["--participant", "P07", "--methods", "teleop,nope", "--answers", ANSWERS],
     "'nope' is unknown"),
    (["--participant", "P07", "--answers", ANSWERS, "--no-meshcat"],
     "a session shows each run in the page"),
])
@pytest.mark.parametrize("task", [TASK, "diagrams/hsr_grasp.yaml"])
def test_a_bad_session_stops_before_it_runs(repo, tmp_path, capsys, monkeypatch, argv,
                                            message, task):
    monkeypatch.chdir(tmp_path)
    output = tmp_path / "P07"
    argv = ["run", str(repo / task), "--headless", "--operator", "virtual", "--output",
            str(output), *argv]
    if "keyboard" in argv:
        argv.remove("--headless")
    assert main(argv) == 2
    captured = capsys.readouterr()
    err = captured.err
    assert err.startswith("pbp-drake: ") and message in err and "Traceback" not in err
    # Refused before the Meshcat server starts, and before anything is written.
    assert "Meshcat" not in captured.out
    assert not output.exists() and not (tmp_path / "run.csv").exists()


@pytest.mark.slow
def test_an_interrupted_session_resumes_where_it_stopped(short_task, tmp_path):
    output = tmp_path / "P00"
    order = session_order(METHODS, "P00")
    ran = []

    def interrupted_at_second(trial):
        if trial.scenario.seed == short_task.seed:  # the recorded runs, after practice
            if ran:
                raise KeyboardInterrupt  # Ctrl-C during the second method
            ran.append(trial.scenario.method)
        return run_task(trial)

    first = FixedAnswers(parse_answers(ANSWERS, METHODS))
    with pytest.raises(KeyboardInterrupt):
        run_session(short_task, "P00", METHODS, output, interrupted_at_second, first,
                    practice=True)
    assert ran == [order[0]]
    assert first.asked == [(order[0], "tiredness"), (order[0], "ease")]
    saved = session_files(output, order[:1])
    practice = sorted(p.name for p in (output / "practice" / "trials").rglob("*.json"))
    assert practice == [f"seed_{PRACTICE_SEED_OFFSET}.json"] * 3

    # Stopped again, this time between the second method's two questions.
    class StopsAtEase(FixedAnswers):
        def answer(self, method, question):
            if method == order[1] and question == "ease":
                raise KeyboardInterrupt
            return super().answer(method, question)

    second = StopsAtEase(parse_answers(ANSWERS, METHODS))
    with pytest.raises(KeyboardInterrupt):
        run_session(short_task, "P00", METHODS, output, run_task, second, practice=True)
    assert second.asked == [(order[1], "tiredness")]
    assert trial_paths(output, order[1], 0)[0].is_file()

    third = FixedAnswers(parse_answers(ANSWERS, METHODS))
    reran = []
    summary = run_session(short_task, "P00", METHODS, output,
                          lambda trial: reran.append(trial.scenario.method) or run_task(trial),
                          third, practice=True)
    # Nothing saved is run, asked or written again; the rest of the session is done.
    assert reran == [order[2]]
    assert third.asked == [(order[1], "ease"), (order[2], "tiredness"), (order[2], "ease")]
    assert session_files(output, order[:1]) == saved
    assert sorted(summary["methods"]) == sorted(METHODS)
    assert all(entry["trials"] == 1 for entry in summary["methods"].values())
    assert read_answers(output) == parse_answers(ANSWERS, METHODS)
    assert sorted(p.name for p in (output / "practice" / "trials").rglob("*.json")) == practice


@pytest.mark.slow
def test_a_session_refuses_a_folder_of_another_scenario(repo, tmp_path, capsys):
    output = tmp_path / "P01"
    base = ["run", str(repo / TASK), "--headless", "--operator", "virtual", "--participant",
            "P01", "--methods", "teleop", "--answers", ANSWERS, "--output", str(output)]
    assert main([*base, "--duration", "1"]) in (0, 1)
    saved = session_files(output, ["teleop"])
    capsys.readouterr()
    assert main([*base, "--duration", "1.5"]) == 2
    err = capsys.readouterr().err
    assert "holds a study of another scenario" in err and "choose another --output" in err
    # What differs is named, so that a person sees which setting to put back.
    assert "; duration 1.0 there, 1.5 here): choose another --output folder" in err
    assert session_files(output, ["teleop"]) == saved


@pytest.mark.slow
def test_an_unattended_session_on_the_grasping_task_and_its_report(repo, tmp_path, capsys):
    study = tmp_path / "grasp_study"
    output = study / "P04"
    assert main(["run", str(repo / "diagrams" / "hsr_grasp.yaml"), "--headless", "--operator",
                 "virtual", "--participant", "P04", "--answers", ANSWERS, "--duration", "3",
                 "--output", str(output)]) == 1  # 3 s is too short to grasp
    assert capsys.readouterr().err.endswith(
        "pbp-drake: the runs of pbp_continuous, teleop, pbp_alternated did not reach their "
        "targets (exit 1); the session is complete and saved.\n")
    for method in METHODS:
        record_path, csv_path = trial_paths(output, method, 0)
        record = json.loads(record_path.read_text())
        assert record["error"] is None and record["final_angle_to_target"] is not None
        # The trial's rows hold the grasping task's orientation columns.
        assert "angle_to_target" in csv_path.read_text().splitlines()[0].split(",")
    assert read_answers(output) == parse_answers(ANSWERS, METHODS)
    capsys.readouterr()
    assert main(["report", str(study)]) == 0
    results = (study / "results.md").read_text()
    assert "| P04 |" in results and (study / "fig8_questionnaire.png").is_file()


@pytest.mark.slow
def test_a_participant_folder_takes_no_other_participant_and_no_second_session(
        repo, tmp_path, capsys):
    output = tmp_path / "P01"

    def session(participant, *more):
        return main(["session", str(repo / TASK), "--headless", "--operator", "virtual",
                     "--participant", participant, "--answers", ANSWERS, "--duration", "1",
                     "--methods", "teleop", "--output", str(output), *more])

    assert session("P01") in (0, 1)
    saved = session_files(output, ["teleop"])
    answers = (output / "questionnaire.json").read_bytes()
    assert json.loads((output / "study.json").read_text())["participant"] == "P01"
    capsys.readouterr()
    # A second participant given the first one's folder by mistake: their runs and answers
    # were taken as P01's (and the order recorded was P02's).
    assert session("P02") == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pbp-drake: {output} holds the session of participant P01, not "
                          "P02: resume it with --participant P01, or give P02 a folder of")
    # The same command once the session is complete: the page said "Session complete"
    # having run nothing, and a person sat down for nothing.
    assert session("P01") == 2
    err = capsys.readouterr().err
    assert "holds P01's complete session (teleop, each run and answered): nothing to run" in err
    assert session_files(output, ["teleop"]) == saved
    assert (output / "questionnaire.json").read_bytes() == answers


@pytest.mark.slow
def test_a_session_resumed_on_another_seed_is_refused(repo, tmp_path, capsys):
    output = tmp_path / "P01"
    base = ["session", str(repo / TASK), "--headless", "--operator", "virtual",
            "--participant", "P01", "--answers", ANSWERS, "--duration", "1", "--methods",
            "teleop", "--output", str(output)]
    assert main(base) in (0, 1)
    saved = session_files(output, ["teleop"])
    capsys.readouterr()
    # The scene is outside the scenario's hash: the session ran again on seed 5 for the
    # same person, teleop's answers (given on seed 0) kept beside its seed-5 run.
    assert main([*base, "--seed", "5"]) == 2
    assert (f"pbp-drake: {output} holds a session on the scene of --seed 0; this one's is "
            "--seed 5: resume it with --seed 0") in capsys.readouterr().err
    assert session_files(output, ["teleop"]) == saved
    assert not trial_paths(output, "teleop", 5)[0].exists()


@pytest.mark.slow
def test_a_resumed_session_keeps_its_methods_and_says_where_it_resumes(
        repo, short_task, tmp_path, capsys):
    output = tmp_path / "P01"
    order = session_order(METHODS, "P01")

    def stops_at_second(trial):
        if trial.scenario.method != order[0]:
            raise KeyboardInterrupt
        return run_task(trial)

    with pytest.raises(KeyboardInterrupt):
        run_session(short_task, "P01", METHODS, output, stops_at_second,
                    FixedAnswers(parse_answers(ANSWERS, METHODS)))
    saved = session_files(output, order[:1])
    base = ["session", str(repo / TASK), "--headless", "--operator", "virtual",
            "--participant", "P01", "--answers", ANSWERS, "--duration", "1.5",
            "--output", str(output)]
    # Other methods, so another order: the first method's run and answers were kept beside
    # a study.json of other methods, and the counterbalanced order was lost.
    assert main([*base, "--methods", "teleop,pbp_continuous"]) == 2
    err = capsys.readouterr().err
    assert (f"{output} holds P01's session begun with the methods in the order "
            f"{', '.join(order)}; this one's order is pbp_continuous, teleop: resume it with "
            "the --methods it began with (--methods pbp_alternated,pbp_continuous,teleop)"
            in err)
    assert main([*base, "--practice"]) in (0, 1)
    out = capsys.readouterr().out
    assert (f"Resuming P01's session: {order[0]} saved, not run again; no practice (recorded "
            f"runs exist); next: {order[1]}, method 2 of 3, from its start.\n") in out
    assert session_files(output, order[:1]) == saved


@pytest.mark.parametrize("existing", ["p07", "P07"])
def test_a_participant_folder_beside_one_differing_only_in_case_is_refused(
        repo, tmp_path, capsys, existing):
    (tmp_path / existing).mkdir()
    other = existing.swapcase()
    assert main(["session", str(repo / TASK), "--headless", "--operator", "virtual",
                 "--participant", other, "--answers", ANSWERS,
                 "--output", str(tmp_path / other)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pbp-drake: {tmp_path / existing} is beside {tmp_path / other}, "
                          "their names differing only in case")
    assert f"Resume with the ID of {existing}" in err and not (tmp_path / other).exists()


@pytest.mark.slow
def test_sigterm_stops_a_session_as_ctrl_c_and_the_same_command_resumes(repo, tmp_path):
    output = tmp_path / "P01"
    order = session_order(METHODS, "P01")
    command = [sys.executable, "-m", "pbp_drake", "session", str(repo / TASK), "--headless",
               "--operator", "virtual", "--participant", "P01", "--answers", ANSWERS,
               "--duration", "60", "--output", str(output)]
    env = dict(os.environ, PYTHONPATH=str(repo))
    session = subprocess.Popen(command, env=env, text=True, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE)
    second = trial_paths(output, order[1], 0)[0].with_suffix(".running")
    deadline = time.monotonic() + 120
    while not second.exists():  # the second method is running
        assert session.poll() is None and time.monotonic() < deadline, "no second method"
        time.sleep(0.01)
    session.send_signal(signal.SIGTERM)
    _, err = session.communicate(timeout=60)
    # It died at once, without a word, leaving the running method's marker.
    assert session.returncode == 143, err
    assert err.endswith(f"Terminated (SIGTERM): the methods and answers saved so far are in "
                        f"{output}; the same command resumes the session.\n")
    assert [p for p in output.rglob("*") if p.suffix in (".tmp", ".running")] == []
    assert trial_paths(output, order[0], 0)[0].is_file()
    assert not trial_paths(output, order[1], 0)[0].exists()
    saved = session_files(output, order[:1])

    resumed = subprocess.run(command, env=env, capture_output=True, text=True)
    assert resumed.returncode in (0, 1), resumed.stderr
    assert (f"Resuming P01's session: {order[0]} saved, not run again; next: {order[1]}, "
            "method 2 of 3, from its start.") in resumed.stdout
    assert session_files(output, order[:1]) == saved
    assert read_answers(output) == parse_answers(ANSWERS, METHODS)
