"""The `pbp-drake` command line: `run` one scenario in Meshcat, `study` a scenario file."""

import argparse
import dataclasses
import pathlib
import sys
import time

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams, Rgba

from pbp_drake.bench.run import main as bench_main
from pbp_drake.builder import build_diagram, run_task, run_task_streamed, simulate
from pbp_drake.cli_types import port, realtime_rate, wait_seconds
from pbp_drake.core.toy_scene import collision_ratio
from pbp_drake.draw import main as draw_main
from pbp_drake.output_paths import (
    check_log_path, check_output_folder, check_record_path, mark_replay)
from pbp_drake.scenarios import (
    METHODS, OPERATOR_NAMES, Gamepad, Hsr, Keyboard, MethodComparison, ScenarioError,
    check_method_comparison, load_scenario_file, resolve, with_method)
from pbp_drake.studies.comparison import run_method_comparison
from pbp_drake.studies.progress import ProgressBar
from pbp_drake.studies.report import FIGURES, report, results_table
from pbp_drake.studies.sessions import DEFAULT_SESSION_METHODS, run_session, session_order
from pbp_drake.studies.splits import SPLITS, first_seed, split_of
from pbp_drake.studies.toy import TOY_FIGURES, print_alpha_study, run_study


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="pbp-drake",
        description="Policy Blending with Primitives (PBP): shared control on Drake.")
    commands = parser.add_subparsers(dest="command", required=True)

    run = commands.add_parser("run", help="simulate one scenario in Meshcat")
    run.add_argument("scenario", help="a scenario file, e.g. diagrams/toy_alpha_study.yaml")
    run.add_argument("--method", help=f"override the scenario's method: {', '.join(METHODS)}")
    run.add_argument("--alpha", type=float, help="override alpha (fixed_alpha)")
    run.add_argument("--scene", help="use the obstacles of this scene of the file's study")
    run.add_argument("--operator", help="HSR tasks: who drives, one of "
                     f"{', '.join(OPERATOR_NAMES)} (keyboard and gamepad: in the browser)")
    run.add_argument("--seed", type=int, help="HSR tasks: the seed of the scene and the noise")
    run.add_argument("--participant", metavar="ID",
                     help="HSR tasks: a user-study session; every method of --methods once, "
                     "in an order counterbalanced across participants, saved in the study "
                     "format under --output (`pbp-drake report` reads it)")
    run.add_argument("--methods", help="with --participant: the methods of the session "
                     "(default: pbp_alternated,pbp_continuous,teleop)")
    run.add_argument("--output", help="with --participant: the session's folder "
                     "(default: outputs/participants/ID)")
    run.add_argument("--headless", action="store_true",
                     help="simulate as fast as possible without waiting for a browser")
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
                     help="Meshcat port, 0..65535 (default 0: a free one)")
    run.add_argument("--wait-for-browser", type=wait_seconds, default=15.0, metavar="SECONDS",
                     help="before starting, wait this long for a browser to open the page "
                     "(default 15); a keyboard or gamepad run that no browser joins in time "
                     "stops with exit 2, having run and recorded nothing")

    study = commands.add_parser("study", help="run the study a scenario file describes")
    study.add_argument("scenario", help="a scenario file with a `study:` section")
    study.add_argument("--output", required=True, help="folder for summary.json and figures")
    study.add_argument("--methods", help="comma-separated methods to compare (HSR tasks)")
    study.add_argument("--trials", type=int, help="seeded scenes per method (HSR tasks)")
    study.add_argument("--split", choices=SPLITS,
                       help="HSR tasks: run the study's tuning or evaluation seeds (default: "
                            "the study's `split`)")
    study.add_argument("--seed", type=int, help="the first scene's seed (HSR tasks; results "
                       "are labelled with the split the seeds fall in)")
    study.add_argument("--jobs", type=int, default=1,
                       help="HSR tasks: trials run in this many processes at once (default 1)")
    study.add_argument("--backend", choices=("local", "ray"), default="local",
                       help="HSR tasks: run the trials in local processes (default) or as "
                       "Ray tasks, at most --jobs at once (needs: pip install "
                       "'pbp_drake[ray]')")
    study.add_argument("--ray-address", metavar="ADDRESS",
                       help="with --backend ray: the Ray cluster to use, e.g. auto or "
                       "ray://HEAD:10001 (its workers must have pbp_drake installed); "
                       "default: start a local Ray with --jobs CPUs")
    study.add_argument("--retry-errors", action="store_true",
                       help="HSR tasks: run again the trials on disk that failed with an error")

    report = commands.add_parser(
        "report", help="rebuild the summary, table and figures of a study folder from its "
        "trial files, without simulating; damaged or foreign files are named on stderr and "
        "skipped (exit 1 when there were any, or when trials failed with an error or did not "
        "run, as `study` does; 2 when there is nothing to report)")
    report.add_argument("output", help="the --output folder of `pbp-drake study`")

    # Their own argument parsers live with them; the rest of the line is passed on.
    for name, help_text in [("bench", "time the DMP bank against the DMP libraries people "
                                      "use (pbp-drake bench --help)"),
                            ("draw", "write a scenario's system diagram as SVG "
                                     "(pbp-drake draw --help)")]:
        tool = commands.add_parser(name, help=help_text, add_help=False)
        tool.add_argument("arguments", nargs=argparse.REMAINDER)

    argv = sys.argv[1:] if argv is None else list(argv)
    tools = {"bench": bench_main, "draw": draw_main}
    if argv and argv[0] in tools:
        # Before argparse, which would take their options (e.g. --help) for its own.
        return tools[argv[0]](argv[1:])
    args = parser.parse_args(argv)
    try:
        if args.command == "run":
            return _run(args)
        if args.command == "report":
            return _report(args)
        return _study(args)
    except ScenarioError as error:
        print(f"pbp-drake: {error}", file=sys.stderr)
        return 2


