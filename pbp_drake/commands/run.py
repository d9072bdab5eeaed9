"""`pbp-drake run`: one scenario in Meshcat, or a participant's session of a user study."""

import dataclasses
import functools
import logging
import pathlib
import sys
import time

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams

from pbp_drake.builder import (
    build_diagram, check_buildable, find_system, run_task, run_task_streamed, simulate)
from pbp_drake.cli_types import (
    EXIT_FAILED, EXIT_INTERRUPTED, EXIT_STOPPED, EXIT_SUCCESS, EXIT_WRITE_FAILED, port,
    realtime_rate, token, wait_seconds)
from pbp_drake.commands.run_checks import check_run_flags, is_person, session_methods
from pbp_drake.console import (
    CAMERAS, Console, LiveRun, Progress, RobotCamera, method_name, result_text)
from pbp_drake.console.front import PageFront, PortError, bind_page_port
from pbp_drake.console.questionnaire import FixedAnswers, MeshcatSessionPage, start_label
from pbp_drake.core.reach_task import sample_grid_scene
from pbp_drake.core.toy_scene import collision_ratio
from pbp_drake.output_paths import (
    check_log_path, check_output_folder, check_record_path, recorded_replay)
from pbp_drake.scenarios import (
    METHODS, OPERATOR_NAMES, Gamepad, GraspTask, MultiGoalReach, ScenarioError, TASK_ROBOTS,
    counted, load_scenario_file, resolve)
from pbp_drake.scenarios.bounds import MAX_GOALS
from pbp_drake.studies.questionnaire import QUESTIONNAIRE_FILE, parse_answers, scales_text
from pbp_drake.studies.atomic_files import (
    is_disk_failure, write_atomically, write_failure_line)
from pbp_drake.studies.sessions import run_session

#: The choices in the page while a task runs, and after it has ended.
RUN_CHOICES = ("stop", "restart", "next")
AFTER_RUN_CHOICES = ("restart", "next", "close")
PAGE_ENDED = "This run has ended; you can close this page."
# Why a keyboard or gamepad run stops when no browser opens its page.
PERSON_NEEDS_PAGE = ("the keyboard and gamepad are read in the page, so nothing was run or "
                     "recorded")


# The most objects `--goals` places: as many as a scenario file may hold.
MOST_GRID_GOALS = MAX_GOALS


