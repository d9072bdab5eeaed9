"""Closed loop: simulated seconds per wall second of the HSR reaching task with K goals."""

import dataclasses
import math
import time
from pathlib import Path

import numpy as np
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator

from pbp_drake.builder import build_diagram
from pbp_drake.scenarios import load_scenario_file

HSR_KS = (4, 100, 1000)
# Headless runs per K, of which the bench reports the median (one with Meshcat, slower).
HSR_REPEATS = 5
# The station's dynamic robot, measured beside the shipped scenario's (kinematic) one.
DYNAMIC = "dynamic"
# The repository's diagrams/ folder (this file is pbp_drake/bench/closed_loop.py).
DIAGRAMS = Path(__file__).resolve().parents[2] / "diagrams"


def hsr_scenario(goal_count, seed=0):
    """The HSR reaching scenario of `diagrams/hsr_reach.yaml` with `goal_count` objects on a
    jittered grid in the paper's region, the target the first of them, no switches."""
    scenario = load_scenario_file(DIAGRAMS / "hsr_reach.yaml").scenario
    task = scenario.task
    (x0, x1), (y0, y1) = task.x_range, task.y_range
    rows = max(1, int(math.ceil(math.sqrt(goal_count * (x1 - x0) / (y1 - y0)))))
    columns = int(math.ceil(goal_count / rows))
    dx, dy = (x1 - x0) / rows, (y1 - y0) / columns
    rng = np.random.default_rng(seed)
    cells = rng.permutation(rows * columns)[:goal_count]
    jitter = rng.uniform(-0.25, 0.25, (goal_count, 2))
    objects = np.stack([x0 + (cells // columns + 0.5 + jitter[:, 0]) * dx,
                        y0 + (cells % columns + 0.5 + jitter[:, 1]) * dy,
                        np.full(goal_count, task.height)], axis=1)
    task = dataclasses.replace(task, objects=objects.tolist(), targets=[0],
                               switch_schedule=[0.0],
                               min_separation=min(task.min_separation, 0.4 * min(dx, dy)))
    return dataclasses.replace(scenario, task=task)


def with_motion(scenario, motion):
    """`scenario` with its HSR station's `motion` ("dynamic" or "kinematic")."""
    robot = scenario.robot
    station = dataclasses.replace(robot.station, motion=motion)
    return dataclasses.replace(scenario, robot=dataclasses.replace(robot, station=station))


def hsr_speed(goal_count, simulated_seconds, meshcat=None, motion=None):
    """Simulated seconds per wall second of one run of the HSR task (and the build time),
    on the scenario file's robot, or with `motion` the station's other motion model."""
    scenario = hsr_scenario(goal_count)
    if motion is not None:
        scenario = with_motion(scenario, motion)
    began = time.perf_counter()
    diagram = build_diagram(scenario, meshcat)
    simulator = Simulator(diagram)
    simulator.set_target_realtime_rate(0.0)
    simulator.Initialize()
    built = time.perf_counter() - began
    began = time.perf_counter()
    simulator.AdvanceTo(simulated_seconds)
    wall = time.perf_counter() - began
    return {"goals": goal_count, "motion": scenario.robot.station.motion,
            "simulated_s": simulated_seconds, "wall_s": wall,
            "realtime_factor": simulated_seconds / wall, "build_s": built,
            "control_period_s": scenario.control_period}


def closed_loop_runs(goal_counts, simulated_seconds, dynamic_goals=None, meshcat=False,
                     progress=print):
    """The bench's closed-loop runs, each K's as one result: headless on the shipped
    robot, and on the dynamic robot at K = `dynamic_goals`, each the median of
    `HSR_REPEATS` runs taken in rounds over all of them (so that a slowdown of a
    shared machine, which lasts seconds, spreads over every K rather than falling on one
    K's runs; every run's factor is kept in `realtime_factors`); then, with `meshcat`,
    one run each with Meshcat publishing. In K order, headless first."""
    headless = [(k, None) for k in goal_counts] + (
        [(dynamic_goals, DYNAMIC)] if dynamic_goals in goal_counts else [])
    samples = {config: [] for config in headless}
    for round_ in range(HSR_REPEATS):
        progress(f"HSR reaching, round {round_ + 1} of {HSR_REPEATS}: K = "
                 + ", ".join(f"{k}{f' ({motion} robot)' if motion else ''}"
                             for k, motion in headless) + ", headless ...")
        for k, motion in headless:
            samples[(k, motion)].append(hsr_speed(k, simulated_seconds, None, motion))
    results = []
    for (k, motion), runs in samples.items():
        walls = [run["wall_s"] for run in runs]
        result = dict(runs[int(np.argsort(walls)[len(walls) // 2])])  # the median run
        result.update(meshcat=False, shipped_robot=motion is None,
                      realtime_factors=[run["realtime_factor"] for run in runs])
        results.append(result)
    for k in goal_counts if meshcat else ():
        progress(f"HSR reaching, K = {k}, Meshcat ...")
        server = Meshcat(MeshcatParams(host="localhost"))
        results.append(dict(hsr_speed(k, simulated_seconds, server), meshcat=True,
                            shipped_robot=True))
        del server
    return sorted(results, key=lambda run: (run["goals"], run["meshcat"]))
