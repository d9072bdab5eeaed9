"""`pbp-drake study` (a scenario file's study), `pbp-drake report` (a study folder's
tables and figures, rebuilt from its trial files) and `pbp-drake compare` (two studies of
the same seeds, trial by trial); `study` and `report` stop as `signals.stopping_cleanly`
says."""

import dataclasses
import pathlib
import sys
import time

from pbp_drake.cli_types import (
    EXIT_INTERRUPTED, EXIT_TERMINATED, chosen_methods, method_list)
from pbp_drake.commands.scenario_flags import (
    add_goals_flag, add_override_flags, load_with_overrides, scenario_overrides)
from pbp_drake.commands.signals import Terminated, stopping_cleanly
from pbp_drake.core.participant_impairment import PARTICIPANT_CONDITIONS, condition
from pbp_drake.output_paths import check_output_folder
from pbp_drake.robots import drives_real_robot
from pbp_drake.scenarios import (
    Gamepad, Keyboard, MethodComparison, ScenarioError, TaskScenario, VirtualParticipant,
    check_method_comparison, counted)
from pbp_drake.studies.comparison import (
    BACKENDS, name_left_out, run_method_comparison, run_method_matrix)
from pbp_drake.studies.matrix import MATRIX, PILOTS_FOLDER, check_pilots, pilot_folder
from pbp_drake.studies.matrix_report import FIGURE as MATRIX_FIGURE, report_matrix
from pbp_drake.studies.paired import (
    PAIRED_METRICS, paired_comparison, paired_table, paired_with, paired_with_markdown)
from pbp_drake.studies.participant_report import is_participant_collection, participant_report
from pbp_drake.studies.questionnaire_figure import FIG8
from pbp_drake.studies.progress import ProgressBar
from pbp_drake.studies.report import figure_names, report, results_table
from pbp_drake.studies.folders import TOY_STUDIES, folder_kind
from pbp_drake.studies.results_markdown import (
    check_markdown_path, method_comparison_markdown, read_study_json, toy_markdown,
    write_markdown, write_toy_study)
from pbp_drake.studies.splits import SPLITS, check_within_split, first_seed, split_of
from pbp_drake.scenarios.pilots import ATTENTIVE, PILOT_NAMES, with_pilot
from pbp_drake.scenarios.validation import check_seed
from pbp_drake.studies.toy import TOY_FIGURES, print_alpha_study, run_study
from pbp_drake.studies.trial_files import METHOD_COMPARISON, name_damaged


