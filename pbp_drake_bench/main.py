"""`pbp-drake bench` (`python -m pbp_drake_bench`): its command line, one row of step
timings per (D, K, weights), the closed-loop runs, and the files it writes."""

import argparse
import json
import math
import os
import platform
import sys
from pathlib import Path

import numpy as np

import pbp_drake_bench
from pbp_drake.output_paths import dangling_link
from pbp_drake_bench.cases import (
    BASIS, DT, bank_math_step, leaf_simulator, leaf_step, make_bank, make_case, motion_fields)
from pbp_drake_bench.checks import (
    CHECKED_HSR_GOALS, CHECKED_REPLAY_GOALS, MOTION_ROWS, PEERS, evaluate, exit_code)
from pbp_drake_bench.closed_loop import HSR_KS, TASKS, closed_loop_runs, split_run
from pbp_drake_bench.driver_rate import driver_rate_run
from pbp_drake_bench.estimators import estimator_steps
from pbp_drake_bench.peers import (
    available, movement_primitives_stacked_step, movement_primitives_step, pydmps_step)
from pbp_drake_bench.pinning import blas_threads, in_measuring_process, measure_in_fresh_process
from pbp_drake_bench.plot import plot_control_rate, plot_scaling
from pbp_drake_bench.pose_cases import measure_pose_row
from pbp_drake_bench.replay import REPLAY_SECONDS, replay_sizes
from pbp_drake_bench.table import format_report, microseconds, ratio
from pbp_drake_bench.timing import memory_bandwidth, timed

KS = (1, 10, 100, 1000, 10000, 100000)
DS = (2, 3, 6)
POSE_MAX_GOALS = 10000
# The reach runs whose per-tick time is split by category (headless and with Meshcat).
SPLIT_KS = (4, 10000)
# Wall seconds a closed-loop run with Meshcat may take before it stops (at the next slice).
MESHCAT_WALL_CAP = 20.0


def _count(text):
    """A goal count, dimension, ...: a whole number, 1 or more."""
    return _whole(text, 1)


def _count_or_zero(text):
    """`--peer-max-goals`, `--blas-threads`: a whole number, 0 or more."""
    return _whole(text, 0)


def _whole(text, least):
    try:
        value = int(text)
    except ValueError:
        value = None
    if value is None or value < least:
        raise argparse.ArgumentTypeError(f"{text!r}: give a whole number, {least} or more")
    return value