def scenario_for_run(scenario_file, method=None, alpha=None, scene=None, operator=None,
                     seed=None, duration=None):
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
        if not isinstance(scenario.robot, Hsr):
            raise ScenarioError("--operator chooses who drives the HSR tasks; this scenario "
                                "uses the 2-D toy robot")
        if not isinstance(scenario.operator, OPERATOR_NAMES[operator]):
            scenario = dataclasses.replace(scenario, operator=OPERATOR_NAMES[operator]())
    if seed is not None:
        scenario = dataclasses.replace(scenario, seed=seed)
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


def _run(args):
    # The paths first: a bad one must not cost a run, let alone a person's session.
    if args.record:
        check_record_path(args.record, force=args.force)
    if args.log:
        check_log_path(args.log, force=args.force)
    if args.output is not None:
        check_output_folder(args.output)
    resolved = scenario_for_run(load_scenario_file(args.scenario), args.method, args.alpha,
                                args.scene, args.operator, args.seed, args.duration)
    scenario = resolved.scenario
    meshcat = Meshcat(MeshcatParams(host="localhost", port=args.port or None))
    print(f"Meshcat: {meshcat.web_url()}", flush=True)
    if resolved.is_hsr:
        return _run_task(args, resolved, meshcat)
    if args.log:
        raise ScenarioError("--log streams an HSR task's per-tick rows; this scenario uses "
                            "the 2-D toy robot")
    diagram = build_diagram(resolved, meshcat)
    if not args.headless and sys.stdin.isatty():
        _wait_for_browser(meshcat, args.wait_for_browser)
    if args.record:
        meshcat.StartRecording(frames_per_second=30.0)
    trajectory = simulate(resolved, realtime_rate=0.0 if args.headless else args.realtime_rate,
                          diagram=diagram)
    positions = np.zeros((len(trajectory.positions), 3))
    positions[:, :trajectory.positions.shape[1]] = trajectory.positions[:, :3]
    meshcat.SetLine("/pbp/executed", positions.T, 2.0, Rgba(0.1, 0.3, 0.9, 1.0))
    ratio = collision_ratio(trajectory.positions, [o.center for o in scenario.obstacles],
                            [o.radius for o in scenario.obstacles])
    if args.record:
        _save_recording(meshcat, args.record)
    print(f"{scenario.name} [{scenario.method}]: final position "
          f"{np.array2string(trajectory.positions[-1], precision=3)}, collision ratio "
          f"{ratio:.3f}, intervention ratio {trajectory.operator_active.mean():.3f}")
    if not args.headless and sys.stdin.isatty():
        input("Press Enter to quit (the page stays live until then). ")
    return 0