def add_study_commands(commands):
    """The `study` and `report` subcommands and their arguments."""
    study = commands.add_parser("study", help="run the study a scenario file describes")
    study.add_argument("scenario", help="a scenario file with a `study:` section")
    study.add_argument("--output", help="folder for summary.json and figures (default: "
                       "outputs/SCENARIO-METHODS, e.g. outputs/hsr_reach-pbp_alternated-teleop; "
                       "a 2-D study's outputs/SCENARIO)")
    study.add_argument("--methods", help="comma-separated methods to compare (HSR tasks)")
    study.add_argument("--trials", type=int, help="seeded scenes per method (HSR tasks)")
    study.add_argument("--pilots", type=method_list, metavar="P1,P2,...",
                       help="HSR tasks: run every method under each of these operators, "
                       f"of {', '.join(PILOT_NAMES)} ({ATTENTIVE}: the scenario's own virtual "
                       "participant), on the same seeds, into one folder (a subfolder per "
                       "pilot under OUTPUT/pilots); its summary.json holds "
                       "\"pilots\": {NAME: {\"methods\": ...}}")
    study.add_argument("--split", choices=SPLITS,
                       help="HSR tasks: run the study's tuning or evaluation seeds (default: "
                            "the study's `split`)")
    study.add_argument("--seed", type=int, help="the first scene's seed (HSR tasks; results "
                       "are labelled with the split the seeds fall in)")
    study.add_argument("--jobs", type=int, default=1,
                       help="HSR tasks: trials run in this many processes at once (default 1)")
    study.add_argument("--backend", choices=BACKENDS, default="local",
                       help="HSR tasks: run the trials in local processes (default) or as "
                       "Ray tasks, at most --jobs at once (needs: pip install "
                       "'pbp_drake[ray]')")
    study.add_argument("--ray-address", metavar="ADDRESS",
                       help="with --backend ray: the Ray cluster to use, e.g. HEAD:6379, "
                       "auto or ray://HEAD:10001 (its nodes need pbp_drake installed; they "
                       "run this machine's copy of it); default: start a local Ray with "
                       "--jobs CPUs")
    study.add_argument("--retry-errors", action="store_true",
                       help="HSR tasks: run again the trials on disk that failed with an error")
    study.add_argument("--participant-condition", choices=tuple(PARTICIPANT_CONDITIONS),
                       help="HSR tasks with the virtual participant: impair it, in place of "
                       "the file's `impairment`: noisy (motor noise of 0.3 times its speed, "
                       "held about 0.5 s), late (its commands 0.3 s late) or mistaken (one "
                       "target in five first mistaken for another, for 1 s); recorded in "
                       "study.json and named in the results")

    report = commands.add_parser(
        "report", help="rebuild the summary, table and figures of a study folder from its "
        "trial files, without simulating; damaged or foreign files are named on stderr and "
        "skipped (exit 1 when there were any, or when trials failed with an error or did not "
        "run, as `study` does; 2 when there is nothing to report)")
    report.add_argument("output", help="the --output folder of `pbp-drake study` (of a "
                        "matrix, with --pilots: its method x pilot tables with 95 %% "
                        "intervals, every method paired with PBP-Alt per pilot, and "
                        f"{MATRIX_FIGURE}, a panel per pilot), or a user "
                        "study's folder of participant folders (`pbp-drake session --participant "
                        "ID --output DIR/ID`): then per-method metrics and answers, pairwise "
                        "Wilcoxon tests and Fig. 8 in DIR/results.md and "
                        f"DIR/{FIG8}")
    report.add_argument("--paired-with", metavar="METHOD",
                        help="also compare every other method of the study with METHOD "
                        "(e.g. pbp_alternated), seed by seed: per metric the paired "
                        "difference and its 95 %% interval, as `compare` does between two "
                        "studies (printed, and in --markdown's file); for a matrix, the "
                        "method every other is paired with (default pbp_alternated)")
    report.add_argument("--markdown", metavar="FILE",
                        help="also write the study's results table as a Markdown fragment "
                        "to FILE (its folder is created), after a line naming the command "
                        "and seeds that made the study; for a 2-D study folder, a table of "
                        "its summary.json and the figure's path (not for a user study)")
    compare = commands.add_parser(
        "compare", help="compare two studies of the same seeds trial by trial (e.g. before "
        "and after changing a setting): per method and metric, the paired difference and "
        "its 95 %% interval against the first study's trial-to-trial noise; exit 1 when a "
        "metric moved by more than that noise or a trial's file was damaged (each named on "
        "stderr, its trial left out)")
    compare.add_argument("first", help="a `pbp-drake study` --output folder (A)")
    compare.add_argument("second", help="another, of the same seeds (B)")
    add_goals_flag(add_override_flags(study))
    study.set_defaults(handler=stopping_cleanly(_study))
    report.set_defaults(handler=stopping_cleanly(_report))
    compare.set_defaults(handler=_compare)


def _study(args):
    overrides = scenario_overrides(args, shorthands=False)
    scenario_file = load_with_overrides(args, overrides)
    if drives_real_robot(getattr(scenario_file.scenario.robot, "hardware", None)):
        raise ScenarioError("a study runs its trials unattended in simulation: drop "
                            "robot.hardware.connect (pbp-drake run --hardware drives the real "
                            "arm; --driver-sim studies the LCM path)")
    if args.output is None:
        args.output = str(default_output(args.scenario, scenario_file, args.methods))
    check_output_folder(args.output)
    if isinstance(scenario_file.scenario, TaskScenario):
        return _method_study(args, scenario_file, overrides)
    for flag, given in (("--pilots", args.pilots is not None),
                        (f"--participant-condition {args.participant_condition}",
                         args.participant_condition is not None)):
        if given:
            raise ScenarioError(f"{flag}: {args.scenario} is a 2-D study, which has no "
                                "virtual participant; the HSR tasks' studies take it")
    for flag, given in (("--methods", args.methods is not None),
                        ("--trials", args.trials is not None),
                        ("--split", args.split is not None), ("--seed", args.seed is not None),
                        ("--jobs", args.jobs != 1), ("--backend", args.backend != "local"),
                        ("--ray-address", args.ray_address is not None),
                        ("--retry-errors", args.retry_errors)):
        if given:  # not left unused in silence
            raise ScenarioError(f"{flag}: {args.scenario} is a 2-D study, whose runs its "
                                "`study:` section sets; the HSR tasks' studies take it")
    if scenario_file.study is None:
        raise ScenarioError(f"{args.scenario}: has no `study:` section to run")
    output = pathlib.Path(args.output)
    started = time.monotonic()
    summary = run_study(scenario_file, output)
    write_toy_study(output, summary["study"], summary["scenario"], args.scenario,
                    overrides.record() if overrides else None)
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