def add_run_command(commands):
    """The `run` subcommand and its arguments."""
    run = commands.add_parser("run", help="simulate one scenario in Meshcat")
    run.add_argument("scenario", help="a scenario file, e.g. diagrams/toy_alpha_study.yaml")
    run.add_argument("--method", help=f"override the scenario's method: {', '.join(METHODS)}")
    run.add_argument("--alpha", type=float, help="override alpha (fixed_alpha)")
    run.add_argument("--scene", help="use the obstacles of this scene of the file's study")
    run.add_argument("--operator", help="HSR tasks: who drives, one of "
                     f"{', '.join(OPERATOR_NAMES)} (keyboard and gamepad: in the browser)")
    run.add_argument("--seed", type=int, help="HSR tasks: the seed of the scene and the noise")
    run.add_argument("--goals", type=int, metavar="K",
                     help="reaching task: K objects (candidate goals, up to "
                     f"{MOST_GRID_GOALS:,}), one in each cell of a grid over the task's "
                     "region drawn from the seed, in place of the file's")
    run.add_argument("--participant", metavar="ID",
                     help="HSR tasks: a user-study session; every method of --methods once, "
                     "in an order counterbalanced across participants, saved in the study "
                     "format under --output (`pbp-drake report` reads it)")
    run.add_argument("--methods", help="with --participant: the methods of the session "
                     "(default: pbp_alternated,pbp_continuous,teleop)")
    run.add_argument("--output", help="with --participant: the session's folder "
                     "(default: outputs/participants/ID)")
    run.add_argument("--practice", action="store_true",
                     help="with --participant: first one practice run of each method, in "
                     "the same order on other scenes, saved apart in ID/practice and never "
                     "counted in a report")
    run.add_argument("--answers", metavar="ANSWERS",
                     help="with --participant and --operator virtual: fixed questionnaire "
                     f"answers, {scales_text()}, for unattended sessions: comma-separated "
                     "[METHOD:]QUESTION=VALUE (QUESTION tiredness or ease), e.g. "
                     "tiredness=3,ease=4,teleop:tiredness=1 (a person answers in the page)")
    run.add_argument("--headless", action="store_true",
                     help="no page: simulate as fast as possible and quit at the end "
                     "(--record still saves a replay)")
    run.add_argument("--no-meshcat", action="store_true",
                     help="no Meshcat server and no page at all (implies --headless)")
    run.add_argument("--camera", choices=CAMERAS, default="overview",
                     help="HSR tasks: the page's camera; overview (default, free to orbit) "
                     "or robot (follows the robot from above and behind its head, looking "
                     "down past the hand to the targets)")
    run.add_argument("--record", metavar="FILE.html",
                     help="save a self-contained replay of the run")
    run.add_argument("--log", metavar="FILE.csv", help="HSR tasks: write the per-tick rows to "
                     "this CSV as the task runs (nothing of them kept in memory)")
    run.add_argument("--force", action="store_true",
                     help="let --record (--log) overwrite an existing file that is not a "
                     "replay (time series)")
    run.add_argument("--duration", type=float, metavar="SECONDS",
                     help="override the scenario's duration (for HSR tasks, the time limit)")
    run.add_argument("--realtime-rate", type=realtime_rate, default=1.0, metavar="RATE",
                     help="target simulated seconds per wall second, positive (default 1; "
                     "--headless runs as fast as possible)")
    run.add_argument("--port", type=port, default=0,
                     help="the page's port, 0..65535 (default 0: a free one); one in use "
                     "is refused before anything is built")
    run.add_argument("--token", type=token,
                     help="the page's secret (16 to 128 letters, digits, '-' or '_'; default: "
                     "a random one): only a browser that opens the printed URL, which holds "
                     "it, gets the page and can drive")
    run.add_argument("--start-on-connect", action="store_true",
                     help="keyboard and gamepad runs: start the task as soon as the page "
                     "connects, as a script wants, instead of at the page's Start button")
    run.add_argument("--keep-page", type=wait_seconds, default=600.0, metavar="SECONDS",
                     help="after the run, keep the page with its result served until it is "
                     "closed, its Close button is pressed, or this many seconds pass "
                     "(default 600)")
    run.add_argument("--wait-for-browser", type=wait_seconds, default=15.0, metavar="SECONDS",
                     help="before starting, wait this long for a browser to open the page "
                     "(default 15); a keyboard or gamepad run that no browser joins in time "
                     "stops with exit 2, having run and recorded nothing")
    run.set_defaults(handler=_saying_write_failures(_run))


def scenario_for_run(scenario_file, method=None, alpha=None, scene=None, operator=None,
                     seed=None, duration=None, goals=None):
    """The file's resolved scenario with the command line's overrides applied: resolved again
    only when an override changes what is derived (a method or alpha does not)."""
    scenario = scenario_file.scenario
    if duration is not None:
        if not (np.isfinite(duration) and duration > 0):
            raise ScenarioError(f"--duration {duration:g} must be a positive number of "
                                "seconds")
        scenario = dataclasses.replace(scenario, duration=duration)
    if operator is not None:
        if operator not in OPERATOR_NAMES:
            raise ScenarioError(f"--operator {operator!r} is unknown; choose one of "
                                f"{list(OPERATOR_NAMES)}")
        if not isinstance(scenario.robot, TASK_ROBOTS):
            raise ScenarioError("--operator chooses who drives the tasks; this scenario "
                                "uses the 2-D toy robot")
        if not isinstance(scenario.operator, OPERATOR_NAMES[operator]):
            scenario = dataclasses.replace(scenario, operator=OPERATOR_NAMES[operator]())
    if seed is not None:
        scenario = dataclasses.replace(scenario, seed=seed)
    if goals is not None:
        scenario = with_grid_goals(scenario, goals)
    if scene is not None:
        scenes = getattr(scenario_file.study, "scenes", [])
        names = [s.name for s in scenes]
        if scene not in names:
            raise ScenarioError(f"--scene {scene!r} is not in this file's study; scenes: {names}")
        chosen = scenes[names.index(scene)]
        scenario = dataclasses.replace(scenario, name=f"{scenario.name}/{scene}",
                                       obstacles=list(chosen.obstacles))
    try:
        resolved = (scenario_file.resolved if scenario is scenario_file.scenario
                    else resolve(scenario))
        method = method or scenario.method
        if alpha is not None:
            if method != "fixed_alpha":
                raise ScenarioError(f"--alpha sets the weight of fixed_alpha; the method is "
                                    f"{method}")
            method = f"fixed_alpha={alpha}"
        if method != scenario.method or alpha is not None:
            resolved = resolved.with_method(method)
    except ScenarioError as error:
        raise ScenarioError(f"{error} (after the command-line overrides)") from None
    return resolved


