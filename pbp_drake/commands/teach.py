"""`pbp-drake teach FILE --output P.json`: a primitive taught by driving (the grasping task: a
pose's), see docs/tasks/teach.md. The task runs under teleop, the hand's path is fitted with
the scenario's DMP settings (`pbp_drake.core.dmp.primitive`) and saved, the run's rows beside
it (`P.csv`); `--from FILE` teaches from a recorded path instead.
"""

import argparse
import csv
import json
import os
import pathlib
import shlex
import sys

import numpy as np

from pbp_drake.builder.time_series import HAND_ORIENTATION_COLUMNS
from pbp_drake.cli_types import (
    EXIT_FAILED, EXIT_INTERRUPTED, EXIT_STOPPED, EXIT_SUCCESS, EXIT_WRITE_FAILED, port)
from pbp_drake.commands.run import add_run_command
from pbp_drake.commands.scenario_flags import add_override_flags, scenario_overrides
from pbp_drake.core.dmp.primitive import primitive_document, teach_primitive
from pbp_drake.output_paths import (
    check_figure_path, check_log_path, check_primitive_path, is_replay, replay_track,
    same_file)
from pbp_drake.scenarios import GraspTask, ScenarioError, TaskScenario, load_scenario_file
from pbp_drake.scenarios.bounds import is_special_file
from pbp_drake.studies.atomic_files import (
    is_disk_failure, write_atomically, write_failure_line)
from pbp_drake.studies.primitive_figure import plot_primitive
from pbp_drake.systems.visualizers.reach_scene_visualizer import HAND_MARKER

#: The operators who can drive a demonstration.
TEACHERS = ("virtual", "keyboard", "gamepad")
#: The largest file `--from` reads (bytes): a run's CSV takes about 9 KB a simulated second,
#: its replay a few MB and more a minute.
MOST_HAND_PATH_BYTES = 256 << 20


def add_teach_command(commands):
    """The `teach` subcommand and its arguments."""
    parser = commands.add_parser(
        "teach", help="teach a primitive by driving: the hand's path from the task's start, "
        "fitted as a DMP and saved, for any scenario's dmp: {primitive: FILE}")
    parser.add_argument("scenario", help="a reaching or obstacle task's scenario file, e.g. "
                        "diagrams/hsr_reach.yaml (its dmp section: the fit's settings)")
    parser.add_argument("--output", required=True, metavar="FILE.json",
                        help="where the primitive is saved")
    parser.add_argument("--operator", choices=TEACHERS, default="virtual",
                        help="who drives: virtual (default, headless: the virtual participant "
                        "drives to its target), keyboard or gamepad (you, in the page)")
    parser.add_argument("--from", dest="source", metavar="FILE",
                        help="teach from a recorded path instead of driving: a run's --log "
                        "CSV, a study trial's CSV, or a run's --record replay")
    parser.add_argument("--seed", type=int, help="--set seed=N: the scene driven in")
    parser.add_argument("--figure", metavar="FILE.png",
                        help="also draw the demonstration, its reproduction and the shape "
                        "carried to the scene's objects")
    parser.add_argument("--port", type=port, default=0,
                        help="keyboard and gamepad: the page's port (default 0: a free one)")
    parser.add_argument("--force", action="store_true",
                        help="overwrite an existing --output that is not a primitive")
    add_override_flags(parser)
    parser.set_defaults(handler=_teach, method=None, alpha=None, duration=None, goals=None,
                        hardware=False, driver_sim=False)