def default_output(scenario_path, scenario_file, methods=None):
    """`outputs/<the file's stem>-<the methods, by '-'>` (`methods`: `--methods`' text, None
    for the study's); a 2-D study's `outputs/<stem>`."""
    stem = pathlib.Path(scenario_path).stem
    if not isinstance(scenario_file.study, MethodComparison) and methods is None:
        return pathlib.Path("outputs", stem)
    methods = method_list(methods) if methods else scenario_file.study.methods
    return pathlib.Path("outputs", "-".join([stem, *methods]))


def with_participant_condition(scenario, name, scenario_path):
    """`scenario` with its virtual participant impaired by the named condition, in place of
    the file's `impairment`; ScenarioError for another operator."""
    operator = scenario.operator
    if not isinstance(operator, VirtualParticipant):
        raise ScenarioError(
            f"--participant-condition {name}: {scenario_path}'s scenario.operator is "
            f"!{type(operator).__name__}, not the virtual participant; the condition impairs "
            "operator: !VirtualParticipant only")
    return dataclasses.replace(
        scenario, operator=dataclasses.replace(operator, impairment=condition(name)))


def _method_study(args, scenario_file, overrides):
    scenario = scenario_file.scenario
    if args.pilots is not None:
        check_pilots(args.pilots)
        if args.participant_condition is not None:
            raise ScenarioError("--participant-condition and --pilots: give one (the "
                                "condition impairs the scenario's own participant; "
                                "--pilots replaces it)")
    if args.participant_condition is not None:
        scenario = with_participant_condition(scenario, args.participant_condition,
                                              args.scenario)
    study = scenario_file.study or MethodComparison()  # the loader refused any other kind
    if isinstance(scenario.operator, (Keyboard, Gamepad)):
        raise ScenarioError("a study runs unattended: use operator: !VirtualParticipant {} "
                            "(--set 'operator=!VirtualParticipant {}')")
    methods = (None if args.methods is None
               else chosen_methods(args.methods, "pbp_alternated,teleop"))
    if args.trials is not None and args.trials < 1:
        raise ScenarioError(f"--trials must be at least 1, got {args.trials}")
    flags = {"methods": methods, "trials": args.trials, "split": args.split}
    study = dataclasses.replace(study, **{name: value for name, value in flags.items()
                                          if value is not None})
    if args.seed is not None:
        check_seed(args.seed, "--seed")
    seed = first_seed(study, study.split) if args.seed is None else args.seed
    if args.split is not None or args.seed is None:  # else --seed's seeds, labelled
        check_within_split(study, study.split, seed, study.trials,
                           f"--split {args.split}" if args.split else
                           f"{args.scenario}'s study.split {study.split}")
    split = split_of(study, seed, study.trials)
    if args.jobs < 1:
        raise ScenarioError(f"--jobs {args.jobs}: give a positive number of processes")
    if args.ray_address is not None and args.backend != "ray":
        raise ScenarioError("--ray-address needs --backend ray")
    try:
        check_method_comparison(study, scenario)
    except ScenarioError as error:
        raise ScenarioError(f"{error} (after the command-line overrides)") from None
    output = pathlib.Path(args.output)
    pilots = args.pilots or []
    for pilot in pilots:  # a pilot the scenario cannot take stops here, nothing written
        with_pilot(scenario, pilot)
    total = len(study.methods) * study.trials * max(1, len(pilots))
    condition_words = ("" if args.participant_condition is None else
                       f", the {args.participant_condition} virtual participant")
    if pilots:
        condition_words = f", under the pilots {', '.join(pilots)}"
    print(f"Study {scenario.name}: {', '.join(study.methods)}, "
          f"{counted(study.trials, 'trial')} each ({split} seeds {seed} to "
          f"{seed + study.trials - 1}){condition_words},"
          f" {args.jobs} job{'s' if args.jobs > 1 else ''}"
          + ("" if args.backend == "local" else
             f" on Ray ({args.ray_address or 'local'})") + f", into {output}", flush=True)
    bar = ProgressBar()
    runs = []

    def progress(done, total_now, record, elapsed):
        runs.append(done)
        bar(done, total_now, record, elapsed)

    started = time.monotonic()
    options = dict(jobs=args.jobs, split=split, retry_errors=args.retry_errors,
                   backend=args.backend, ray_address=args.ray_address,
                   scenario_file=args.scenario,
                   overrides=overrides.record() if overrides else None,
                   split_seeds={split_name: first_seed(study, split_name)
                                for split_name in SPLITS})
    try:
        if pilots:
            summary = run_method_matrix(scenario, study.methods, pilots, study.trials, seed,
                                        output, progress, **options)
        else:
            summary = run_method_comparison(
                scenario, study.methods, study.trials, seed, output, progress,
                participant_condition=args.participant_condition, **options)
    except KeyboardInterrupt as stop:
        terminated = isinstance(stop, Terminated)
        trials = output / "pilots" / "*" / "trials" if pilots else output / "trials"
        print(f"\n{'Terminated (SIGTERM)' if terminated else 'Interrupted'}: the finished "
              f"trials are in {trials}; the same command resumes the study.", file=sys.stderr)
        return EXIT_TERMINATED if terminated else EXIT_INTERRUPTED
    reused = total - len(runs)
    print(f"Ran {counted(len(runs), 'trial')} in {time.monotonic() - started:.1f} s"
          + (f"; {reused} were already on disk." if reused else "."), flush=True)
    if pilots:
        _print_matrix_report(summary, output)
        return _failed_matrix_trials(summary, output)
    _print_report(summary, output)
    return _failed_trials(summary, output)


