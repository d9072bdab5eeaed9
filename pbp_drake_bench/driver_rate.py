"""The arm at its driver's rate: the iiwa reaching task (`diagrams/iiwa_reach.yaml`, the
virtual participant under PBP-Alt) with K goals on the task's grid, its station over LCM to
the driver simulator in the same process (`run --hardware --driver-sim`: memq://, the iiwa's
status and commands every 5 ms), headless. A run's speed is its simulated seconds over the
wall seconds of the control ticks, each advanced and timed on its own; a stall at the
driver's rate shows as the ticks' 99th percentile far above their median."""

import dataclasses
import time

import numpy as np
from pydrake.systems.analysis import Simulator

from pbp_drake.builder import build_diagram
from pbp_drake.robots.arm_station_config import DRIVERS
from pbp_drake.scenarios import load_scenario_file, resolve
from pbp_drake_bench.checks import DRIVER_GOALS
from pbp_drake_bench.scenes import DIAGRAMS

IIWA_REACH = DIAGRAMS / "iiwa_reach.yaml"


def driver_rate_run(simulated_seconds, goal_count=DRIVER_GOALS, progress=None):
    """{"goals", "driver", "driver_period_s", "control_period_s", "simulated_s", "wall_s",
    "realtime_factor", "ticks", "tick_median_ms", "tick_p99_ms", "p99_over_median"}; the
    run ends at `simulated_seconds` or at the task's success."""
    if progress:
        progress(f"The iiwa over LCM at its driver's rate, K = {goal_count} ...")
    scenario = load_scenario_file(IIWA_REACH).scenario
    robot = scenario.robot
    scenario = dataclasses.replace(
        scenario, task=dataclasses.replace(scenario.task, grid_objects=goal_count),
        robot=dataclasses.replace(robot, hardware=dataclasses.replace(
            robot.hardware, connect=True, driver_sim=True)))
    resolved = resolve(scenario)
    simulator = Simulator(build_diagram(resolved))
    simulator.set_target_realtime_rate(0.0)
    simulator.Initialize()
    period = scenario.control_period
    ticks = []
    for tick in range(1, int(round(simulated_seconds / period)) + 1):
        began = time.perf_counter()
        simulator.AdvanceTo(tick * period)
        ticks.append(time.perf_counter() - began)
        if simulator.get_context().get_time() < tick * period - 1e-9:
            break  # the task succeeded (the task monitor's termination)
    simulated = simulator.get_context().get_time()
    wall = float(np.sum(ticks))
    median, p99 = np.median(ticks), np.percentile(ticks, 99)
    driver = robot.hardware.driver
    return {"goals": goal_count, "driver": driver, "driver_period_s": DRIVERS[driver].period,
            "control_period_s": period, "simulated_s": simulated, "wall_s": wall,
            "realtime_factor": simulated / wall, "ticks": len(ticks),
            "tick_median_ms": median * 1e3, "tick_p99_ms": p99 * 1e3,
            "p99_over_median": p99 / median}