def _teach(args):
    # A person's flags with a recording, or the page's port without a page, would be
    # taken and do nothing.
    if args.source is not None and args.operator != "virtual":
        raise ScenarioError(f"--from teaches from a recording; --operator {args.operator} "
                            "drives the task instead: give one of them")
    if args.port and (args.source is not None or args.operator == "virtual"):
        raise ScenarioError("--port is the page's port of a keyboard or gamepad drive "
                            "(--operator keyboard or gamepad, without --from)")
    check_primitive_path(args.output, force=args.force)
    if args.figure is not None:
        check_figure_path(args.figure)
        if same_file(args.figure, args.output):
            raise ScenarioError(f"--figure and --output both name {args.output}; give each "
                                "its own file")
    if args.source is None and pathlib.Path(args.output).suffix == ".csv":
        raise ScenarioError(f"--output {args.output}: the drive's rows are saved beside the "
                            "primitive as a .csv; give the primitive a .json file")
    scenario_file = load_scenario_file(args.scenario,
                                       scenario_overrides(args, shorthands=False))
    scenario = scenario_file.scenario
    if not isinstance(scenario, TaskScenario):
        raise ScenarioError("teach drives a robot task's hand; this scenario is a 2-D scene, "
                            "whose demonstration is scenario.demonstration")
    origin = args.source
    if origin is None:
        # Kept beside the primitive: a person's demonstration is not to be driven twice.
        origin = str(pathlib.Path(args.output).with_suffix(".csv"))
        check_log_path(origin, force=args.force)
        try:
            code = _drive(args, origin, switches=hasattr(scenario.task, "switch_schedule"),
                          hand_trail=not isinstance(scenario.task, GraspTask))
        except KeyboardInterrupt:
            if args.operator == "virtual" or not pathlib.Path(origin).is_file():
                raise
            # A person's drive ended by Ctrl-C, not Stop: its rows so far are the demonstration
            # they may mean, and the next drive would write over them.
            print(f"\npbp-drake: interrupted; the drive so far is kept in {origin}: "
                  f"{_teach_again(args, origin)} teaches from it", file=sys.stderr)
            return EXIT_INTERRUPTED
        if code not in (EXIT_SUCCESS, EXIT_FAILED, EXIT_STOPPED):
            return code
    times, positions, orientations = read_hand_path(origin)
    if isinstance(scenario.task, GraspTask) and orientations is None:
        raise ScenarioError(f"{origin}: the grasping task teaches a pose: the recording needs "
                            f"the columns {', '.join(HAND_ORIENTATION_COLUMNS)} (a grasping run's)")
    try:
        primitive = teach_primitive(times, positions, scenario.dmp, orientations)
    except ValueError as error:
        raise ScenarioError(f"{origin}: {error}") from None
    try:
        _save(args, primitive, scenario_file.resolved.scene.objects)
    except OSError as error:
        if not is_disk_failure(error):
            raise
        # Said with the command that teaches from the demonstration kept: a person's drive
        # is not to be driven again.
        print(write_failure_line(error, f"{_teach_again(args, origin)} teaches from {origin}"),
              file=sys.stderr)
        return EXIT_WRITE_FAILED
    return EXIT_SUCCESS


def _save(args, primitive, objects):
    """Writes the primitive to `args.output` (and the figure of it, of the scene's
    `objects`, to `args.figure`) and says so."""
    write_atomically(pathlib.Path(args.output), json.dumps(primitive_document(primitive)))
    start, goal = (", ".join(f"{x:.3f}" for x in point)
                   for point in (primitive.start, primitive.goal))
    print(f"Taught from {len(primitive.times)} samples over {primitive.duration:.2f} s, from "
          f"[{start}] to [{goal}] m, {primitive.length_ratio:.2f} times the straight "
          f"distance; the {primitive.settings.formulation} DMP reproduces it within "
          f"{primitive.fit_error * 1000:.1f} mm RMS"
          + ("" if primitive.orientation is None else
             f", its turn within {np.degrees(primitive.orientation.fit_error):.1f} degrees RMS")
          + f". Saved to {args.output}: name it in {args.scenario} as dmp: "
          f"{{primitive: {_from_scenario(args.output, args.scenario)}}}", flush=True)
    if args.figure is not None:
        plot_primitive(primitive, objects, args.figure)
        print(f"Figure: {args.figure} (the demonstration, its reproduction, the shape "
              "carried to the scene's objects)", flush=True)


def _teach_again(args, origin):
    """The command line that teaches the same primitive from the recording `origin`."""
    argv = ["pbp-drake", "teach", args.scenario, "--from", origin, "--output", args.output]
    for setting in args.settings:
        argv += ["--set", setting]
    if args.scenario_text is not None:
        argv += ["--scenario-text", args.scenario_text]
    if args.figure is not None:
        argv += ["--figure", args.figure]
    return shlex.join(argv)


def _from_scenario(path, scenario):
    """`path` as the file `scenario` names it: a relative path is read from the scenario
    file's folder (`--output` was from the working folder)."""
    if os.path.isabs(path):
        return path
    return os.path.relpath(os.path.abspath(path), os.path.dirname(os.path.abspath(scenario)))