def _failed_trials(summary, output, where=None):
    """1, with a line on stderr, when trials recorded an error or did not run (a missed
    target is a result, not an error); else 0."""
    errors = sum(entry["errors"] for entry in summary["methods"].values())
    missing = sum(entry["missing"] for entry in summary["methods"].values())
    if not errors and not missing:
        return 0
    print(f"{errors} of {summary['trials'] * len(summary['methods'])} trials"
          + ("" if where is None else f" {where}") + " failed with an "
          f"error (in the `error` field of their {output / 'trials'}/METHOD/seed_SEED.json)"
          + (f" and {missing} did not run" if missing else "") + ".", file=sys.stderr)
    return 1


def _failed_matrix_trials(summary, output):
    """`_failed_trials` of each pilot of a matrix: 1 when any pilot's are."""
    return max(_failed_trials({**summary, **pilot}, pilot_folder(output, name),
                              f"under the pilot {name}")
               for name, pilot in summary["pilots"].items())


def _print_matrix_report(summary, output):
    print((output / "results.md").read_text(), end="")
    for name in ("summary.json", "results.md", "trials.json", MATRIX_FIGURE):
        print(f"  wrote {output / name}")


def _print_report(summary, output):
    print(results_table(summary), end="")
    for method, entry in summary["methods"].items():
        if entry["errors"]:
            print(f"  {method}: {counted(entry['errors'], 'trial')} failed with an error (seeds "
                  f"{entry['error_seeds']}); see {output / 'trials' / method}")
    for name in ("summary.json", "results.md", "trials.json", *figure_names(summary)):
        print(f"  wrote {output / name}")


def _compare(args):
    """Prints the paired table (`pbp_drake.studies.paired`); exit 1 when a metric of two
    pairs or more moved by more than the first study's trial-to-trial SD or a file was
    damaged (each named on stderr, its trial left out), 2 when the studies share no trial."""
    for which, folder in (("first", args.first), ("second", args.second)):
        _check_is_folder(folder, f"compare: the {which} folder's")
        kind = folder_kind(folder)
        if kind not in (None, METHOD_COMPARISON):
            pilots = sorted((pathlib.Path(folder) / PILOTS_FOLDER).glob("*/study.json"))
            within = (f": compare one pilot's study in it, e.g. {pilots[0].parent}"
                      if kind == MATRIX and pilots else "")
            raise ScenarioError(f"compare: {folder} holds a study of kind {kind!r}, not a "
                                f"method comparison{within}")
    damaged, unpaired = [], []
    rows = paired_comparison(args.first, args.second, damaged, unpaired)
    name_damaged(damaged)
    if not rows:
        raise ScenarioError(f"{args.first} and {args.second} share no method and seed that "
                            "both ran without an error")
    print(paired_table(rows, "A", "B"), end="")
    moved = [row for row in rows if row.moved]
    judged = sum(row.judged for row in rows)
    single = len(rows) - judged
    print(f"A = {args.first}, B = {args.second}. " + (
        f"{len(moved)} of {judged} rows moved by more than A's trial-to-trial SD."
        if moved else f"All {judged} rows within A's trial-to-trial SD." if judged else
        "No row has two pairs: nothing is judged; run both studies with more trials.")
        + (f" {counted(single, 'row')} of a single pair not judged (one trial has no SD)."
           if single and judged else "")
        + "".join(f" {method}: only in {side}, not compared." if side else
                  f" {method}: no seed both ran without an error, not compared."
                  for method, side in unpaired))
    if damaged:
        print(f"pbp-drake: {counted(len(damaged), 'damaged or foreign file')} skipped (listed "
              "above); their trials are left out of the pairs", file=sys.stderr)
    return 1 if moved or damaged else 0