def with_grid_goals(scenario, count):
    """`scenario` (a reaching task) with `count` objects on a grid over its region
    (`core.reach_task.sample_grid_scene`, from its seed) in place of its own."""
    task = scenario.task
    if type(task) is not MultiGoalReach or task.objects:
        raise ScenarioError("--goals places the objects of a reaching task drawn from its "
                            "seed (an untagged task without fixed objects)")
    least = 2 if len(task.switch_schedule) > 1 else 1
    if not least <= count <= MOST_GRID_GOALS:
        raise ScenarioError(f"--goals {count} is out of range; expected {least} to "
                            f"{MOST_GRID_GOALS:,}")
    layout, separation = sample_grid_scene(
        scenario.seed, count, task.x_range, task.y_range, task.height,
        task.switch_schedule, task.z_range or None)
    task = dataclasses.replace(task, objects=layout.objects.tolist(),
                               targets=list(layout.targets),
                               min_separation=min(task.min_separation, 0.9 * separation))
    return dataclasses.replace(scenario, task=task)


def _run(args):
    # The paths first: a bad one must not cost a run, let alone a person's session.
    if args.record:
        check_record_path(args.record, force=args.force)
    if args.log:
        check_log_path(args.log, force=args.force)
    if args.output is not None:
        check_output_folder(args.output)
    if args.no_meshcat:
        args.headless = True
    # The page's port before anything is built: taken or forbidden, a one-line refusal.
    listening = None
    if not args.headless:
        try:
            listening = bind_page_port(args.port)
        except PortError as error:
            raise ScenarioError(str(error)) from None
    try:
        resolved = scenario_for_run(load_scenario_file(args.scenario), args.method,
                                    args.alpha, args.scene, args.operator, args.seed,
                                    args.duration, args.goals)
        check_buildable(resolved)  # before the page opens: what the builder cannot build
        if args.camera == "robot" and (not resolved.has_task or resolved.is_arm):
            raise ScenarioError("--camera robot looks from the HSR's head; this scenario "
                                "has no HSR")
        check_run_flags(args, resolved)  # and the flags' combinations, before the page too
    except BaseException:
        if listening is not None:
            listening.close()
        raise
    meshcat = page = None
    if not args.no_meshcat:
        meshcat = _private_meshcat()
    if listening is not None:
        # The page people open: our front, which lets in only who holds the printed URL.
        page = PageFront(meshcat.port(), listening, token=args.token)
        print(f"Meshcat: {page.url}", flush=True)
    try:
        if resolved.has_task:
            return _run_task(args, resolved, meshcat, page)
        return _run_scene(args, resolved, meshcat, page)
    finally:
        if page is not None:
            page.close()


def _private_meshcat():
    """Meshcat on a random free localhost port that nobody is told of (the page front
    relays to it; Drake's `port=None` would take the first free one from 7000, easy to
    guess), without Drake's line announcing its URL."""
    drake_log = logging.getLogger("drake")
    level = drake_log.level
    drake_log.setLevel(logging.WARNING)
    try:
        return Meshcat(MeshcatParams(host="localhost", port=0))
    finally:
        drake_log.setLevel(level)


def _run_scene(args, resolved, meshcat, page):
    """A 2-D scene: live in the page (its console has Stop alone) for its duration."""
    scenario = resolved.scenario
    diagram = build_diagram(resolved, meshcat)
    console = None
    if page is not None:
        console = _console(meshcat, page, args, scenario, choices=("stop",))
        console.show_title(method_name(scenario.method, _alpha(scenario)))
        if _terminal():  # someone may be watching
            _wait_for_browser(page, args.wait_for_browser)
    if args.record:
        meshcat.StartRecording(frames_per_second=30.0)
    live = LiveRun(diagram, scenario.duration, console, Progress(scenario.duration))
    trajectory = simulate(resolved, realtime_rate=0.0 if args.headless else args.realtime_rate,
                          diagram=diagram, advance=live.advance)
    ratio = collision_ratio(trajectory.positions, [o.center for o in scenario.obstacles],
                            [o.radius for o in scenario.obstacles])
    outcome = (f"stopped at {trajectory.times[-1]:.1f} s" if live.choice == "stop"
               else f"done, collision ratio {ratio:.3f}")
    if args.record:
        _save_recording(meshcat, args.record)
    print(f"{scenario.name} [{scenario.method}]: "
          + (f"{outcome}, " if live.choice == "stop" else "") + "final position "
          f"{np.array2string(trajectory.positions[-1], precision=3)}, collision ratio "
          f"{ratio:.3f}, intervention ratio {trajectory.operator_active.mean():.3f}",
          flush=True)
    code = EXIT_STOPPED if live.choice == "stop" else 0
    if console is not None:
        console.show_result(outcome)
        if live.choice is None:
            _keep_page(args, page, console, ("close",))
        page.end(PAGE_ENDED)
    return code


