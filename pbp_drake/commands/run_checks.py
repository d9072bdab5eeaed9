"""The checks of `pbp-drake run`'s flags against each other and against the scenario, made
before the Meshcat server starts: a combination `run` refuses costs no page, no port and no
run, and is named in one line (ScenarioError: `pbp-drake: ...`, exit 2)."""

from pbp_drake.cli_types import chosen_methods
from pbp_drake.commands.run_page import page_flags_given
from pbp_drake.scenarios import Gamepad, GraspTask, Keyboard, ScenarioError, with_method
from pbp_drake.studies.questionnaire import parse_answers
from pbp_drake.studies.sessions import (
    DEFAULT_SESSION_METHODS, check_session_folder, session_folder, session_order)


def check_run_flags(args, resolved):
    """Raises ScenarioError for flags of `run` (the parsed `args`) that do not go together,
    or not with the resolved scenario (`--no-meshcat` implies `--headless`). Returns a
    session's `(methods, order, answers, on_disk)` (`--answers` parsed, or None; on_disk
    the SessionOnDisk of its folder, which it can take), else None."""
    if args.no_meshcat and (args.record or args.camera == "robot"):
        raise ScenarioError("--record and --camera robot need the page: drop --no-meshcat")
    if args.headless and (page_flags := page_flags_given(args)):
        raise ScenarioError(f"{', '.join(page_flags)}: the page's flags; --headless has no "
                            "page (drop them, or --headless)")
    _check_hand_trail(args, resolved)
    if not resolved.has_task:
        _check_scene_flags(args)
        return
    person = is_person(resolved.scenario)
    if args.no_meshcat and person:
        raise ScenarioError("--no-meshcat: a keyboard or gamepad is read in the page; use "
                            "--operator virtual")
    if args.headless and person:
        raise ScenarioError("--headless runs unattended: a person cannot drive it; use "
                            "--operator virtual")
    if args.participant is None:
        if args.methods is not None or args.output is not None or args.practice or args.answers:
            raise ScenarioError("--methods, --output, --practice and --answers belong to a "
                                "session: add --participant ID")
        return None
    if args.no_meshcat:
        raise ScenarioError("--participant: a session shows each run in the page; drop "
                            "--no-meshcat")
    if args.record or args.log:
        raise ScenarioError("--record and --log save one run; a session saves every run under "
                            "--output")
    methods = (list(DEFAULT_SESSION_METHODS) if args.methods is None
               else chosen_methods(args.methods, ",".join(DEFAULT_SESSION_METHODS)))
    for method in methods:
        with_method(resolved.scenario, method)
    try:
        order = session_order(methods, args.participant)
    except ValueError as error:
        raise ScenarioError(f"--participant: {error}") from None
    answers = None
    if args.answers is not None:
        if person:
            raise ScenarioError("--answers stands in for a person's answers: it goes with "
                                "--operator virtual; a keyboard or gamepad participant "
                                "answers in the page")
        answers = parse_answers(args.answers, methods)
    elif args.headless:
        raise ScenarioError("a --headless session needs --answers (e.g. --answers "
                            "tiredness=3,ease=4): otherwise the questions are asked in the "
                            "browser")
    on_disk = check_session_folder(resolved.scenario, args.participant, methods,
                                   session_folder(args.participant, args.output))
    return methods, order, answers, on_disk


def _check_hand_trail(args, resolved):
    """--hand-trail draws in the page of a reaching or obstacle task only: elsewhere it
    would be taken and do nothing."""
    if not args.hand_trail:
        return
    if args.no_meshcat:
        raise ScenarioError("--hand-trail draws the hand's path in the page: drop --no-meshcat")
    if not resolved.has_task:
        raise ScenarioError("--hand-trail draws a reaching or obstacle task's hand path; this "
                            "scenario uses the 2-D toy robot, whose page draws its path")
    if isinstance(resolved.scenario.task, GraspTask):
        raise ScenarioError("--hand-trail draws a reaching or obstacle task's hand path; the "
                            "grasping task draws none")


def is_person(scenario):
    """A person drives the scenario's robot from the page (keyboard or gamepad)."""
    return isinstance(scenario.operator, (Keyboard, Gamepad))


def _check_scene_flags(args):
    """A 2-D scene has no task to log nor session to run."""
    if args.log:
        raise ScenarioError("--log streams an HSR task's per-tick rows; this scenario uses "
                            "the 2-D toy robot")
    session = [flag for flag, value in (("--participant", args.participant),
                                        ("--methods", args.methods),
                                        ("--output", args.output),
                                        ("--practice", args.practice),
                                        ("--answers", args.answers)) if value]
    if session:
        raise ScenarioError(f"{', '.join(session)}: user-study sessions run the HSR tasks; "
                            "this scenario uses the 2-D toy robot")
