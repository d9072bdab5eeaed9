"""Every study the docs quote, in one list: `make results` runs them
(`python -m pbp_drake_bench.results_catalogue`), each into `outputs/results/NAME/` with
`--jobs 2`, and writes its table with `pbp-drake report DIR --markdown
docs/results/generated/NAME.md`. The first line of each generated file is the command below
(read back from the study folder), so a table on the docs site cannot drift from what made it.
The matrices of every method under every pilot (`ARENA_STUDIES`) also make the arena page,
docs/results/arena.md (`pbp_drake_bench.arena_page`), from their summaries, and the many-goals
studies the K sweep's figure and table (`pbp_drake_bench.many_goals_figure`).

A study interrupted part-way resumes from the trials on disk when this runs again, if the
code that made them is today's (`code_fingerprint`, kept in the folder's `.code`); a folder
made by other code starts afresh, since a study's hash covers its scenario, not the code.
"""

import argparse
import hashlib
import pathlib
import shutil
import subprocess
import sys

from pbp_drake.scenarios.pilots import PILOT_NAMES
from pbp_drake_bench.arena_page import write_arena_page
from pbp_drake_bench.many_goals_figure import (
    ESTIMATORS, GOAL_COUNTS, OTHER_METHODS, methods_study_name, plot_many_goals,
    write_sweep_table)
from pbp_drake_bench.many_goals_figure import sweep as many_goals_sweep
from pbp_drake_bench.many_goals_figure import FIGURE as MANY_GOALS_FIGURE
from pbp_drake_bench.many_goals_figure import TABLE as MANY_GOALS_TABLE
from pbp_drake.studies.matrix_report import FIGURE as MATRIX_FIGURE
from pbp_drake.studies.report import BOX_FIGURES as DOCS_FIGURES

REACH = ["diagrams/hsr_reach.yaml", "--methods",
         "pbp_alternated,pbp_continuous,confidence_alpha,teleop", "--trials", "30"]
# The obstacle task's methods are its file's (`study:` section); the generated line names them.
OBSTACLES = ["diagrams/hsr_obstacles.yaml", "--trials", "30"]
FIXED_ALPHAS = ",".join(f"fixed_alpha=0.{tenth}" for tenth in range(1, 10))
PBP = "pbp_alternated,pbp_continuous"
# PBP beside the shared-autonomy baselines (docs/results/baselines.md) and teleop: HOP, its
# predict-then-assist variant and Dragan and Srinivasa's arbitration (confidence_alpha).
BASELINE_METHODS = "hop,predict_then_assist,confidence_alpha"
BASELINES = ["--methods", f"pbp_alternated,pbp_continuous,{BASELINE_METHODS},teleop",
             "--trials", "30", "--split", "evaluation"]
# The reaching task's methods with the virtual participant unimpaired and under each of its
# conditions (docs/results/impaired.md).
IMPAIRED = ["diagrams/hsr_reach.yaml", "--methods",
            f"pbp_alternated,pbp_continuous,{BASELINE_METHODS},teleop",
            "--trials", "30", "--split", "evaluation"]

# Every method under every pilot of the registry (`scenarios.pilots`), on the evaluation
# seeds; its tasks: name -> (scenario file, the arena page's title of it).
ARENA = ["--methods", "pbp_alternated,pbp_continuous,hop,confidence_alpha,teleop",
         "--split", "evaluation", "--pilots", ",".join(PILOT_NAMES)]
# 30 trials a cell on the reaching task; 10 on the others, whose trials are the slowest
# (750 trials of the reaching task take most of `make results`' time already).
ARENA_TASKS = {"hsr_reach_arena": ("diagrams/hsr_reach.yaml", "Reaching", 30),
               "hsr_obstacles_arena": ("diagrams/hsr_obstacles.yaml", "Obstacles", 10),
               "hsr_grasp_arena": ("diagrams/hsr_grasp.yaml", "Grasping", 10),
               "arm_reach_arena": ("diagrams/arm_reach.yaml", "Reaching with the arm", 10)}