def _run_task(args, resolved, meshcat, page):
    scenario = resolved.scenario
    person = is_person(scenario)
    if args.participant is not None:
        return _run_session(args, resolved, meshcat, page, person)
    console = None
    if page is not None:
        console = _console(meshcat, page, args, scenario)
    first = True
    while True:
        scenario = resolved.scenario
        diagram = build_diagram(resolved, meshcat)
        if console is not None:
            # After the operator's buttons, which the build added: the same order each run.
            console.set_choices(RUN_CHOICES)
        if first and page is not None and (person or _terminal()):
            # A person needs the page open before the task starts.
            print(f"Open {page.url} in a browser (waiting up to {args.wait_for_browser:g} s); "
                  + ("the task starts when it connects." if not _start_gate(args, person) else
                     "the task starts when Start is pressed in the page."), flush=True)
            if person:
                print(_controls_line(scenario), flush=True)
            _wait_for_browser(page, args.wait_for_browser,
                              PERSON_NEEDS_PAGE if person else None)
        first = False
        result, live = _run_task_once(args, resolved, diagram, meshcat, console,
                                      start_button="Start" if _start_gate(args, person)
                                      else None)
        code = _task_code(result, live)
        if console is None:
            return code
        choice = live.choice
        if choice is None:
            choice = _keep_page(args, page, console, AFTER_RUN_CHOICES)
        if choice in (None, "stop", "close"):
            page.end(PAGE_ENDED)
            return code
        operator = diagram.GetSubsystemByName("operator")
        if hasattr(operator, "Delete"):
            operator.Delete()  # the next build adds its buttons again
        if choice == "next":
            resolved = resolve(dataclasses.replace(scenario, seed=scenario.seed + 1))
        print(f"{'Restart' if choice == 'restart' else 'Next scene'}: seed "
              f"{resolved.scenario.seed}.", flush=True)


def _controls_line(scenario):
    """What the person's keys or gamepad do, printed before the task starts: the grasping
    task steers the hand in six DoF, the reaching task in four."""
    if not isinstance(scenario.task, GraspTask):
        return "Keys: arrows move the hand (forward only in teleop), Q and E turn it."
    if isinstance(scenario.operator, Gamepad):
        return ("Gamepad: left stick moves the hand (forward only in teleop), triggers raise "
                "(RT) and lower (LT) it; right stick yaws and pitches, shoulders roll.")
    return ("Keys: arrows move the hand (forward only in teleop), PageUp/PageDown raise and "
            "lower it; R switches to turning (arrows pitch and yaw, PageUp/PageDown roll).")


def _run_task_once(args, resolved, diagram, meshcat, console, start_button=None):
    """One run of the task in `diagram`, live in `console` and the terminal: `(TaskResult,
    LiveRun)`. With `start_button` (a label), the task's clock starts when it is pressed."""
    scenario = resolved.scenario
    camera = None
    if args.camera == "robot":
        camera = RobotCamera(meshcat, find_system(diagram, "hsr_station"))
    if console is not None:
        console.show_title(f"{method_name(scenario.method, _alpha(scenario))}, seed "
                           f"{scenario.seed}")
        console.clear_result()
    live = LiveRun(diagram, scenario.duration, console, Progress(scenario.duration), camera,
                   start_label=start_button, stdin=_terminal())
    if args.record:
        meshcat.StartRecording(frames_per_second=30.0)
    rate = 0.0 if args.headless else args.realtime_rate
    if args.log:  # its folder may be made (check_log_path)
        pathlib.Path(args.log).parent.mkdir(parents=True, exist_ok=True)
    result = (run_task_streamed(resolved, args.log, realtime_rate=rate, diagram=diagram,
                                advance=live.advance)
              if args.log else run_task(resolved, realtime_rate=rate, diagram=diagram,
                                        advance=live.advance))
    if args.record:
        _save_recording(meshcat, args.record)
    if console is not None:
        console.show_result(_outcome(result, live))
    hand = ""
    if len(result.ee_positions):
        hand = ", hand at [" + ", ".join(f"{x:.3f}" for x in result.ee_positions[-1]) + "]"
    if args.log:
        hand = f"; per-tick rows in {args.log}"
    print(f"{scenario.name} [{scenario.method}, seed {scenario.seed}]: "
          f"{result.summary_line(stopped=live.choice is not None)}{hand}", flush=True)
    return result, live


