"""The runs of `pbp-drake run`: a task, live in the page and the terminal, run again on
Restart and on the next seed on Next scene; a 2-D scene, run once."""

import dataclasses
import pathlib

import numpy as np
from pydrake.lcm import DrakeLcm

from pbp_drake.builder import build_diagram, find_system, run_task, run_task_streamed, simulate
from pbp_drake.cli_types import EXIT_FAILED, EXIT_STOPPED, EXIT_SUCCESS
from pbp_drake.commands.run_checks import is_person
from pbp_drake.commands.run_page import (
    AFTER_RUN_CHOICES, PERSON_NEEDS_PAGE, RUN_CHOICES, end_page, keep_page, page_console,
    save_recording, terminal, wait_for_browser)
from pbp_drake.console import LiveRun, Progress, RobotCamera, method_name, result_text
from pbp_drake.console.text import controls_line, failure_text
from pbp_drake.core.toy_scene import collision_ratio
from pbp_drake.robots import DriverError, drives_real_robot, measured_ready_positions
from pbp_drake.robots.task_space_bridge import read_first_state
from pbp_drake.scenarios import METHODS, Arm, Gamepad, GraspTask, ScenarioError, resolve
from pbp_drake.scenarios.bounds import is_special_file
from pbp_drake.studies.atomic_files import is_disk_failure, write_failed


def run_scene(args, resolved, meshcat, page):
    """A 2-D scene: live in the page (its console has Stop alone) for its duration."""
    scenario = resolved.scenario
    diagram = build_diagram(resolved, meshcat)
    console = None
    if page is not None:
        console = page_console(meshcat, page, args, alpha_of(scenario), choices=("stop",))
        console.show_title(method_name(scenario.method, scenario.alpha))
        if terminal():  # someone may be watching
            wait_for_browser(page, args.wait_for_browser)
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
        save_recording(meshcat, args.record)
    print(f"{scenario.name} [{scenario.method}]: "
          + (f"{outcome}, " if live.choice == "stop" else "") + "final position "
          f"{position_text(trajectory.positions[-1])}, collision ratio {ratio:.3f}, "
          f"intervention ratio {trajectory.operator_active.mean():.3f}", flush=True)
    if console is not None:
        console.show_result(outcome)
        if live.choice is None:
            keep_page(args, page, console, ("close",))
        end_page(page, console)
    return EXIT_STOPPED if live.choice == "stop" else EXIT_SUCCESS


def run_task_loop(args, resolved, meshcat, page):
    """A task, run until the person is done: Restart runs it again, Next scene on the next
    seed; the exit code of the last run."""
    person = is_person(resolved.scenario)
    # A person's task waits for Start in the page, unless --start-on-connect.
    start_button = "Start" if person and not args.start_on_connect else None
    console = None
    if page is not None:
        console = page_console(meshcat, page, args, alpha_of(resolved.scenario))
    first = True
    while True:
        scenario = resolved.scenario
        diagram = build_diagram(resolved, meshcat, hand_trail=args.hand_trail)
        if console is not None:
            # After the operator's buttons, which the build added: the same order each run.
            console.set_choices(RUN_CHOICES)
        if first and page is not None and (person or terminal()):
            print(f"Open {page.url} in a browser (waiting up to {args.wait_for_browser:g} s); "
                  + ("the task starts when it connects." if start_button is None else
                     "the task starts when Start is pressed in the page."), flush=True)
            if person:
                print(controls_line(scenario), flush=True)
            wait_for_browser(page, args.wait_for_browser, PERSON_NEEDS_PAGE if person else None)
        first = False
        result, live = run_task_once(args, resolved, diagram, meshcat, console, start_button)
        code = EXIT_SUCCESS if result.success else EXIT_FAILED
        if live.choice == "stop":
            code = EXIT_STOPPED
        if console is None:
            return code
        delete_operator(diagram)  # its keys drive nothing once the run is over
        choice = live.choice
        if choice is None:
            choice = keep_page(args, page, console, AFTER_RUN_CHOICES)
        if choice in (None, "stop", "close"):
            end_page(page, console)
            return code
        if choice == "next":
            scenario = dataclasses.replace(scenario, seed=scenario.seed + 1)
        if on_a_real_arm(scenario):  # the arm moved in the run: the next starts where it is
            resolved = resolve(standing_where_the_arm_stands(scenario))
        elif choice == "next":
            resolved = resolve(scenario)
        check_the_bridged_robot_s_hand(resolved)  # the hand moved: it must be back at the start
        print(f"{'Restart' if choice == 'restart' else 'Next scene'}: seed "
              f"{resolved.scenario.seed}.", flush=True)


def on_a_real_arm(scenario):
    """Whether `scenario` drives a real arm through its driver (not the driver's simulator)."""
    return isinstance(scenario.robot, Arm) and drives_real_robot(scenario.robot.hardware)


def standing_where_the_arm_stands(scenario):
    """`scenario` whose arm starts, and is ready, where its driver's first status says it
    stands (never where the file assumes, nor where a run before this one began)."""
    robot = scenario.robot
    try:
        q = measured_ready_positions(robot.station_config())
    except DriverError as error:
        raise ScenarioError(str(error)) from None
    print(f"The {robot.hardware.driver} driver answers on {robot.hardware.lcm_bus.lcm_url}: "
          "the arm stands at [" + ", ".join(f"{value:.4f}" for value in q) + "] rad",
          flush=True)
    return dataclasses.replace(scenario, robot=dataclasses.replace(
        robot, initial_positions=[float(value) for value in q], ready_tool_pose=None))