def _run_task(args, resolved, meshcat):
    scenario = resolved.scenario
    person = isinstance(scenario.operator, (Keyboard, Gamepad))
    if args.headless and person:
        raise ScenarioError("--headless runs unattended: a person cannot drive it; use "
                            "--operator virtual")
    if args.participant is not None:
        return _run_session(args, resolved, meshcat, person)
    if args.methods is not None or args.output is not None:
        raise ScenarioError("--methods and --output belong to a session: add --participant ID")
    diagram = build_diagram(resolved, meshcat)
    if person or (not args.headless and sys.stdin.isatty()):
        # A person needs the page open before the task starts.
        print(f"Open {meshcat.web_url()} in a browser; the task starts when it connects "
              f"(waiting up to {args.wait_for_browser:g} s).", flush=True)
        if person:
            print("Keys: arrows move the hand (forward only in teleop), Q and E turn it.",
                  flush=True)
        _wait_for_browser(meshcat, args.wait_for_browser, person)
    if args.record:
        meshcat.StartRecording(frames_per_second=30.0)
    rate = 0.0 if args.headless else args.realtime_rate
    result = (run_task_streamed(resolved, args.log, realtime_rate=rate, diagram=diagram)
              if args.log else run_task(resolved, realtime_rate=rate, diagram=diagram))
    if args.record:
        _save_recording(meshcat, args.record)
    hand = ""
    if len(result.ee_positions):
        hand = ", hand at [" + ", ".join(f"{x:.3f}" for x in result.ee_positions[-1]) + "]"
    if args.log:
        hand = f"; per-tick rows in {args.log}"
    print(f"{scenario.name} [{scenario.method}, seed {scenario.seed}]: "
          f"{result.summary_line()}{hand}", flush=True)
    if not args.headless and sys.stdin.isatty():
        input("Press Enter to quit (the page stays live until then). ")
    return 0 if result.success else 1


def _run_session(args, resolved, meshcat, person):
    scenario = resolved.scenario
    if args.record or args.log:
        raise ScenarioError("--record and --log save one run; a session saves every run under "
                            "--output")
    methods = _method_list(args.methods) if args.methods else list(DEFAULT_SESSION_METHODS)
    for method in methods:
        with_method(scenario, method)
    try:
        order = session_order(methods, args.participant)
    except ValueError as error:
        raise ScenarioError(f"--participant: {error}") from None
    output = pathlib.Path(args.output or pathlib.Path("outputs", "participants",
                                                       args.participant))
    print(f"Participant {args.participant}: {', '.join(order)}, in this order; saved in "
          f"{output}", flush=True)
    if person:
        print(f"Open {meshcat.web_url()} in a browser; the session starts when it connects "
              f"(waiting up to {args.wait_for_browser:g} s).", flush=True)
        _wait_for_browser(meshcat, args.wait_for_browser, person)

    def run_one(trial):
        diagram = build_diagram(trial, meshcat)
        print(f"Next: {trial.scenario.method}.", flush=True)
        if person and sys.stdin.isatty():
            input("Press Enter to start. ")
        result = run_task(trial, realtime_rate=0.0 if args.headless else
                          args.realtime_rate, diagram=diagram)
        operator = diagram.GetSubsystemByName("operator")
        if hasattr(operator, "Delete"):
            operator.Delete()  # the next method may want other keys
        print(f"  {trial.scenario.method}: {result.summary_line()}", flush=True)
        return result

    summary = run_session(scenario, args.participant, methods, output, run_one)
    failed = [m for m, entry in summary["methods"].items() if entry["success_rate"] < 1.0]
    print(f"Session saved in {output} (`pbp-drake report {output}` rebuilds its tables).")
    return 1 if failed else 0


def _method_list(text):
    """`--methods a,b,c` as a list."""
    return [method.strip() for method in text.split(",") if method.strip()]


def _wait_for_browser(meshcat, seconds, person=False):
    """Waits up to `seconds` for a browser on the page. A person's run (keyboard, gamepad)
    cannot go on without one: it stops with exit 2 before anything runs or is recorded."""
    deadline = time.monotonic() + seconds
    while meshcat.GetNumActiveConnections() == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    if person and meshcat.GetNumActiveConnections() == 0:
        raise ScenarioError(f"no browser opened {meshcat.web_url()} within {seconds:g} s "
                            "(--wait-for-browser): the keyboard and gamepad are read in the "
                            "page, so nothing was run or recorded")


def _save_recording(meshcat, path):
    meshcat.StopRecording()
    meshcat.PublishRecording()
    record = pathlib.Path(path)
    record.parent.mkdir(parents=True, exist_ok=True)
    record.write_text(mark_replay(meshcat.StaticHtml()))
    print(f"Replay saved to {record}")


def _study(args):
    check_output_folder(args.output)
    scenario_file = load_scenario_file(args.scenario)
    if isinstance(scenario_file.scenario.robot, Hsr):
        return _method_study(args, scenario_file)
    if scenario_file.study is None:
        raise ScenarioError(f"{args.scenario}: has no `study:` section to run")
    output = pathlib.Path(args.output)
    started = time.monotonic()
    summary = run_study(scenario_file, output)
    print(f"Study {summary['study']} done in {time.monotonic() - started:.1f} s.")
    if summary["study"] == "alpha_study":
        print_alpha_study(summary)
    else:
        for method, mode in summary["modes"].items():
            print(f"  {method}: final error {mode['final_error'] * 100:.2f} cm, phase constant "
                  f"while the operator acts: {mode['phase_constant_while_operator_acts']}, "
                  f"strictly increasing: {mode['phase_strictly_increasing']}")
    for name in ("summary.json", TOY_FIGURES[summary["study"]]):
        print(f"  wrote {output / name}")
    return 0