def _seconds(text):
    """`--hsr-seconds`, `--min-time`, `--meshcat-wall-cap`: finite and positive."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text!r}: give a positive number of seconds")
    return value


def _folder(text):
    """`--output`: a folder, or a path where one can be made (not under a file)."""
    path = Path(text)
    if not text:
        raise argparse.ArgumentTypeError("the path is empty; give a folder, e.g. outputs/bench")
    if (dangling := dangling_link(path)) is not None:  # its mkdir: a FileExistsError
        raise argparse.ArgumentTypeError(f"{text}: {dangling}")
    blocker = next(parent for parent in (path.absolute(), *path.absolute().parents)
                   if parent.exists())
    if not blocker.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: {blocker} is a file, not a folder")
    return text


def build_parser():
    """The argument parser of `pbp-drake bench` (the CLI reference is generated from it)."""
    parser = argparse.ArgumentParser(prog="pbp-drake bench",
                                     description=pbp_drake_bench.__doc__.split("\n")[0])
    parser.add_argument("--output", type=_folder, default="outputs/bench",
                        help="folder for bench.json and bench_control_rate.png (default: "
                        "outputs/bench)")
    parser.add_argument("--quick", action="store_true",
                        help="a short run: D = 3 only, fewer repeats, 1 s of HSR simulation")
    parser.add_argument("--goals", type=_count, nargs="+", default=list(KS),
                        help=f"goal counts K (default: {' '.join(map(str, KS))})")
    parser.add_argument("--dimensions", type=_count, nargs="+", default=None,
                        help="dimensions D (default: 2 3 6; --quick: 3)")
    parser.add_argument("--peer-max-goals", type=_count_or_zero, default=1000,
                        help="largest K for the one-object-per-goal peers (default 1000)")
    parser.add_argument("--hsr-goals", type=_count, nargs="*", default=list(HSR_KS),
                        help="goal counts K of the closed-loop HSR runs (default: "
                        f"{' '.join(map(str, HSR_KS))}; none skips every closed-loop "
                        "measurement: the matrix, the time split and the replays)")
    parser.add_argument("--tasks", nargs="+", choices=TASKS, default=list(TASKS),
                        help="the closed-loop tasks: reach (the HSR reaching task) and "
                        "grasp (the six-DoF grasping task) (default: both)")
    parser.add_argument("--hsr-seconds", type=_seconds, default=None,
                        help="simulated seconds per HSR run (default 5; --quick: 1)")
    parser.add_argument("--no-meshcat", action="store_true",
                        help="skip the closed-loop runs with Meshcat (the matrix's, the time "
                        "split's and the replays)")
    parser.add_argument("--meshcat-wall-cap", type=_seconds, default=MESHCAT_WALL_CAP,
                        help="wall seconds after which a run with Meshcat stops, reporting "
                        f"the simulated seconds it reached (default {MESHCAT_WALL_CAP:g})")
    parser.add_argument("--split-goals", type=_count, nargs="*", default=list(SPLIT_KS),
                        help="K of the reach runs whose per-tick time is split by category "
                        f"under cProfile (default: {' '.join(map(str, SPLIT_KS))}; none to "
                        "skip)")
    parser.add_argument("--no-estimators", action="store_true",
                        help="skip the goal estimators' step at K = 10,000 (and its check)")
    parser.add_argument("--no-driver-rate", action="store_true",
                        help="skip the iiwa's closed loop over LCM at its driver's rate (and "
                        "its checks)")
    parser.add_argument("--blas-threads", type=_count_or_zero, default=1,
                        help="BLAS threads for every backend (default 1): the bench measures "
                        "in a fresh Python process with OPENBLAS_NUM_THREADS, "
                        "OMP_NUM_THREADS, MKL_NUM_THREADS, ... set before NumPy loads "
                        "(0: the library's default, measured in this process)")
    parser.add_argument("--min-time", type=_seconds, default=None,
                        help="seconds of repeats per measurement (default 0.3; --quick 0.08)")
    return parser


def _parse(argv):
    return build_parser().parse_args(argv)


def plan(args):
    """What a run measures. `--quick` keeps every check's case (D = 3; the default goal
    counts, HSR runs and replays) and takes fewer repeats and a shorter HSR simulation
    (the replays keep their 5 s: their check compares sizes)."""
    closed_loop = bool(args.hsr_goals)
    meshcat = closed_loop and not args.no_meshcat
    return {"dimensions": args.dimensions or ([3] if args.quick else list(DS)),
            "goals": list(args.goals), "hsr_goals": list(args.hsr_goals),
            # The six-DoF pose bank (PoseDmpBank), up to K = 10,000 (its check's case).
            "pose_goals": [k for k in args.goals if k <= POSE_MAX_GOALS],
            "min_time": args.min_time or (0.08 if args.quick else 0.3),
            "hsr_seconds": args.hsr_seconds or (1.0 if args.quick else 5.0),
            "tasks": [task for task in TASKS if task in args.tasks],
            "meshcat": meshcat, "meshcat_wall_cap": args.meshcat_wall_cap,
            # (K, with Meshcat) of the split runs: reach, headless and with Meshcat.
            "split": [(k, with_meshcat) for k in (args.split_goals if closed_loop and
                                                  "reach" in args.tasks else ())
                      for with_meshcat in ((False, True) if meshcat else (False,))],
            "replay_goals": list(CHECKED_REPLAY_GOALS) if meshcat else [],
            "estimators": not args.no_estimators,
            # The arm over LCM at its driver's rate, with the closed loop's runs.
            "driver_rate": closed_loop and not args.no_driver_rate,
            "replay_seconds": REPLAY_SECONDS}


def main(argv=None):
    """Runs the bench; returns its exit code: 1 when a check fails, else 0."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = _parse(argv)
    if args.blas_threads > 0 and not in_measuring_process():
        # NumPy is loaded in this process already (pbp_drake.cli and this module import
        # it), too late for the thread variables: measure in a fresh process pinned from
        # its start (pbp_drake_bench.pinning).
        return measure_in_fresh_process(argv, args.blas_threads)
    return _measure(args)


