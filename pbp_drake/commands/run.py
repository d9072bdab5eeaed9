"""`pbp-drake run` (one scenario in Meshcat) and `pbp-drake session` (a participant's
session of a user study): their flags, and what both do before anything runs (the paths,
the page's port, the scenario with the command line's overrides, the flags' checks)."""

import sys

from pbp_drake.cli_types import EXIT_DRIVER, realtime_rate
from pbp_drake.commands.run_checks import check_run_flags
from pbp_drake.commands.run_page import add_page_flags, open_page
from pbp_drake.commands.scenario_flags import (
    OPERATOR_ON_A_SCENE, add_goals_flag, add_hardware_flags, add_override_flags,
    add_shorthand_flags, load_with_overrides, scenario_overrides)
from pbp_drake.commands.session import add_session_flags, run_session_command
from pbp_drake.commands.signals import stopping_cleanly
from pbp_drake.commands.task_runs import (
    check_the_bridged_robot_s_hand, on_a_real_arm, run_scene, run_task_loop,
    standing_where_the_arm_stands)
from pbp_drake.console import CAMERAS
from pbp_drake.console.front import bind_page_port
from pbp_drake.output_paths import (
    check_log_path, check_output_folder, check_record_path, same_file)
from pbp_drake.robots import DriverError
from pbp_drake.scenarios import (
    METHODS, ScenarioError, TaskScenario, resolve)
from pbp_drake.scenarios.pilots import ATTENTIVE, PILOT_NAMES, with_pilot
from pbp_drake.studies.toy import scene_scenario


def add_run_command(commands):
    """The `run` and `session` subcommands and their arguments."""
    handler = stopping_cleanly(_run, "run the same command again", sigterm=False)
    run = commands.add_parser("run", help="simulate one scenario in Meshcat")
    run.add_argument("scenario", help="a scenario file, e.g. diagrams/hsr_reach.yaml")
    fields = add_override_flags(run)
    add_shorthand_flags(fields)
    add_goals_flag(fields)
    add_hardware_flags(fields)
    fields.add_argument("--scene", help="use the obstacles of this scene of the file's study")
    fields.add_argument("--pilot", metavar="PILOT",
                        help="a surrogate pilot drives in place of the file's virtual "
                        f"participant, as under `study --pilots`: {', '.join(PILOT_NAMES)} "
                        "(with --seed, a study trial's run again, to watch or --log)")
    _add_common_flags(run, records=True)
    run.add_argument("--no-meshcat", action="store_true",
                     help="no Meshcat server and no page at all (implies --headless)")
    run.add_argument("--record", metavar="FILE.html",
                     help="save a self-contained replay of the run")
    run.add_argument("--log", metavar="FILE.csv", help="HSR tasks: write the per-tick rows to "
                     "this CSV as the task runs (nothing of them kept in memory)")
    run.add_argument("--force", action="store_true",
                     help="let --record (--log) overwrite an existing file that is not a "
                     "replay (time series)")
    run.add_argument("--hand-trail", action="store_true",
                     help="reaching and obstacle tasks: draw the hand's path in the page as "
                     "it grows (pbp-drake teach draws the demonstration so)")
    add_page_flags(run)
    add_session_flags(run, hidden=True)  # `run --participant ID` is `session --participant ID`
    run.set_defaults(handler=handler)

    session = commands.add_parser(
        "session", help="a participant's session of a user study: every method of --methods "
        "once, in an order counterbalanced across participants, each followed by the "
        "questions (`run --participant` does the same)")
    session.add_argument("scenario", help="an HSR task's scenario file, e.g. "
                         "diagrams/hsr_reach.yaml")
    add_session_flags(session)
    fields = add_override_flags(session)
    fields.add_argument("--operator", help="--set operator=...: keyboard or gamepad (a person "
                        "in the browser), virtual (with --answers)")
    fields.add_argument("--duration", type=float, metavar="SECONDS",
                        help="--set duration=SECONDS: each run's time limit")
    fields.add_argument("--seed", type=int,
                        help="--set seed=N: the scene of every run (practice: the next scenes)")
    _add_common_flags(session)
    add_page_flags(session)
    session.set_defaults(handler=handler, method=None, alpha=None, goals=None, scene=None,
                         no_meshcat=False, record=None, log=None, force=False,
                         hardware=False, driver_sim=False, hand_trail=False, pilot=None)