# The reaching task with K candidate goals on a grid (docs/results/many-goals.md): PBP-Alt
# following one goal at a time (the paper's) beside teleop, and PBP-Alt with goal groups;
# on the HSR at K = 4, 100 and 1,000, and on the arm at K = 100.
MANY_GOALS = GOAL_COUNTS
GROUPS = ["--set", "goal_estimator.group_mass=0.9"]
INTENT_FILTER = ["--set", "goal_estimator.method=intent_filter"]
# The shipped estimators beside `angle` that read the hand in the reaching task.
OTHER_ESTIMATORS = tuple(estimator for estimator in ESTIMATORS if estimator != "angle")
EVALUATION_30 = ["--trials", "30", "--split", "evaluation"]
GRASPS_300 = ["diagrams/hsr_grasp.yaml", "--set", "task.object_count=10", "--set",
              "task.grasps_per_object=30"]
# The intent filter's silence and override rates (nats/s) on the grasping task: teleop
# cannot show them (there a silent operator leaves the hand still, and no goal is shown),
# so they are chosen on PBP-Alt's tuning seeds 0 to 7 at 10 x 30 grasps
# (docs/results/many-goals.md has the numbers).
GRASP_INTENT_FILTER = ["--set", "goal_estimator.intent_filter.silence_rate=8", "--set",
                       "goal_estimator.intent_filter.override_rate=10"]

