"""`pbp-drake session`: a participant's session of a user study (`studies.sessions`), each
method of `--methods` run once in an order counterbalanced across participants, each run
followed by the questions, in the page (`run --participant` is the same command)."""

import argparse
import sys

from pbp_drake.builder import build_diagram
from pbp_drake.cli_types import (
    EXIT_FAILED, EXIT_INTERRUPTED, EXIT_STOPPED, EXIT_SUCCESS, EXIT_TERMINATED)
from pbp_drake.commands.run_checks import is_person
from pbp_drake.commands.run_page import (
    PERSON_NEEDS_PAGE, RUN_CHOICES, end_page, keep_page, page_console, wait_for_browser)
from pbp_drake.commands.signals import Terminated, sigterm_as_interrupt
from pbp_drake.commands.task_runs import alpha_of, delete_operator, run_task_once
from pbp_drake.console.front import ENDED_NOTICE
from pbp_drake.console.questionnaire import FixedAnswers, MeshcatSessionPage
from pbp_drake.scenarios import counted
from pbp_drake.studies.questionnaire import QUESTIONNAIRE_FILE, scales_text
from pbp_drake.studies.sessions import resume_text, run_session, session_folder


def add_session_flags(parser, hidden=False):
    """The session's own flags (`hidden`: on `run`, where `--participant` makes a run a
    session, out of its help)."""
    def words(text):
        return argparse.SUPPRESS if hidden else text

    parser.add_argument("--participant", metavar="ID", required=not hidden,
                        help=words("the participant; the order of the methods is "
                                   "counterbalanced across participants"))
    parser.add_argument("--methods", help=words(
        "the methods of the session (default: pbp_alternated,pbp_continuous,teleop)"))
    parser.add_argument("--output", help=words(
        "the session's folder (default: outputs/participants/ID), in the study format "
        "(`pbp-drake report` reads it)"))
    parser.add_argument("--practice", action="store_true", help=words(
        "first one practice run of each method, in the same order on other scenes, saved "
        "apart in ID/practice and never counted in a report"))
    parser.add_argument("--answers", metavar="ANSWERS", help=words(
        f"with --operator virtual: fixed questionnaire answers, {scales_text()}, for "
        "unattended sessions: comma-separated [METHOD:]QUESTION=VALUE (QUESTION tiredness "
        "or ease), e.g. tiredness=3,ease=4,teleop:tiredness=1 (a person answers in the "
        "page)"))


def run_session_command(args, resolved, meshcat, page, session):
    """The session of `args.participant` on the resolved scenario, `session` its
    `(methods, order, answers, on_disk)` from `check_run_flags`; its exit code."""
    scenario = resolved.scenario
    methods, order, answers, on_disk = session
    output = session_folder(args.participant, args.output)
    print(f"Participant {args.participant}: {', '.join(order)}, in this order"
          + (", each practised first" if args.practice else "") + f"; saved in {output}",
          flush=True)
    resuming = resume_text(args.participant, order, on_disk, args.practice)
    if resuming:
        print(resuming, flush=True)
    if answers is not None:
        questions = FixedAnswers(answers)
    else:
        questions = MeshcatSessionPage(meshcat, start_in_run=not args.start_on_connect)
    if page is not None and answers is None:
        # The pages are the person's: no browser, no session (`--answers` needs none).
        print(f"Open {page.url} in a browser (waiting up to {args.wait_for_browser:g} s); "
              "each method starts when its Start is pressed in the page, and the questions "
              "and Next are buttons there too (Open Controls).", flush=True)
        wait_for_browser(page, args.wait_for_browser,
                         PERSON_NEEDS_PAGE if is_person(scenario) else
                         "the session's Start buttons and questions are in the page, so "
                         "nothing was run or saved")

    # Stop ends the session (resumable), Restart runs the method again (the stopped run is
    # not saved), Next scene ends this method's run as it stands (saved, not a success) and
    # goes on to its questions.
    console = (None if page is None
               else page_console(meshcat, page, args, alpha_of(scenario)))

    def run_one(trial):
        # Kept through a Restart: each run of the method starts at its Start.
        start_button = questions.take_start_label() if answers is None else None
        while True:
            diagram = build_diagram(trial, meshcat)
            if console is not None:
                # After the operator's buttons; clicks made on the questions do not count.
                console.set_choices(RUN_CHOICES)
            result, live = run_task_once(args, trial, diagram, meshcat, console,
                                         start_button=start_button)
            delete_operator(diagram)  # the next method may want other keys
            if console is not None:
                console.set_choices(())  # no Stop under the questions
            if live.choice == "stop":
                raise _SessionStopped
            if live.choice != "restart":
                return result
            print(f"Restart: {trial.scenario.method} again, seed {trial.scenario.seed} "
                  "(the stopped run is not saved).", flush=True)

    try:
        # SIGTERM (a `kill`, a `timeout`) stops the session as Ctrl-C does: the running
        # method's leftovers removed, the page and the terminal told.
        with sigterm_as_interrupt():
            summary = run_session(scenario, args.participant, methods, output, run_one,
                                  questions, practice=args.practice)
    except (KeyboardInterrupt, _SessionStopped) as stop:
        stopped = isinstance(stop, _SessionStopped)
        terminated = isinstance(stop, Terminated)
        print(("Stopped in the page" if stopped else
               "\nTerminated (SIGTERM)" if terminated else "\nStopped")
              + f": the methods and answers saved so far are in {output}; the same command "
              "resumes the session.", file=sys.stderr)
        if page is not None:
            end_page(page, console, "The session was stopped; what was saved is kept. "
                     + ENDED_NOTICE)
        return (EXIT_STOPPED if stopped else EXIT_TERMINATED if terminated
                else EXIT_INTERRUPTED)
    failed = [m for m, entry in summary["methods"].items() if entry["success_rate"] < 1.0]
    print(f"Session saved in {output}, answers in {output / QUESTIONNAIRE_FILE} "
          f"(`pbp-drake report {output.parent}` compares the participants).", flush=True)
    if failed:
        runs = (f"the run of {failed[0]} did not reach its target" if len(failed) == 1 else
                f"the runs of {', '.join(failed)} did not reach their targets")
        print(f"pbp-drake: {runs} (exit {EXIT_FAILED}); the session is complete and saved.",
              file=sys.stderr)
    if console is not None:
        console.show_title("Session complete - you can close this page")
        console.show_status(f"{counted(len(order), 'method')} run and answered; thank you.")
        console.clear_result()
        keep_page(args, page, console, ("close",))
        end_page(page, console, "Session complete - you can close this page")
    return EXIT_FAILED if failed else EXIT_SUCCESS


class _SessionStopped(Exception):
    """Stop pressed in the page during a session's run: the session ends, resumable."""