def _drive(args, log, switches, hand_trail):
    """The exit code of `pbp-drake run` of the scenario under teleop by `args.operator`,
    its rows in `log`; a task whose target `switches` keeps one target; `hand_trail`: the
    task's page draws the hand's path (a reaching or obstacle task's)."""
    argv = ["run", args.scenario, "--method", "teleop", "--operator", args.operator,
            "--log", str(log), "--force"]
    if switches:
        # One target from the start (the switches would put turns in the shape); the
        # command line's own settings come after, and may change that.
        argv += ["--set", "task.switch_schedule=[0.0]"]
    for setting in args.settings:
        argv += ["--set", setting]
    if args.scenario_text is not None:
        argv += ["--scenario-text", args.scenario_text]
    if args.seed is not None:
        argv += ["--seed", str(args.seed)]
    if args.operator == "virtual":
        argv.append("--headless")
    else:  # the demonstration ends with the run: no result page to keep
        argv += ["--port", str(args.port), "--keep-page", "0"] + (
            ["--hand-trail"] if hand_trail else [])
    parser = argparse.ArgumentParser(prog="pbp-drake")
    add_run_command(parser.add_subparsers(dest="command"))
    run_args = parser.parse_args(argv)
    return run_args.handler(run_args)


def read_hand_path(path):
    """Times (T,), hand positions (T, 3) and orientations (T, 4; None where the recording
    has none) of a run's or trial's CSV, or of a run's replay (`run --record`, at its frame
    rate); ScenarioError naming the file for one that cannot be read or has no hand path."""
    if is_special_file(path):
        raise ScenarioError(f"{path}: not a regular file; give a run's CSV (run --log) or "
                            "replay (run --record)")
    try:
        size = pathlib.Path(path).stat().st_size
    except OSError as error:
        raise ScenarioError(f"{path}: cannot be read as a CSV ({error})") from None
    if size > MOST_HAND_PATH_BYTES:  # read whole, it was a MemoryError (a 2 GB file)
        raise ScenarioError(f"{path}: holds {size:,} bytes; a run's CSV or replay to teach "
                            f"from is at most {MOST_HAND_PATH_BYTES:,}")
    if is_replay(path):
        return _replay_hand_path(path)
    columns = ("time", "ee_x", "ee_y", "ee_z")
    try:
        with open(path, newline="") as file:
            reader = csv.reader(file)
            header = next(reader, [])
            if all(name in header for name in HAND_ORIENTATION_COLUMNS):
                columns += tuple(HAND_ORIENTATION_COLUMNS)
            # Each row's hand columns only, not the row (a few hundred bytes as a dict).
            picks = [header.index(name) if name in header else None for name in columns]
            rows = [[row[pick] if pick < len(row) else None for pick in picks]
                    for row in reader if row] if None not in picks else []
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise ScenarioError(f"{path}: cannot be read as a CSV ({error})") from None
    if not rows:
        beside = pathlib.Path(path).with_suffix(".csv")
        trial = (f"; a trial's path is in its CSV, {beside}" if pathlib.Path(path).suffix
                 == ".json" and beside.is_file() else "")
        raise ScenarioError(f"{path}: not a run's path: it needs the columns "
                            f"{', '.join(columns[:4])} (pbp-drake run --log writes them)"
                            f"{trial}")
    try:
        table = np.array([[float(value) for value in row] for row in rows])
    except (TypeError, ValueError):
        raise ScenarioError(f"{path}: a value of {', '.join(columns)} is not a number"
                            ) from None
    return table[:, 0], table[:, 1:4], (table[:, 4:8] if table.shape[1] == 8 else None)


def _replay_hand_path(path):
    """The hand's path in a replay: the track of the marker at the hand (`HAND_MARKER`), in
    time order, each time once."""
    try:
        times, positions = replay_track(pathlib.Path(path).read_text(), HAND_MARKER,
                                        ".position")
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError) as error:
        raise ScenarioError(f"{path}: no hand path in this replay ({error}); a reaching or "
                            "obstacle task's run records one") from None
    times, first = np.unique(times, return_index=True)
    positions = positions[first].reshape(-1, 3)
    # Meshcat keeps a key only where a frame changed something: the frames it skipped are
    # put back (the fit differentiates twice, and an uneven step reads as a jolt).
    frame = float(np.median(np.diff(times))) if len(times) > 1 else 1.0
    grid = times[0] + frame * np.arange(int(round((times[-1] - times[0]) / frame)) + 1)
    return grid, np.column_stack([np.interp(grid, times, axis) for axis in positions.T]), None