def _method_study(args, scenario_file):
    study = scenario_file.study or MethodComparison()
    if not isinstance(study, MethodComparison):
        raise ScenarioError(f"{args.scenario}: HSR tasks take study: !MethodComparison")
    if args.methods is not None:
        study = dataclasses.replace(study, methods=_method_list(args.methods))
    if args.trials is not None:
        study = dataclasses.replace(study, trials=args.trials)
    if args.split is not None:
        study = dataclasses.replace(study, split=args.split)
    seed = first_seed(study, study.split) if args.seed is None else args.seed
    split = split_of(study, seed, study.trials)
    if args.jobs < 1:
        raise ScenarioError(f"--jobs {args.jobs}: give a positive number of processes")
    if args.ray_address is not None and args.backend != "ray":
        raise ScenarioError("--ray-address needs --backend ray")
    if len(set(study.methods)) != len(study.methods):
        raise ScenarioError(f"--methods {','.join(study.methods)} names a method twice")
    try:
        check_method_comparison(study, scenario_file.scenario)
    except ScenarioError as error:
        raise ScenarioError(f"{error} (after the command-line overrides)") from None
    output = pathlib.Path(args.output)
    total = len(study.methods) * study.trials
    print(f"Study {scenario_file.scenario.name}: {', '.join(study.methods)}, "
          f"{study.trials} trials each ({split} seeds {seed} to {seed + study.trials - 1}),"
          f" {args.jobs} job{'s' if args.jobs > 1 else ''}"
          + ("" if args.backend == "local" else
             f" on Ray ({args.ray_address or 'local'})") + f", into {output}", flush=True)
    bar = ProgressBar()
    runs = []

    def progress(done, total_now, record, elapsed):
        runs.append(done)
        bar(done, total_now, record, elapsed)

    started = time.monotonic()
    try:
        summary = run_method_comparison(scenario_file.scenario, study.methods, study.trials,
                                        seed, output, progress, jobs=args.jobs, split=split,
                                        retry_errors=args.retry_errors,
                                        backend=args.backend, ray_address=args.ray_address)
    except KeyboardInterrupt:
        print(f"\nInterrupted: the finished trials are in {output / 'trials'}; the same "
              "command resumes the study.", file=sys.stderr)
        return 130
    reused = total - len(runs)
    print(f"Ran {len(runs)} trials in {time.monotonic() - started:.1f} s"
          + (f"; {reused} were already on disk." if reused else "."), flush=True)
    _print_report(summary, output)
    return _failed_trials(summary, output)


def _failed_trials(summary, output):
    """1, with a line on stderr, when trials recorded an error or did not run (a trial
    that ran but missed its target is a result, not an error); else 0."""
    errors = sum(entry["errors"] for entry in summary["methods"].values())
    missing = sum(entry["missing"] for entry in summary["methods"].values())
    if not errors and not missing:
        return 0
    print(f"{errors} of {summary['trials'] * len(summary['methods'])} trials failed with an "
          f"error (in the `error` field of their {output / 'trials'}/METHOD/seed_SEED.json)"
          + (f" and {missing} did not run" if missing else "") + ".", file=sys.stderr)
    return 1


def _print_report(summary, output):
    print(results_table(summary), end="")
    for method, entry in summary["methods"].items():
        if entry["errors"]:
            print(f"  {method}: {entry['errors']} trials failed with an error (seeds "
                  f"{entry['error_seeds']}); see {output / 'trials' / method}")
    for name in ("summary.json", "results.md", "trials.json", *FIGURES):
        print(f"  wrote {output / name}")


def _report(args):
    """Exit 0; 1, like `study`, when trials recorded an error or did not run, and when
    damaged or foreign files were skipped (what could be read is still reported and
    written); 2 (ScenarioError) when there is nothing to report."""
    output = pathlib.Path(args.output)
    summary = report(output)
    _print_report(summary, output)
    failed = _failed_trials(summary, output)
    if summary["damaged"]:
        print(f"pbp-drake: {len(summary['damaged'])} damaged or foreign files skipped "
              f"(listed above and in {output / 'summary.json'})", file=sys.stderr)
        return 1
    return failed