def _add_common_flags(parser, records=False):
    """`--headless`, `--camera` and `--realtime-rate`; `records`: the command has --record."""
    parser.add_argument("--headless", action="store_true",
                        help="no page: simulate as fast as possible and quit at the end"
                        + (" (--record still saves a replay)" if records else ""))
    parser.add_argument("--camera", choices=CAMERAS, default="overview",
                        help="HSR tasks: the page's camera; overview (default, free to "
                        "orbit) or robot (follows the robot from above and behind its head, "
                        "looking down past the hand to the targets)")
    parser.add_argument("--realtime-rate", type=realtime_rate, default=1.0, metavar="RATE",
                        help="target simulated seconds per wall second, positive (default 1; "
                        "--headless runs as fast as possible)")


def scenario_for_run(args):
    """The scenario file of `args` with the command line's overrides, resolved; `--scene`
    then places the obstacles of a scene of the file's study."""
    scenario_file = load_with_overrides(args, scenario_overrides(args))
    scenario = scenario_file.scenario
    if args.alpha is not None and not METHODS[scenario.method].takes_weight:
        weighted = ", ".join(name for name, method in METHODS.items() if method.takes_weight)
        raise ScenarioError(f"--alpha sets the weight of {weighted}; the method is "
                            f"{scenario.method}")
    if args.operator is not None and not isinstance(scenario, TaskScenario):
        raise ScenarioError(OPERATOR_ON_A_SCENE)
    piloted = args.pilot not in (None, ATTENTIVE)
    if piloted:
        try:
            scenario = with_pilot(scenario, args.pilot)
        except ScenarioError as error:
            raise ScenarioError(f"--pilot: {error}") from None
    if on_a_real_arm(scenario):
        return resolve(standing_where_the_arm_stands(scenario))
    if args.scene is None:
        return resolve(scenario) if piloted else scenario_file.resolved
    scenes = getattr(scenario_file.study, "scenes", [])
    names = [scene.name for scene in scenes]
    if not names:
        raise ScenarioError(f"--scene {args.scene!r}: this file's study has no scenes; "
                            "--scene picks one of a 2-D alpha study's (e.g. "
                            "diagrams/toy_alpha_study.yaml)")
    if args.scene not in names:
        raise ScenarioError(f"--scene {args.scene!r} is not in this file's study; "
                            f"scenes: {names}")
    return resolve(scene_scenario(scenario, scenes[names.index(args.scene)]))


def _run(args):
    # The paths first: a bad one must not cost a run, let alone a person's session.
    if args.record is not None:
        check_record_path(args.record, force=args.force)
    if args.log is not None:
        check_log_path(args.log, force=args.force)
        if args.record is not None and same_file(args.record, args.log):
            raise ScenarioError(f"--record and --log both name {args.log}; give each its "
                                "own file")
    if args.output is not None:
        check_output_folder(args.output)
    if args.no_meshcat:
        args.headless = True
    # The page's port before anything is built: taken or forbidden, a one-line refusal.
    listening = None if args.headless else bind_page_port(args.port)
    try:
        resolved = scenario_for_run(args)
        if args.camera == "robot" and (not resolved.has_task or resolved.is_arm):
            raise ScenarioError("--camera robot looks from the HSR's head; this scenario "
                                "has no HSR")
        hardware = getattr(resolved.scenario.robot, "hardware", None)
        if args.camera == "robot" and not resolved.is_arm and hardware and hardware.connect:
            raise ScenarioError("--camera robot looks from the simulated HSR's head; through "
                                "the task-space bridge (robot.hardware.connect) the robot "
                                "is on the far side")
        session = check_run_flags(args, resolved)  # the flags' combinations, before the page
        check_the_bridged_robot_s_hand(resolved)  # last: it waits for the robot
    except BaseException:
        if listening is not None:
            listening.close()
        raise
    meshcat = page = None
    if not args.no_meshcat:
        meshcat, page = open_page(listening, args)
    try:
        if args.participant is not None:
            return run_session_command(args, resolved, meshcat, page, session)
        if resolved.has_task:
            return run_task_loop(args, resolved, meshcat, page)
        return run_scene(args, resolved, meshcat, page)
    except DriverError as error:
        # The robot holds where it was last commanded: the arm's driver keeps that
        # position, and a bridge's relay is told to (docs/tasks/real-arm.md).
        print(f"pbp-drake: {error}", file=sys.stderr)
        return EXIT_DRIVER
    finally:
        if page is not None:
            page.close()