def _report(args):
    """`report` of a study folder, a matrix's or a folder of participant folders, with the
    exit codes the command's help gives."""
    _check_is_folder(args.output, "report: the folder's")
    output = pathlib.Path(args.output)
    if args.markdown is not None:
        check_markdown_path(args.markdown)
        if folder_kind(output) in TOY_STUDIES:
            write_markdown(args.markdown, toy_markdown(output))
            print(f"  wrote {args.markdown}")
            return 0
        if is_participant_collection(output):
            raise ScenarioError(f"--markdown: {output} is a user study's folder; --markdown "
                                "takes a `pbp-drake study` folder")
    kind = folder_kind(output)
    # A 2-D study keeps no trial files to rebuild from (with trials/, its study.json is a
    # damaged one of a robot task's study, which read_study names).
    if kind in TOY_STUDIES and not (output / "trials").is_dir():
        raise ScenarioError(f"{output} holds a 2-D study ({kind}), whose summary.json and "
                            "figure `pbp-drake study` writes; report rebuilds a robot task's "
                            "study from its trial files (--markdown FILE: a table of this one)")
    if is_participant_collection(output):
        text, damaged = participant_report(output)
        print(text, end="")
        for name in ("results.md", FIG8):
            print(f"  wrote {output / name}")
        if damaged:
            print(f"pbp-drake: {counted(damaged, 'damaged file')} skipped (listed above)",
                  file=sys.stderr)
        return 1 if damaged else 0
    if kind == MATRIX:
        return _report_matrix(args, output)
    paired = None
    if args.paired_with is not None:  # a method the study did not run: refused, unwritten
        try:
            unpaired = []
            rows = paired_with(output, args.paired_with, PAIRED_METRICS, unpaired)
        except ValueError as error:
            raise ScenarioError(f"--paired-with: {error}") from None
        paired = paired_with_markdown(rows, args.paired_with, unpaired)
    summary = report(output)
    _print_report(summary, output)
    name_left_out(output, summary["methods"], summary["trials"], summary["seed"])
    if paired is not None:
        print(paired, end="")
    if args.markdown is not None:
        write_markdown(args.markdown, method_comparison_markdown(
            read_study_json(output), summary) + ("" if paired is None else "\n" + paired))
        print(f"  wrote {args.markdown}")
    return _report_status(summary, output, _failed_trials(summary, output))


def _check_is_folder(path, whose):
    """ScenarioError unless `path` is a folder: a file (a study's study.json, say) would be
    read as a folder without a study, or as a user study's; `whose` names an empty path."""
    if not path:  # pathlib would read it as ".", the current folder
        raise ScenarioError(f"{whose} path is empty; give a `pbp-drake study` --output folder")
    path = pathlib.Path(path)
    if path.is_file():
        raise ScenarioError(f"{path}: is a file, not a folder; give a `pbp-drake study` "
                            "--output folder")
    if not path.is_dir():
        raise ScenarioError(f"{path}: no such folder")


def _report_matrix(args, output):
    """`report` of a matrix folder: its tables, figure and --markdown file."""
    try:
        summary = report_matrix(output, args.paired_with, args.markdown)
    except ScenarioError:  # the folder's own problem (StudyFolderError), named as it is
        raise
    except ValueError as error:
        raise ScenarioError(f"--paired-with: {error}") from None
    _print_matrix_report(summary, output)
    if args.markdown is not None:
        print(f"  wrote {args.markdown}")
    return _report_status(summary, output, _failed_matrix_trials(summary, output))


def _report_status(summary, output, failed):
    """1, with a line on stderr, when files were damaged or foreign; else `failed`."""
    if summary["damaged"]:
        print(f"pbp-drake: {counted(len(summary['damaged']), 'damaged or foreign file')} skipped "
              f"(listed above and in {output / 'summary.json'})", file=sys.stderr)
        return 1
    return failed