#: name -> the arguments of `pbp-drake study` (without --output and --jobs).
STUDIES = {
    "toy_alpha_study": ["diagrams/toy_alpha_study.yaml"],
    "toy_alt_vs_cont": ["diagrams/toy_alt_vs_cont.yaml"],
    "hsr_reach_evaluation": [*REACH, "--split", "evaluation"],
    "hsr_reach_tuning": [*REACH, "--split", "tuning"],
    "hsr_reach_teleop_calibration": ["diagrams/hsr_reach.yaml", "--methods", "teleop",
                                     "--trials", "30", "--split", "tuning"],
    "hsr_reach_nearest": ["diagrams/hsr_reach_nearest.yaml", "--methods", PBP,
                          "--trials", "30", "--split", "evaluation"],
    "hsr_reach_bayesian": ["diagrams/hsr_reach_bayesian.yaml", "--methods", PBP,
                           "--trials", "30", "--split", "evaluation"],
    "hsr_obstacles_evaluation": [*OBSTACLES, "--split", "evaluation"],
    # A still wall across the way (docs/tasks/teach.md): straight DMPs, and the primitive
    # taught around its end.
    "hsr_wall_evaluation": ["diagrams/hsr_wall.yaml", "--trials", "30", "--split",
                            "evaluation"],
    "hsr_wall_primitive_evaluation": [
        "diagrams/hsr_wall.yaml", "--methods", PBP, "--trials", "30", "--split", "evaluation",
        "--set", "dmp.primitive=primitives/around_the_wall.json"],
    # ... and under every pilot of the arena (10 trials a cell, as the arena's slower tasks).
    "hsr_wall_pilots": ["diagrams/hsr_wall.yaml", "--methods", "pbp_alternated,teleop",
                        "--trials", "10", "--split", "evaluation", "--pilots",
                        ",".join(PILOT_NAMES)],
    "hsr_wall_primitive_pilots": [
        "diagrams/hsr_wall.yaml", "--methods", "pbp_alternated", "--trials", "10", "--split",
        "evaluation", "--pilots", ",".join(PILOT_NAMES), "--set",
        "dmp.primitive=primitives/around_the_wall.json"],
    "hsr_obstacles_tuning": [*OBSTACLES, "--split", "tuning"],
    "hsr_reach_fixed_alpha": ["diagrams/hsr_reach.yaml", "--methods", FIXED_ALPHAS,
                              "--trials", "30", "--split", "tuning"],
    "hsr_obstacles_fixed_alpha": ["diagrams/hsr_obstacles.yaml", "--methods", FIXED_ALPHAS,
                                  "--trials", "30", "--split", "tuning"],
    "hsr_grasp_evaluation": ["diagrams/hsr_grasp.yaml", "--methods",
                             "pbp_alternated,pbp_continuous,teleop", "--trials", "30",
                             "--split", "evaluation"],
    "hsr_reach_baselines": ["diagrams/hsr_reach.yaml", *BASELINES],
    "hsr_obstacles_baselines": ["diagrams/hsr_obstacles.yaml", *BASELINES],
    "hsr_grasp_baselines": ["diagrams/hsr_grasp.yaml", *BASELINES],
    "hsr_reach_maxent": ["diagrams/hsr_reach_maxent.yaml", "--methods", PBP,
                         "--trials", "30", "--split", "evaluation"],
    "hsr_reach_unimpaired": IMPAIRED,
    # The reaching task on our 7-joint arm (docs/results/arm.md), and the same scenario on
    # the test suite's 6-joint arm of other kinematics is the test's.
    "arm_reach_evaluation": ["diagrams/arm_reach.yaml", "--methods",
                             f"pbp_alternated,pbp_continuous,{BASELINE_METHODS},teleop",
                             "--trials", "30", "--split", "evaluation"],
    # The same with a participant that never moves the hand to where the tool can point
    # (docs/results/arm.md shows both).
    "arm_reach_without_repositioning": [
        "diagrams/arm_reach_without_repositioning.yaml", "--methods",
        f"pbp_alternated,pbp_continuous,{BASELINE_METHODS},teleop", "--trials", "30",
        "--split", "evaluation"],
    "arm_reach_teleop_calibration": ["diagrams/arm_reach.yaml", "--methods", "teleop",
                                     "--trials", "30", "--split", "tuning"],
    # Our Franka Panda and KUKA iiwa (docs/results/arm.md): teleop on the tuning seeds,
    # then PBP against it on the evaluation seeds.
    **{f"{arm}_reach_teleop_calibration": [f"diagrams/{arm}_reach.yaml", "--methods", "teleop",
                                           "--trials", "30", "--split", "tuning"]
       for arm in ("panda", "iiwa")},
    **{f"{arm}_reach_evaluation": [f"diagrams/{arm}_reach.yaml", "--methods",
                                   "pbp_alternated,pbp_continuous,teleop", *EVALUATION_30]
       for arm in ("panda", "iiwa")},
    **{f"hsr_reach_{condition}": [*IMPAIRED, "--participant-condition", condition]
       for condition in ("noisy", "late", "mistaken")},
    **{f"hsr_reach_goals_{goals}": ["diagrams/hsr_reach.yaml", "--goals", str(goals),
                                     "--methods", "pbp_alternated,teleop", *EVALUATION_30]
       for goals in MANY_GOALS},
    **{f"hsr_reach_goals_{goals}_groups": ["diagrams/hsr_reach.yaml", "--goals", str(goals),
                                            *GROUPS, "--methods", "pbp_alternated",
                                            *EVALUATION_30] for goals in MANY_GOALS},
    # The same with each of the other estimators (docs/results/many-goals.md).
    **{f"hsr_reach_goals_{goals}_groups_{estimator}": [
        "diagrams/hsr_reach.yaml", "--goals", str(goals), *GROUPS, "--set",
        f"goal_estimator.method={estimator}", "--methods", "pbp_alternated", *EVALUATION_30]
       for estimator in OTHER_ESTIMATORS for goals in MANY_GOALS},
    "arm_reach_goals_100": ["diagrams/arm_reach.yaml", "--goals", "100", "--methods",
                            "pbp_alternated,teleop", *EVALUATION_30],
    "arm_reach_goals_100_groups": ["diagrams/arm_reach.yaml", "--goals", "100", *GROUPS,
                                   "--methods", "pbp_alternated", *EVALUATION_30],
    # What the intent filter's operator model is fitted on (`studies.intent_fit`): teleop
    # under every pilot, on tuning seeds, at K = 4 and 100.
    **{f"hsr_reach_goals_{goals}_teleop_tuning": [
        "diagrams/hsr_reach.yaml", "--goals", str(goals), "--methods", "teleop", "--trials",
        "16", "--split", "tuning", "--pilots", ",".join(PILOT_NAMES)] for goals in (4, 100)},
    # A participant that first heads for a wrong object, now and then (impaired.md).
    "hsr_reach_goals_100_groups_mistaken": [
        "diagrams/hsr_reach.yaml", "--goals", "100", *GROUPS, "--methods",
        "pbp_alternated,teleop", *EVALUATION_30, "--participant-condition", "mistaken"],
    "hsr_reach_goals_100_groups_pilots": [
        "diagrams/hsr_reach.yaml", "--goals", "100", *GROUPS, "--methods",
        "pbp_alternated,teleop", *EVALUATION_30, "--pilots", ",".join(PILOT_NAMES)],
    # The intent filter with goal groups: under every pilot at each K (teleop under them at
    # K = 100 is hsr_reach_goals_100_groups_pilots'), mistaken, on the arm.
    **{f"hsr_reach_goals_{goals}_groups_intent_filter_pilots": [
        "diagrams/hsr_reach.yaml", "--goals", str(goals), *GROUPS, *INTENT_FILTER, "--methods",
        "pbp_alternated" if goals == 100 else "pbp_alternated,teleop", *EVALUATION_30,
        "--pilots", ",".join(PILOT_NAMES)] for goals in MANY_GOALS},
    # Every other method at each K, with goal groups and the intent filter where it follows
    # DMPs (HOP's methods have none).
    **{methods_study_name(goals): [
        "diagrams/hsr_reach.yaml", "--goals", str(goals), *GROUPS, *INTENT_FILTER, "--methods",
        ",".join(OTHER_METHODS), *EVALUATION_30] for goals in MANY_GOALS},
    "hsr_reach_goals_100_groups_intent_filter_mistaken": [
        "diagrams/hsr_reach.yaml", "--goals", "100", *GROUPS, *INTENT_FILTER, "--methods",
        "pbp_alternated", *EVALUATION_30, "--participant-condition", "mistaken"],
    "arm_reach_goals_100_groups_intent_filter": [
        "diagrams/arm_reach.yaml", "--goals", "100", *GROUPS, *INTENT_FILTER, "--methods",
        "pbp_alternated", *EVALUATION_30],
    # The grasping task with 10 objects of 30 grasps each (docs/tasks/grasp.md): PBP-Alt
    # with the pose estimator one grasp at a time (the paper's) beside teleop, with goal
    # groups, and with goal groups and the intent filter, whose silences and overrides are
    # evidence here.
    "hsr_grasp_grasps_300": [*GRASPS_300, "--methods", "pbp_alternated,teleop",
                             *EVALUATION_30],
    "hsr_grasp_grasps_300_groups": [*GRASPS_300, *GROUPS, "--methods", "pbp_alternated",
                                    *EVALUATION_30],
    "hsr_grasp_grasps_300_groups_intent_filter": [
        *GRASPS_300, *GROUPS, *INTENT_FILTER, *GRASP_INTENT_FILTER, "--methods",
        "pbp_alternated", *EVALUATION_30],
    # Every method under every pilot (docs/results/arena.md).
    **{name: [scenario, *ARENA[:2], "--trials", str(trials), *ARENA[2:]]
       for name, (scenario, _, trials) in ARENA_TASKS.items()},
}