def _measure(args):
    output = Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    settings = plan(args)
    dimensions, min_time = settings["dimensions"], settings["min_time"]
    hsr_seconds = settings["hsr_seconds"]
    blas = blas_threads(args.blas_threads)
    installed = {name for name, module in [("pydmps", "pydmps"),
                                           ("movement_primitives", "movement_primitives.dmp")]
                 if available(module)}
    have_pydmps, have_mp = "pydmps" in installed, "movement_primitives" in installed
    print(f"pbp-drake bench: {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} CPUs, Python {platform.python_version()}, NumPy "
          f"{np.__version__}; {blas['note']}")
    for name in PEERS:
        if name not in installed:
            print(f"note: {name} is not installed (pip install -e '.[bench]'); its columns "
                  "stay empty and the checks against it are skipped")

    print("Measuring memory bandwidth ...", flush=True)
    bandwidth = memory_bandwidth()
    print(f"  read {bandwidth['read_gb_per_s']:.1f} GB/s, copy "
          f"{bandwidth['copy_gb_per_s']:.1f} GB/s ({bandwidth['array_megabytes']} MB array); "
          f"read {bandwidth['cache_read_gb_per_s']:.1f} GB/s from a "
          f"{bandwidth['cache_array_megabytes']} MB array (cache)")

    rows = []
    # Measured in increasing K, every D and then the pose bank at each: measured after the
    # banks of K = 100,000 had come and gone (hundreds of MB allocated and freed), the
    # pose bank of K = 10,000 ran 1.2 to 1.5 times slower in three runs of four (the
    # process's later arrays read slower; fewer huge pages, we suspect), a history no
    # user's process has. The table lists the rows by D as before.
    for goal_count in sorted(settings["goals"]):
        for dimension in dimensions:
            for distinct in (True, False):
                rows.append(_measure_row(dimension, goal_count, distinct, min_time,
                                         args.peer_max_goals, have_pydmps, have_mp,
                                         bandwidth))
                _print_progress(rows[-1])
        if goal_count not in settings["pose_goals"]:
            continue
        for distinct in (True, False):
            row = measure_pose_row(goal_count, distinct, min_time, bandwidth)
            # Against the 3-D position bank of the same run (the machine may be loaded).
            position = [r for r in rows if (r["D"], r["K"], r["weights"], r.get("pose")) ==
                        (3, goal_count, row["weights"], None)]
            row["leaf_vs_position_3d"] = (ratio(row["leaf_us"], position[0]["leaf_us"])
                                          if position else None)
            rows.append(row)
            _print_progress(rows[-1])
    rows.sort(key=lambda row: (bool(row.get("pose")), row["D"], row["K"]))

    closed_loop = closed_loop_runs(settings["hsr_goals"], hsr_seconds, CHECKED_HSR_GOALS,
                                   meshcat=settings["meshcat"], tasks=settings["tasks"],
                                   wall_cap=settings["meshcat_wall_cap"], progress=_progress)
    split = []
    for goal_count, with_meshcat in settings["split"]:
        _progress(f"Time split (cProfile): reach, K = {goal_count}, "
                 + ("Meshcat with a client ..." if with_meshcat else "headless ..."))
        split.append(split_run(goal_count, hsr_seconds, with_meshcat,
                               settings["meshcat_wall_cap"]))
    replay = (replay_sizes(settings["replay_goals"], settings["replay_seconds"], _progress)
              if settings["replay_goals"] else None)

    estimators = (estimator_steps(min_time, progress=_progress) if settings["estimators"]
                  else None)
    driver_rate = (driver_rate_run(hsr_seconds, progress=_progress)
                   if settings["driver_rate"] else None)

    report = {
        "machine": {"processor": platform.processor() or platform.machine(),
                    "cpus": os.cpu_count(), "python": platform.python_version(),
                    "numpy": np.__version__, "blas": blas,
                    "load_average": os.getloadavg() if hasattr(os, "getloadavg") else None},
        "settings": {"basis_count": BASIS, "dt": DT, "min_time_s": min_time,
                     "quick": args.quick, "hsr_seconds": hsr_seconds,
                     "tasks": settings["tasks"],
                     "meshcat_wall_cap_s": settings["meshcat_wall_cap"]},
        "memory_bandwidth": bandwidth,
        "steps": rows,
        "closed_loop": closed_loop,
        "time_split": split,
        "replay": replay,
        "estimators": estimators,
        "driver_rate": driver_rate,
    }
    report["checks"] = evaluate(rows, closed_loop, installed, blas, replay, estimators,
                                driver_rate)
    text = format_report(report)
    print(text)
    (output / "bench.json").write_text(json.dumps(report, indent=2))
    (output / "bench.txt").write_text(text + "\n")
    figures = [plot_control_rate(rows, output / "bench_control_rate.png")]
    if closed_loop:
        figures.append(plot_scaling(closed_loop, output / "bench_scaling.png"))
    print(f"Wrote {output / 'bench.json'}, {output / 'bench.txt'}, "
          + " and ".join(str(figure) for figure in figures if figure))
    return exit_code(report["checks"])


