"""Closed loop: simulated seconds per wall second of the HSR tasks with K goals (`scenes`:
reaching and grasping), headless and with Meshcat drawing to a client that reads
everything sent (`ws_reader`).

A run's speed is its simulated seconds over the wall seconds of `Simulator.AdvanceTo`
after `Initialize` (building and initializing are reported apart). With Meshcat, the
timed span ends with `Meshcat.Flush()` (what Meshcat still had to send counts), the reader
counts the bytes and messages sent between two marks around it, and a run whose drawing is
slow stops at `wall_cap` seconds of wall time (advancing in slices of `SLICE` simulated
seconds), reporting the simulated seconds it reached."""

import time

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator

from pbp_drake_bench.scenes import GRASP, REACH, TASKS, resolved_scene
from pbp_drake_bench.time_split import profiled_advance, split_row
from pbp_drake_bench.ws_reader import MeshcatReader, send_mark
from pbp_drake.builder import build_diagram

HSR_KS = (4, 100, 1000, 10000)
# Headless runs per case, of which the bench reports the median (one with Meshcat).
HSR_REPEATS = 5
# The station's dynamic robot, measured beside the shipped scenario's (kinematic) one.
DYNAMIC = "dynamic"
# A run with Meshcat advances in slices of this many simulated seconds, so that it can stop
# at its wall-time cap.
SLICE = 0.1

__all__ = ["DYNAMIC", "GRASP", "HSR_KS", "HSR_REPEATS", "REACH", "TASKS", "closed_loop_runs",
           "hsr_speed", "meshcat_speed", "new_meshcat", "split_run"]


def new_meshcat():
    """A Meshcat on localhost at a free port (never a fixed one)."""
    return Meshcat(MeshcatParams(host="localhost", port=0))


def build_simulator(task, goal_count, meshcat=None, motion=None, start_recording=False):
    """`(simulator, resolved scenario, seconds to build and initialize)` of a fresh diagram
    of the bench's scene (`scenes.resolved_scene`, resolved once per process); with
    `start_recording`, Meshcat records from after the build on (as `pbp-drake run
    --record`)."""
    resolved = resolved_scene(task, goal_count, motion)
    began = time.perf_counter()
    diagram = build_diagram(resolved, meshcat)
    if start_recording:
        meshcat.StartRecording(frames_per_second=30.0)
    simulator = Simulator(diagram)
    simulator.set_target_realtime_rate(0.0)
    simulator.Initialize()
    return simulator, resolved, time.perf_counter() - began


def advance(simulator, seconds, wall_cap=None, meshcat=None):
    """Advances `seconds` of simulated time, or in slices until `wall_cap` wall seconds have
    gone; then flushes `meshcat`: `(simulated seconds advanced, wall seconds)`. The task
    monitor may end the simulation earlier (at success)."""
    context = simulator.get_context()
    start = context.get_time()
    end = start + seconds
    began = time.perf_counter()
    if wall_cap is None:
        simulator.AdvanceTo(end)
    else:
        while context.get_time() < end - 1e-9 and time.perf_counter() - began < wall_cap:
            before = context.get_time()
            simulator.AdvanceTo(min(end, before + SLICE))
            if context.get_time() < min(end, before + SLICE) - 1e-9:
                break  # terminated
    if meshcat is not None:
        meshcat.Flush()
    return context.get_time() - start, time.perf_counter() - began


def _result(task, goal_count, resolved, simulated, wall, built, meshcat, shipped=True):
    return {"task": task, "goals": goal_count, "motion": resolved.scenario.robot.station.motion,
            "simulated_s": simulated, "wall_s": wall, "realtime_factor": simulated / wall,
            "build_s": built, "control_period_s": resolved.scenario.control_period,
            "meshcat": meshcat, "shipped_robot": shipped}


def _timed(simulator, seconds, wall_cap, meshcat, profile):
    """`advance`'s `(simulated, wall)` and, with `profile`, the time split (else None)."""
    if not profile:
        return (*advance(simulator, seconds, wall_cap, meshcat), None)
    (simulated, wall), split, total = profiled_advance(
        lambda: advance(simulator, seconds, wall_cap, meshcat))
    return simulated, wall, (split, total)


def hsr_speed(goal_count, simulated_seconds, task=REACH, motion=None, profile=False):
    """One headless run's speed (a dict: "realtime_factor", "simulated_s", "wall_s",
    "build_s", ...), on the scenario file's robot or with `motion` the other one. With
    `profile`, under cProfile, with its "split" (`time_split`)."""
    simulator, resolved, built = build_simulator(task, goal_count, None, motion)
    simulated, wall, split = _timed(simulator, simulated_seconds, None, None, profile)
    result = _result(task, goal_count, resolved, simulated, wall, built, False, motion is None)
    if split is not None:
        result["split"] = split
    return result