def _outcome(result, live):
    """The run's result in a person's words (`result_text`)."""
    return result_text(result.success, result.task_time, stopped=live.choice is not None)


def _task_code(result, live):
    """The exit code of a run: stopped by the person, succeeded or failed (`EXIT_CODES`)."""
    if live.choice == "stop":
        return EXIT_STOPPED
    return EXIT_SUCCESS if result.success else EXIT_FAILED


def _run_session(args, resolved, meshcat, page, person):
    scenario = resolved.scenario
    methods, order = session_methods(args, scenario)  # checked by check_run_flags
    output = pathlib.Path(args.output or pathlib.Path("outputs", "participants",
                                                       args.participant))
    print(f"Participant {args.participant}: {', '.join(order)}, in this order"
          + (", each practised first" if args.practice else "") + f"; saved in {output}",
          flush=True)
    if args.answers is not None:
        questions = FixedAnswers(parse_answers(args.answers, methods))
    else:
        questions = _StartInTheRun(MeshcatSessionPage(meshcat), args.start_on_connect)
    if page is not None and isinstance(questions, _StartInTheRun):
        # The pages are the person's: no browser, no session (`--answers` needs none).
        print(f"Open {page.url} in a browser (waiting up to {args.wait_for_browser:g} s); "
              "each method starts when its Start is pressed in the page, and the questions "
              "and Next are buttons there too (Open Controls).", flush=True)
        _wait_for_browser(page, args.wait_for_browser, PERSON_NEEDS_PAGE if person else
                          "the session's Start buttons and questions are in the page, so "
                          "nothing was run or saved")

    # The live status and Stop, Restart, Next scene, as in a single run. Within a session,
    # Stop ends it (resumable, like Ctrl-C), Restart runs the method again (the stopped run
    # is not saved), and Next scene ends this method's run as it stands (saved, not a
    # success) and goes on to its questions: the next scene of a session is the next run.
    console = None if page is None else _console(meshcat, page, args, scenario)

    def run_one(trial):
        # Shown again after a Restart: each run of the method starts at its Start.
        start_button = (questions.take_start_label()
                        if isinstance(questions, _StartInTheRun) else None)
        while True:
            diagram = build_diagram(trial, meshcat)
            if console is not None:
                # After the operator's buttons; and clicks made between runs (on the
                # questions) do not count.
                console.set_choices(RUN_CHOICES)
            result, live = _run_task_once(args, trial, diagram, meshcat, console,
                                          start_button=start_button)
            operator = diagram.GetSubsystemByName("operator")
            if hasattr(operator, "Delete"):
                operator.Delete()  # the next method may want other keys
            if console is not None:
                console.set_choices(())  # no Stop under the questions
            if live.choice == "stop":
                raise _SessionStopped
            if live.choice != "restart":
                return result
            print(f"Restart: {trial.scenario.method} again, seed {trial.scenario.seed} "
                  "(the stopped run is not saved).", flush=True)

    try:
        summary = run_session(scenario, args.participant, methods, output, run_one,
                              questions, practice=args.practice)
    except (KeyboardInterrupt, _SessionStopped) as stop:
        stopped = isinstance(stop, _SessionStopped)
        print(("Stopped in the page" if stopped else "\nStopped")
              + f": the methods and answers saved so far are in {output}; the same command "
              "resumes the session.", file=sys.stderr)
        if page is not None:
            page.end(f"The session was stopped; what was saved is kept. {PAGE_ENDED}")
        return EXIT_STOPPED if stopped else EXIT_INTERRUPTED
    failed = [m for m, entry in summary["methods"].items() if entry["success_rate"] < 1.0]
    print(f"Session saved in {output}, answers in {output / QUESTIONNAIRE_FILE} "
          f"(`pbp-drake report {output.parent}` compares the participants).", flush=True)
    if failed:
        print(f"pbp-drake: the run of {', '.join(failed)} did not reach its target (exit "
              f"{EXIT_FAILED}); the session is complete and saved.", file=sys.stderr)
    if console is not None:
        console.show_title("Session complete - you can close this page")
        console.show_status(f"{counted(len(order), 'method')} run and answered; thank you.")
        console.clear_result()
        _keep_page(args, page, console, ("close",))
        page.end("Session complete - you can close this page")
    return EXIT_FAILED if failed else EXIT_SUCCESS