#: The matrices of the arena page: name -> the page's title of the task.
ARENA_STUDIES = {name: title for name, (_, title, _) in ARENA_TASKS.items()}


#: Studies whose page compares every method with PBP-Alt seed by seed and shows the study's
#: figures side by side (docs/results/baselines.md): their report adds `--paired-with
#: pbp_alternated`, and the figures are copied beside the table as NAME_FIGURE.png.
PAIRED_WITH_PBP_ALT = ("hsr_reach_baselines", "hsr_obstacles_baselines",
                       "hsr_grasp_baselines")


def with_trials(arguments, trials):
    """The arguments with `--trials` set to `trials` (for a quick check; None: unchanged)."""
    if trials is None or "--trials" not in arguments:
        return list(arguments)
    arguments = list(arguments)
    arguments[arguments.index("--trials") + 1] = str(trials)
    return arguments


# What a trial's numbers depend on beside its scenario: the package and the robot models.
FINGERPRINTED = ("pbp_drake", "models")
CODE_STAMP = ".code"


def code_fingerprint(repo=pathlib.Path(__file__).resolve().parents[1]):
    """A digest of the package's Python files and the models' files under `repo`."""
    digest = hashlib.sha256()
    for root in FINGERPRINTED:
        for path in sorted((repo / root).rglob("*")):
            if path.is_file() and "__pycache__" not in path.parts:
                digest.update(str(path.relative_to(repo)).encode() + b"\0")
                digest.update(path.read_bytes())
    return digest.hexdigest()