def check_the_bridged_robot_s_hand(resolved):
    """Before a run through the task-space bridge to a robot is built: the robot's relay
    answers, and its hand stands where the scenario starts it (`read_first_state`); nothing
    for another robot."""
    bridge = getattr(resolved.scenario.robot, "hardware", None)
    if resolved.is_arm or not drives_real_robot(bridge):
        return
    try:
        ee_state = read_first_state(bridge, DrakeLcm(bridge.lcm_bus),
                                    resolved.initial_ee_state)
    except DriverError as error:
        raise ScenarioError(str(error)) from None
    print(f"The robot's relay answers on {bridge.lcm_bus.lcm_url}: the hand stands at ["
          + ", ".join(f"{value:.3f}" for value in ee_state[:3]) + "] m", flush=True)


def run_task_once(args, resolved, diagram, meshcat, console, start_button=None):
    """One run of the task in `diagram`, live in `console` and the terminal: `(TaskResult,
    LiveRun)`. With `start_button` (a label), the task's clock starts when it is pressed.
    A person's run stands still while its page (`console.panel`) has none present
    (closed, hidden or silent)."""
    scenario = resolved.scenario
    camera = None
    if args.camera == "robot":
        camera = RobotCamera(meshcat, find_system(diagram, "hsr_station"))
    if console is not None:
        console.show_title(f"{method_name(scenario.method, scenario.alpha)}, seed "
                           f"{scenario.seed}")
        console.clear_result()
    live = LiveRun(diagram, scenario.duration, console, Progress(scenario.duration), camera,
                   start_label=start_button, stdin=terminal(),
                   gamepad=isinstance(scenario.operator, Gamepad),
                   page=None if console is None else console.panel)
    if args.record:
        meshcat.StartRecording(frames_per_second=30.0)
    rate = 0.0 if args.headless else args.realtime_rate
    if args.log:
        pathlib.Path(args.log).parent.mkdir(parents=True, exist_ok=True)
    try:
        result = (run_task_streamed(resolved, args.log, realtime_rate=rate, diagram=diagram,
                                    advance=live.advance)
                  if args.log else run_task(resolved, realtime_rate=rate, diagram=diagram,
                                            advance=live.advance))
    except OSError as error:
        # The log that passed its check but cannot be opened (a special file system, a
        # folder changed since): said in one line, as a full disk is (`stopping_cleanly`).
        # A write to it that fails (a full disk, /dev/full with --force) names no file: it
        # was "cannot write a file".
        if args.log and (error.filename == args.log
                         or error.filename is None and is_disk_failure(error)):
            raise write_failed(error, args.log) from None
        raise
    if args.record:
        save_recording(meshcat, args.record)
    stopped = live.choice is not None
    why = None if result.success or stopped else why_failed(result, scenario, args.log)
    if console is not None:
        console.show_result(result_text(result.success, result.task_time, stopped, why))
    hand = ""
    if len(result.ee_positions):
        hand = f", hand at {position_text(result.ee_positions[-1])}"
    if args.log:
        hand = f"; per-tick rows in {args.log}"
    print(f"{scenario.name} [{scenario.method}, seed {scenario.seed}]: "
          f"{result.summary_line(stopped=stopped)}{hand}", flush=True)
    if why is not None:
        print(f"  the time limit ({scenario.duration:g} s) passed: {why}", flush=True)
    return result, live


def why_failed(result, scenario, log=None):
    """Where a failed run's hand ended against its target (`failure_text`); for a run
    streamed to `log`, whose result holds no series, from the file's last row."""
    if len(result.ee_positions) and len(result.targets):
        hand, target = result.ee_positions[-1], int(result.targets[-1])
    else:
        row = log and last_row(log)
        if not row:
            return None
        hand = np.array([float(row[name]) for name in ("ee_x", "ee_y", "ee_z")])
        target = int(float(row["target"]))
    distance = float(np.linalg.norm(hand - result.objects[target]))
    # The grasping task's success is a grasp pose, not a distance to the object's centre.
    grasping = isinstance(scenario.task, GraspTask)
    return failure_text(target, len(result.objects), distance,
                        None if grasping else scenario.task.success_distance,
                        result.joints_at_limits or (),
                        "grasp" if grasping and scenario.task.grasps_per_object > 1
                        else "object")


def last_row(path, tail_bytes=2**16):
    """The last row of the CSV at `path` as {column: text}, read from its header and its
    last `tail_bytes` (a streamed log may be long); None when it has no row or is not a
    file (--force lets the log be a device: /dev/zero never ends)."""
    if is_special_file(path):
        return None
    with open(path, "rb") as file:
        header = file.readline(tail_bytes).decode().strip().split(",")
        file.seek(max(file.tell(), file.seek(0, 2) - tail_bytes))
        lines = file.read().decode().splitlines()
    return dict(zip(header, lines[-1].split(","))) if lines else None


def position_text(position):
    """A position as the terminal shows it: "[0.575, 0.087, 0.362]" (m, fixed point: a
    coordinate of -1e-11 reads 0.000, not in NumPy's scientific notation nor as -0.000)."""
    return "[" + ", ".join(f"{x:.3f}" for x in np.round(position, 3) + 0.0) + "]"


def delete_operator(diagram):
    """Removes the operator's buttons from the page: the next build adds its own."""
    operator = diagram.GetSubsystemByName("operator")
    if hasattr(operator, "Delete"):
        operator.Delete()


def alpha_of(scenario):
    """fixed_alpha's weight, for the page's slider; None under another method."""
    return scenario.alpha if METHODS[scenario.method].takes_weight else None