class _SessionStopped(Exception):
    """Stop pressed in the page during a session's run: the session ends, resumable."""


class _StartInTheRun:
    """A session's pages in Meshcat (`MeshcatSessionPage`) whose Start is pressed inside the
    run, once the run's scene is in the page, rather than before the run is built: `start`
    only keeps the label, which the run's `LiveRun` shows (`take_start_label`). With
    `--start-on-connect`, Start is today's page between the runs."""

    def __init__(self, pages, start_between_runs=False):
        self._pages = pages
        self._start_between_runs = start_between_runs
        self._label = None

    def start(self, method, position, total, practice=False):
        if self._start_between_runs:
            self._pages.start(method, position, total, practice)
        else:
            self._label = start_label(method, position, total, practice)

    def take_start_label(self):
        label, self._label = self._label, None
        return label

    def answer(self, method, question):
        return self._pages.answer(method, question)

    def next(self, position, total):
        self._pages.next(position, total)


def _start_gate(args, person):
    """Whether a run's task waits for Start in the page: a person's, unless
    --start-on-connect asks for today's start as the page connects."""
    return person and not args.start_on_connect


def _terminal():
    """stdin when it is a terminal, where Enter stops a run's wait; else None."""
    return sys.stdin if sys.stdin.isatty() else None


def _alpha(scenario):
    return scenario.alpha if scenario.method == "fixed_alpha" else None


def _console(meshcat, page, args, scenario, choices=RUN_CHOICES):
    """The page's console: its lines in the front's panel, the choices, the alpha slider
    (fixed_alpha) and the real-time rate slider."""
    return Console(meshcat, choices, alpha=_alpha(scenario), realtime_rate=args.realtime_rate,
                   panel=page)


def _keep_page(args, page, console, choices):
    """After a run, with a page open: the result stays served until the person closes the
    page, presses one of `choices` (Close, and after a single run Restart and Next scene),
    presses Enter in a terminal, or --keep-page seconds pass. Returns the choice, or None."""
    if page.pages() == 0:
        return None
    console.set_choices(choices)
    words = {"restart": "Restart runs the scene again", "next": "Next scene the next seed"}
    others = [words[choice] for choice in choices if choice in words]
    print("The page keeps the result until it is closed" + (": " + ", ".join(others)
                                                           if others else "")
          + f"; Close, Enter or closing the page ends the command (at the latest in "
          f"{args.keep_page:g} s).", flush=True)
    return console.wait_for_choice(stdin=_terminal(), timeout=args.keep_page,
                                   until=lambda: page.pages() == 0)


def _wait_for_browser(page, seconds, needed=None):
    """Waits up to `seconds` for a browser on the page. A run that cannot go on without one
    (a person's, a session's: `needed` says why) stops with exit 2 before anything runs or
    is recorded."""
    deadline = time.monotonic() + seconds
    while page.pages() == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    if needed is not None and page.pages() == 0:
        raise ScenarioError(f"no browser opened {page.url} within {seconds:g} s "
                            f"(--wait-for-browser): {needed}")


def _saying_write_failures(command):
    """`command(args)` that says a file it could not write (a full disk) in one line, exit
    4, instead of a traceback: replays and sessions are written whole or not at all."""

    @functools.wraps(command)
    def saying_write_failures(args):
        try:
            return command(args)
        except OSError as error:
            if not is_disk_failure(error):
                raise
            print(write_failure_line(error, "run the same command again"), file=sys.stderr)
            return EXIT_WRITE_FAILED

    return saying_write_failures


def _save_recording(meshcat, path):
    record = pathlib.Path(path)
    write_atomically(record, recorded_replay(meshcat))
    print(f"Replay saved to {record}")


