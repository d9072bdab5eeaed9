"""How long one step of an `OrientationDmpBank` takes: a helper, not a test.

`python -m pbp_drake_bench.orientation_step [K ...]` prints, for K DMPs stepped from one
measured orientation with equal phases (the normal case), the median wall time and the mean
CPU time of one in-place step (`advance_into` with one workspace), for straight DMPs (one
shared shape) and for distinct weights per goal. Run it with OPENBLAS_NUM_THREADS=1 (and
the other thread variables) as the bench measures; it prints what the BLAS library reports.
On a machine shared with other work the CPU time is the steadier. `pbp-drake bench` times
the bank inside the six-DoF LeafSystem (`pbp_drake_bench.pose_cases`).
"""

import sys
import time

import numpy as np

from pbp_drake_bench.pinning import blas_threads
from pbp_drake.core import quaternion
from pbp_drake.core.dmp.orientation_bank import OrientationDmpBank
from pbp_drake.core.dmp.settings import DmpSettings


def random_unit_quaternions(count, rng):
    """`(count, 4)` rows uniformly distributed over the rotations."""
    rows = rng.normal(size=(count, 4))
    return rows / np.linalg.norm(rows, axis=1, keepdims=True)


def step_seconds(goal_count, distinct_weights=False, repeats=100, seed=0):
    """(median wall time, mean CPU time) in seconds of one `advance_into` of `goal_count`
    DMPs, the robot following DMP 0 with a lag (the slerp is not timed)."""
    rng = np.random.default_rng(seed)
    settings = DmpSettings()
    start = random_unit_quaternions(1, rng)[0]
    bank = OrientationDmpBank.straight(start, goal_count, 1.5, settings)
    if distinct_weights:
        weights = np.asarray(bank._weights)[None] * rng.uniform(0.5, 1.5, (goal_count, 1, 3))
        bank = OrientationDmpBank(weights, start, 1.5, settings)
    goals = bank.goals_matrix(random_unit_quaternions(goal_count, rng))
    phase, orientations, velocity = bank.initial_state()
    workspace = bank.make_workspace()
    robot = start[:, np.newaxis]
    wall, cpu = [], 0.0
    for repeat in range(repeats + 5):
        began, began_cpu = time.perf_counter(), time.process_time()
        bank.advance_into(phase, robot, velocity, goals, 1 / 30, phase, orientations,
                          velocity, workspace)
        if repeat >= 5:  # after a warm-up
            wall.append(time.perf_counter() - began)
            cpu += time.process_time() - began_cpu
        robot = quaternion.slerp(robot, orientations[:, :1], 0.5)
    return float(np.median(wall)), cpu / repeats


def main(argv):
    counts = [int(value) for value in argv] or [1, 10, 100, 1_000, 10_000]
    print(blas_threads(1)["note"])  # set OPENBLAS_NUM_THREADS=1 before running to pin
    for count in counts:
        (shared, shared_cpu), (distinct, distinct_cpu) = (
            step_seconds(count), step_seconds(count, distinct_weights=True))
        print(f"K = {count:>7,}: shared shape {shared * 1e6:7.0f} µs wall, "
              f"{shared_cpu * 1e6:7.0f} µs CPU; distinct weights {distinct * 1e6:7.0f} µs "
              f"wall, {distinct_cpu * 1e6:7.0f} µs CPU (one step)")


if __name__ == "__main__":
    main(sys.argv[1:])