def _measure_row(dimension, goal_count, distinct, min_time, peer_max_goals, have_pydmps,
                 have_mp, bandwidth):
    case = make_case(dimension, goal_count, distinct)
    bank = make_bank(case)
    row = {"D": dimension, "K": goal_count, "weights": "distinct" if distinct else "shared"}
    math_median, math_min, repeats = timed(bank_math_step(bank, case), min_time)
    row.update(bank_math_us=microseconds(math_median), bank_math_min_us=microseconds(math_min),
               bank_math_repeats=repeats)

    # Inside the LeafSystem: several periods per timed call, so that Simulator.AdvanceTo's
    # own call cost is spread; the bank and the null system alike. The bank is immutable:
    # every Simulator steps the same one, each in its own Context.
    periods = 10 if goal_count <= 10000 else 2
    for label, leaf_bank in [("leaf", bank), ("drake_overhead", None)]:
        simulator = leaf_simulator(case, leaf_bank)
        median, minimum, _ = timed(leaf_step(simulator, periods), min_time, warmup=1)
        row[f"{label}_us"] = microseconds(median / periods)
        row[f"{label}_min_us"] = microseconds(minimum / periods)
        del simulator
    # What a consumer of all K references (not the builder's blender) would add.
    simulator = leaf_simulator(case, bank, read="references")
    row["leaf_all_references_us"] = microseconds(
        timed(leaf_step(simulator, periods), min_time, warmup=1)[0] / periods)
    del simulator
    if ((dimension, goal_count, row["weights"]), False) in MOTION_ROWS:
        row.update(motion_fields(leaf_simulator(case, bank), bank.duration, periods))
    del bank

    weight_bytes = (case.weights.nbytes if distinct else case.shared_weights.nbytes)
    row["weight_bytes"] = weight_bytes
    row["bandwidth_bound_us"] = microseconds(weight_bytes / (bandwidth["read_gb_per_s"] * 1e9))
    row["cache_bandwidth_bound_us"] = microseconds(
        weight_bytes / (bandwidth["cache_read_gb_per_s"] * 1e9))

    peer_time = max(min_time / 3, 0.02)
    for label, present, factory, limit in [
            ("pydmps_per_goal", have_pydmps, pydmps_step, peer_max_goals),
            ("mp_per_goal", have_mp, movement_primitives_step, peer_max_goals),
            ("mp_stacked", have_mp, movement_primitives_stacked_step, 10**9)]:
        row[f"{label}_us"] = None
        if present and goal_count <= limit and not (
                label == "mp_stacked" and goal_count * dimension > 600000):
            step = factory(case)
            median, _, _ = timed(step, peer_time, max_repeats=500, min_repeats=3, warmup=1)
            row[f"{label}_us"] = microseconds(median)
            del step
    per_goal = [row[k] for k in ("pydmps_per_goal_us", "mp_per_goal_us") if row[k]]
    row["speedup_vs_per_goal"] = ratio(min(per_goal) if per_goal else None,
                                       row["bank_math_us"])
    row["speedup_vs_stacked"] = ratio(row["mp_stacked_us"], row["bank_math_us"])
    row["control_rate_hz"] = 1e6 / row["leaf_us"]
    return row


def _progress(text):
    print(text, flush=True)


def _print_progress(row):
    kind = " pose" if row.get("pose") else ""
    print(f"  D={row['D']}{kind} K={row['K']:>6} {row['weights']:>8}: math "
          f"{row['bank_math_us']:.1f} us, in LeafSystem {row['leaf_us']:.1f} us "
          f"(Drake {row['drake_overhead_us']:.1f} us)", flush=True)