def split_run(goal_count, simulated_seconds, meshcat=False, wall_cap=None):
    """The per-tick time split of one reach run with K = `goal_count` (`time_split`),
    headless or with Meshcat and a client: the run's result with "split", a row of
    `time_split.split_row` (ms per control tick per category and the shares)."""
    run = (meshcat_speed(goal_count, simulated_seconds, REACH, wall_cap, profile=True)
           if meshcat else hsr_speed(goal_count, simulated_seconds, REACH, profile=True))
    seconds, total = run.pop("split")
    run["split"] = split_row(seconds, total, run["simulated_s"] / run["control_period_s"])
    return run


def meshcat_speed(goal_count, simulated_seconds, task=REACH, wall_cap=None, profile=False):
    """One run's speed with Meshcat drawing to a websocket client in another process that
    reads everything (connected before the build, waited for on Meshcat's count of
    connections); adds the bytes and messages it read per simulated second of the timed
    span, and "capped" when the wall cap cut it short. With `profile`, the timed span runs
    under cProfile and the result has its "split" (`time_split`)."""
    meshcat = new_meshcat()
    reader = MeshcatReader(meshcat)
    try:
        simulator, resolved, built = build_simulator(task, goal_count, meshcat)
        send_mark(meshcat, "start")
        simulated, wall, split = _timed(simulator, simulated_seconds, wall_cap, meshcat,
                                        profile)
        send_mark(meshcat, "end")
    finally:
        totals = reader.finish()
    result = _result(task, goal_count, resolved, simulated, wall, built, True)
    if split is not None:
        result["split"] = split
    sent, messages = reader.span("start", "end")
    result.update(bytes_per_s=sent / simulated, messages_per_s=messages / simulated,
                  client_bytes_total=totals["bytes"], client=True,
                  capped=simulated < simulated_seconds - 1e-9, wall_cap_s=wall_cap)
    return result


def closed_loop_runs(goal_counts, simulated_seconds, dynamic_goals=None, meshcat=False,
                     tasks=TASKS, wall_cap=None, progress=print):
    """The bench's closed-loop matrix, one result per (task, K, headless or Meshcat):
    headless on the shipped robot, and on the dynamic robot (reach) at K = `dynamic_goals`,
    each the median of `HSR_REPEATS` runs taken in rounds over all of them (so that a
    slowdown of a shared machine, which lasts seconds, spreads over every case rather than
    falling on one case's runs; every run's factor is kept in `realtime_factors`); then,
    with `meshcat`, one run each with Meshcat and a client (`meshcat_speed`, at most
    `wall_cap` wall seconds). Sorted by task, K, headless first."""
    headless = [(task, k, None) for task in tasks for k in goal_counts]
    if REACH in tasks and dynamic_goals in goal_counts:
        headless.append((REACH, dynamic_goals, DYNAMIC))
    for task, k, motion in headless:  # resolved before timing anything (once per process)
        began = time.perf_counter()
        resolved_scene(task, k, motion)
        if time.perf_counter() - began > 1.0:
            progress(f"  (resolving the {task} scene with K = {k:,} took "
                     f"{time.perf_counter() - began:.1f} s)")
    samples = {case: [] for case in headless}
    for round_ in range(HSR_REPEATS):
        progress(f"HSR closed loop, round {round_ + 1} of {HSR_REPEATS}, headless: "
                 + "; ".join(f"{task} K = {k}{f' ({motion} robot)' if motion else ''}"
                             for task, k, motion in headless) + " ...")
        for task, k, motion in headless:
            samples[(task, k, motion)].append(hsr_speed(k, simulated_seconds, task, motion))
    results = []
    for runs in samples.values():
        walls = [run["wall_s"] / run["simulated_s"] for run in runs]
        result = dict(runs[int(np.argsort(walls)[len(walls) // 2])])  # the median run
        result["realtime_factors"] = [run["realtime_factor"] for run in runs]
        results.append(result)
    for task in tasks if meshcat else ():
        for k in goal_counts:
            progress(f"HSR {task}, K = {k}, Meshcat with a client reading everything ...")
            run = meshcat_speed(k, simulated_seconds, task, wall_cap)
            if run["capped"]:
                progress(f"  stopped at its wall-time cap ({wall_cap:g} s): "
                         f"{run['simulated_s']:.2f} simulated s")
            results.append(run)
    order = {task: index for index, task in enumerate(TASKS)}
    return sorted(results, key=lambda run: (order[run["task"]], run["goals"], run["meshcat"],
                                            not run["shipped_robot"]))