def afresh_unless_made_by(output, fingerprint):
    """Empties the study folder `output` when other code made it (no stamp, or another),
    then stamps it with `fingerprint`; True when it was emptied."""
    stamp = output / CODE_STAMP
    emptied = output.exists() and (not stamp.is_file() or stamp.read_text() != fingerprint)
    if emptied:
        shutil.rmtree(output)
        print(f"  {output} was made by other code: started afresh", flush=True)
    output.mkdir(parents=True, exist_ok=True)
    stamp.write_text(fingerprint)
    return emptied


def _pbp_drake(*arguments):
    command = [sys.executable, "-m", "pbp_drake", *arguments]
    print("+ pbp-drake " + " ".join(arguments), flush=True)
    return subprocess.run(command).returncode


def main(argv=None):
    """Runs the studies (all, or those named) and writes their Markdown (also for a study
    whose trials failed: its table counts them); returns 1 when any study or report failed
    (each is named at the end), else 0."""
    parser = argparse.ArgumentParser(prog="python -m pbp_drake_bench.results_catalogue",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help=f"studies to run (default: all of "
                        f"{', '.join(STUDIES)})")
    parser.add_argument("--outputs", default="outputs/results",
                        help="the study folders go in OUTPUTS/NAME (default outputs/results)")
    parser.add_argument("--generated", default="docs/results/generated",
                        help="the Markdown goes to GENERATED/NAME.md (default "
                             "docs/results/generated)")
    parser.add_argument("--arena", default="docs/results/arena.md",
                        help="the page of the matrices' claims, written when one of "
                             f"{', '.join(ARENA_STUDIES)} runs (default docs/results/arena.md)")
    parser.add_argument("--jobs", type=int, default=2, help="processes per study (default 2)")
    parser.add_argument("--trials", type=int,
                        help="for a quick check only: this many trials per HSR method")
    args = parser.parse_args(argv)
    unknown = [name for name in args.names if name not in STUDIES]
    if unknown:
        parser.error(f"unknown studies {', '.join(unknown)}; known: {', '.join(STUDIES)}")
    failed = []
    fingerprint = code_fingerprint()
    for name in args.names or STUDIES:
        output = pathlib.Path(args.outputs) / name
        afresh_unless_made_by(output, fingerprint)
        markdown = pathlib.Path(args.generated) / f"{name}.md"
        studied = _pbp_drake("study", *with_trials(STUDIES[name], args.trials),
                             "--jobs", str(args.jobs), "--output", str(output))
        if studied != 0:
            failed.append(f"{name}: `pbp-drake study` exited with {studied}")
        if studied not in (0, 1):  # 1: trials failed, and its table counts them
            continue
        paired = ["--paired-with", "pbp_alternated"] if name in PAIRED_WITH_PBP_ALT else []
        reported = _pbp_drake("report", str(output), "--markdown", str(markdown), *paired)
        if reported != 0 and studied == 0:
            failed.append(f"{name}: `pbp-drake report` exited with {reported}")
        if paired and reported == 0:
            for figure in DOCS_FIGURES:
                shutil.copyfile(output / figure, markdown.with_name(f"{name}_{figure}"))
        if name in ARENA_STUDIES and reported in (0, 1):
            # A matrix's one figure, copied beside its table as NAME_pilots.png.
            shutil.copyfile(output / MATRIX_FIGURE, markdown.with_name(f"{name}_{MATRIX_FIGURE}"))
    if any(name in ARENA_STUDIES for name in args.names or STUDIES):
        write_arena_page(ARENA_STUDIES, args.outputs, args.generated, args.arena)
        print(f"  wrote {args.arena}")
    if any(name.startswith("hsr_reach_goals_") for name in args.names or STUDIES):
        figure = pathlib.Path(args.generated) / MANY_GOALS_FIGURE
        table = pathlib.Path(args.generated) / MANY_GOALS_TABLE
        lines = many_goals_sweep(args.outputs)
        if plot_many_goals(lines, figure) and write_sweep_table(lines, table):
            print(f"  wrote {figure} and {table}")
    for line in failed:
        print(f"results: {line}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
