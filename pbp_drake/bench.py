"""`pbp-drake bench`: how fast the DMP bank steps, beside the libraries people use today.

Measured in one run on this machine (issue 6):

- this machine's memory bandwidth (a NumPy copy and sum of a large array, and a sum of a
  cache-sized one), the bound it puts on streaming distinct weights;
- the DMP bank's step for K goals and D dimensions (50 basis functions), with distinct
  learned weights per goal and with one demonstration shared by all goals: the bank math
  alone (`DmpBank.advance_into`) and inside its Drake `LeafSystem` (a Simulator stepping it
  at 1 kHz from constant inputs), with Drake's event overhead measured separately (the same
  LeafSystem ports and state, an update that does nothing);
- the same step with `pydmps` and `movement_primitives`, one object per goal as their APIs
  intend, re-integrated from the robot's position as PBP does, and `movement_primitives`
  with all goals stacked into one K*D-dimensional DMP;
- closed loop: simulated seconds per wall second of the HSR reaching task with K goals,
  headless and with Meshcat publishing;
- the control rate reached versus K, as a figure (`bench_control_rate.png`).

Writes `bench.json` and the figure into `--output` (default `outputs/bench`). Timings are
medians over repeats (the repeat count adapts to K); BLAS is limited to `--blas-threads`
(default 1, through threadpoolctl when installed) for every backend alike.
"""

import argparse
import dataclasses
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

KS = (1, 10, 100, 1000, 10000, 100000)
DS = (2, 3, 6)
BASIS = 50
DT = 0.001  # a 1 kHz control loop
HSR_KS = (4, 100, 1000)


# --------------------------------------------------------------------------------------------
# Timing helpers
# --------------------------------------------------------------------------------------------

def _timed(step, min_time, max_repeats=5000, min_repeats=3, warmup=2):
    """Median and minimum seconds of `step()`, repeated for at least `min_time` seconds."""
    for _ in range(warmup):
        step()
    samples = []
    began = time.perf_counter()
    while len(samples) < max_repeats and (
            len(samples) < min_repeats or time.perf_counter() - began < min_time):
        start = time.perf_counter()
        step()
        samples.append(time.perf_counter() - start)
    samples = np.array(samples)
    return float(np.median(samples)), float(samples.min()), len(samples)


def _limit_blas(threads):
    """Limits BLAS threads for the whole run; returns a note for the report."""
    if threads <= 0:
        return "BLAS threads: library default"
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return (f"BLAS threads: default (threadpoolctl missing; set OPENBLAS_NUM_THREADS="
                f"{threads} before starting Python to limit them)")
    _limit_blas.handle = threadpool_limits(limits=threads, user_api="blas")
    return f"BLAS threads: {threads} (threadpoolctl)"


# --------------------------------------------------------------------------------------------
# Memory bandwidth
# --------------------------------------------------------------------------------------------

def memory_bandwidth(megabytes=400, cache_megabytes=12, repeats=5):
    """GB/s of a NumPy sum (read) and copy (read + write) of a large array, and of a sum of
    an array the size of the weights of K = 10,000, D = 3 (which may stay in cache)."""
    n = int(megabytes * 1e6 / 8)
    a = np.ones(n)
    b = np.empty(n)
    a.sum()
    np.copyto(b, a)
    sum_time = min(_clock(a.sum) for _ in range(repeats))
    copy_time = min(_clock(lambda: np.copyto(b, a)) for _ in range(repeats))
    del a, b
    small = np.ones(int(cache_megabytes * 1e6 / 8))
    cache_time = _timed(small.sum, 0.2, max_repeats=200)[1]
    return {
        "array_megabytes": megabytes,
        "read_gb_per_s": megabytes * 1e6 / sum_time / 1e9,
        "copy_gb_per_s": 2 * megabytes * 1e6 / copy_time / 1e9,
        "cache_array_megabytes": cache_megabytes,
        "cache_read_gb_per_s": cache_megabytes * 1e6 / cache_time / 1e9,
    }


def _clock(function):
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


# --------------------------------------------------------------------------------------------
# The cases: one bank of K DMPs in D dimensions
# --------------------------------------------------------------------------------------------

@dataclasses.dataclass
class Case:
    dimension: int
    goal_count: int
    start: np.ndarray  # (D,)
    goals: np.ndarray  # (K, D)
    robot: np.ndarray  # (D,) the robot's position every step re-integrates from
    weights: np.ndarray | None  # (K, N, D) distinct, or None
    shared_weights: np.ndarray  # (N, D) of one demonstration


def make_case(dimension, goal_count, distinct, seed=0):
    from pbp_drake.core.dmp import DmpSettings, fit_weights, minimum_jerk

    rng = np.random.default_rng(seed + 1000 * dimension + goal_count)
    start = np.zeros(dimension)
    goals = rng.uniform(0.5, 1.5, (goal_count, dimension))
    robot = rng.uniform(-0.05, 0.05, dimension)
    times, path = minimum_jerk(start, np.ones(dimension), 1.0)
    path = path + 0.2 * np.sin(np.pi * times / times[-1])[:, None] * np.arange(dimension)
    shared, _ = fit_weights(times, path, DmpSettings(basis_count=BASIS))
    weights = None
    if distinct:
        # Learned-looking weights, different for every goal (the bank does not care how).
        weights = shared[None] * rng.uniform(0.5, 1.5, (goal_count, 1, dimension))
    return Case(dimension, goal_count, start, goals, robot, weights, shared)


def make_bank(case):
    from pbp_drake.core.dmp import DmpBank, DmpSettings

    settings = DmpSettings(basis_count=BASIS)
    if case.weights is not None:
        return DmpBank(case.weights, case.start, 1.0, settings)
    return DmpBank(case.shared_weights, case.start, 1.0, settings, goal_count=case.goal_count)


def bank_math_step(bank, case):
    """One step of the bank from the robot's position, in place, goals validated each step."""
    phase, positions, scaled_velocity = bank.initial_state()
    robot = case.robot[:, None]
    goals = case.goals.reshape(-1)
    workspace = bank.make_workspace()

    def step():
        bank.advance_into(phase, robot, scaled_velocity, bank.goals_matrix(goals), DT,
                          phase, positions, scaled_velocity, workspace)
    return step


class _NullBank:
    """Factory of a LeafSystem with the DmpBank system's ports and state and an update that
    does nothing: Drake's own cost of one periodic discrete update."""

    @staticmethod
    def build(goal_count, dimension):
        from pydrake.systems.framework import LeafSystem

        from pbp_drake.systems.dmp_bank import DmpBank as DmpBankSystem

        class NullBank(LeafSystem):
            def __init__(self):
                super().__init__()
                k, d = goal_count, dimension
                self.DeclareVectorInputPort("robot_state", 2 * d)
                self.DeclareVectorInputPort("goals", k * d)
                self.DeclareVectorInputPort("operator_active", 1)
                self.DeclareDiscreteState(np.zeros(DmpBankSystem.state_size(k, d)))
                self.DeclarePeriodicDiscreteUpdateEvent(DT, 0.0, self._update)

            def _update(self, context, discrete_state):
                pass

        return NullBank()


def leaf_simulator(case, bank=None):
    """A Simulator of the bank's LeafSystem (or the null one) fed by constant sources."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from pbp_drake.systems.dmp_bank import DmpBank as DmpBankSystem
    from pbp_drake.systems.goals_source import GoalsSource

    builder = DiagramBuilder()
    d = case.dimension
    if bank is None:
        system = builder.AddSystem(_NullBank.build(case.goal_count, d))
    else:
        system = builder.AddSystem(DmpBankSystem(bank, DT))
    robot = builder.AddSystem(ConstantVectorSource(np.concatenate([case.robot, np.zeros(d)])))
    # Our goals source, as the builder uses: Drake's ConstantVectorSource would make the
    # bank re-read its goals at every update.
    goals = builder.AddSystem(GoalsSource(case.goals))
    builder.Connect(robot.get_output_port(), system.get_input_port(0))
    builder.Connect(goals.get_output_port(), system.get_input_port(1))
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    return simulator


def leaf_step(simulator, steps):
    """Advances `steps` control periods; the timed unit is one period."""
    def step():
        context = simulator.get_context()
        simulator.AdvanceTo(context.get_time() + steps * DT)
    return step


# --------------------------------------------------------------------------------------------
# Peers
# --------------------------------------------------------------------------------------------

def _peer_weights(case, k):
    return case.shared_weights if case.weights is None else case.weights[k]


def pydmps_step(case):
    """pydmps, one `DMPs_discrete` per goal, each re-integrated from the robot's position
    (its `.y` is writable) and stepped once."""
    import pydmps

    from pbp_drake.core.dmp import DmpSettings

    centres, widths = DmpSettings(basis_count=BASIS).basis()
    dmps = []
    for k in range(case.goal_count):
        dmp = pydmps.DMPs_discrete(n_dmps=case.dimension, n_bfs=BASIS, dt=DT,
                                   y0=case.start.copy(), goal=case.goals[k].copy(),
                                   w=_peer_weights(case, k).T.copy(),
                                   ax=DmpSettings().alpha_x)
        dmp.c, dmp.h = centres.copy(), widths.copy()
        dmps.append(dmp)
    robot = case.robot

    def step():
        for dmp in dmps:
            dmp.y[:] = robot
            dmp.step()
    return step


def movement_primitives_step(case):
    """movement_primitives, one `DMP` per goal; `step` ignores the state passed in, so the
    robot's position is written into its `current_y` by hand, as a PBP user must."""
    from movement_primitives.dmp import DMP

    dmps = []
    zeros = np.zeros(case.dimension)
    for k in range(case.goal_count):
        dmp = DMP(n_dims=case.dimension, execution_time=1.0, dt=DT,
                  n_weights_per_dim=BASIS, int_dt=DT)
        dmp.configure(start_y=case.start.copy(), goal_y=case.goals[k].copy())
        dmp.set_weights(_peer_weights(case, k).T.reshape(-1).copy())
        dmp.step(case.start.copy(), zeros)
        dmps.append(dmp)
    robot = case.robot

    def step():
        for dmp in dmps:
            dmp.current_y[:] = robot
            dmp.step(robot, zeros)
    return step


def movement_primitives_stacked_step(case):
    """movement_primitives with every goal stacked into one K*D-dimensional DMP: the fastest
    trick its user has (distinct weights per goal come for free; shared ones are tiled)."""
    from movement_primitives.dmp import DMP

    k, d = case.goal_count, case.dimension
    dmp = DMP(n_dims=k * d, execution_time=1.0, dt=DT, n_weights_per_dim=BASIS, int_dt=DT)
    dmp.configure(start_y=np.tile(case.start, k), goal_y=case.goals.reshape(-1).copy())
    if case.weights is None:
        weights = np.tile(case.shared_weights.T, (k, 1))
    else:
        weights = case.weights.transpose(0, 2, 1).reshape(k * d, BASIS)
    dmp.set_weights(weights.reshape(-1).copy())
    robot = np.tile(case.robot, k)
    zeros = np.zeros(k * d)
    dmp.step(robot, zeros)

    def step():
        dmp.current_y[:] = robot
        dmp.step(robot, zeros)
    return step


def _available(module):
    try:
        __import__(module)
        return True
    except ImportError:
        return False


# --------------------------------------------------------------------------------------------
# Closed loop: the HSR reaching task with many goals
# --------------------------------------------------------------------------------------------

def hsr_scenario(goal_count, seed=0):
    """The HSR reaching scenario of `diagrams/hsr_reach.yaml` with `goal_count` objects on a
    jittered grid in the paper's region, the target the first of them, no switches."""
    from pbp_drake.scenarios import load_scenario_file

    path = Path(__file__).resolve().parents[1] / "diagrams" / "hsr_reach.yaml"
    scenario = load_scenario_file(path).scenario
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


def hsr_speed(goal_count, simulated_seconds, meshcat=None):
    """Simulated seconds per wall second of the HSR task (and the build time)."""
    from pydrake.systems.analysis import Simulator

    from pbp_drake.builder import build_diagram

    scenario = hsr_scenario(goal_count)
    began = time.perf_counter()
    diagram = build_diagram(scenario, meshcat)
    simulator = Simulator(diagram)
    simulator.set_target_realtime_rate(0.0)
    simulator.Initialize()
    built = time.perf_counter() - began
    began = time.perf_counter()
    simulator.AdvanceTo(simulated_seconds)
    wall = time.perf_counter() - began
    return {"goals": goal_count, "simulated_s": simulated_seconds, "wall_s": wall,
            "realtime_factor": simulated_seconds / wall, "build_s": built,
            "control_period_s": scenario.control_period}


# --------------------------------------------------------------------------------------------
# The run
# --------------------------------------------------------------------------------------------

def _parse(argv):
    parser = argparse.ArgumentParser(prog="pbp-drake bench", description=__doc__.split("\n")[0])
    parser.add_argument("--output", default="outputs/bench", help="folder for bench.json "
                        "and bench_control_rate.png (default: outputs/bench)")
    parser.add_argument("--quick", action="store_true",
                        help="a short run: D = 3 only, fewer repeats, 1 s of HSR simulation")
    parser.add_argument("--goals", type=int, nargs="+", default=list(KS),
                        help=f"goal counts K (default: {' '.join(map(str, KS))})")
    parser.add_argument("--dimensions", type=int, nargs="+", default=None,
                        help="dimensions D (default: 2 3 6; --quick: 3)")
    parser.add_argument("--peer-max-goals", type=int, default=1000,
                        help="largest K for the one-object-per-goal peers (default 1000)")
    parser.add_argument("--hsr-goals", type=int, nargs="*", default=list(HSR_KS),
                        help="goal counts of the closed-loop HSR runs (none to skip)")
    parser.add_argument("--hsr-seconds", type=float, default=None,
                        help="simulated seconds per HSR run (default 5; --quick: 1)")
    parser.add_argument("--no-meshcat", action="store_true",
                        help="skip the closed-loop runs with Meshcat publishing")
    parser.add_argument("--blas-threads", type=int, default=1,
                        help="BLAS threads for every backend (0: library default)")
    parser.add_argument("--min-time", type=float, default=None,
                        help="seconds of repeats per measurement (default 0.3; --quick 0.08)")
    return parser.parse_args(argv)


def _us(seconds):
    return None if seconds is None else seconds * 1e6


def _fmt(value, width=9):
    if value is None:
        return "-".rjust(width)
    if value >= 100:
        return f"{value:,.0f}".rjust(width)
    return f"{value:.1f}".rjust(width)


def _ratio(numerator, denominator):
    if numerator is None or denominator is None:
        return None
    return numerator / denominator


def main(argv=None):
    args = _parse(argv)
    output = Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    dimensions = args.dimensions or ([3] if args.quick else list(DS))
    min_time = args.min_time or (0.08 if args.quick else 0.3)
    hsr_seconds = args.hsr_seconds or (1.0 if args.quick else 5.0)
    blas_note = _limit_blas(args.blas_threads)
    have_pydmps = _available("pydmps")
    have_mp = _available("movement_primitives.dmp")
    print(f"pbp-drake bench: {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} CPUs, Python {platform.python_version()}, NumPy "
          f"{np.__version__}; {blas_note}")
    for name, present in [("pydmps", have_pydmps), ("movement_primitives", have_mp)]:
        if not present:
            print(f"note: {name} is not installed (pip install -e '.[bench]'); its columns "
                  "stay empty")

    print("Measuring memory bandwidth ...", flush=True)
    bandwidth = memory_bandwidth()
    print(f"  read {bandwidth['read_gb_per_s']:.1f} GB/s, copy "
          f"{bandwidth['copy_gb_per_s']:.1f} GB/s ({bandwidth['array_megabytes']} MB array); "
          f"read {bandwidth['cache_read_gb_per_s']:.1f} GB/s from a "
          f"{bandwidth['cache_array_megabytes']} MB array (cache)")

    rows = []
    for dimension in dimensions:
        for goal_count in args.goals:
            for distinct in (True, False):
                rows.append(_measure_row(dimension, goal_count, distinct, min_time,
                                         args.peer_max_goals, have_pydmps, have_mp,
                                         bandwidth))
                _print_progress(rows[-1])

    closed_loop = []
    for goal_count in args.hsr_goals:
        for with_meshcat in ([False] if args.no_meshcat else [False, True]):
            print(f"HSR reaching, K = {goal_count}, "
                  f"{'Meshcat' if with_meshcat else 'headless'} ...", flush=True)
            meshcat = None
            if with_meshcat:
                from pydrake.geometry import Meshcat, MeshcatParams
                meshcat = Meshcat(MeshcatParams(host="localhost"))
            result = hsr_speed(goal_count, hsr_seconds, meshcat)
            result["meshcat"] = with_meshcat
            closed_loop.append(result)
            del meshcat

    report = {
        "machine": {"processor": platform.processor() or platform.machine(),
                    "cpus": os.cpu_count(), "python": platform.python_version(),
                    "numpy": np.__version__, "blas": blas_note,
                    "load_average": os.getloadavg() if hasattr(os, "getloadavg") else None},
        "settings": {"basis_count": BASIS, "dt": DT, "min_time_s": min_time,
                     "quick": args.quick},
        "memory_bandwidth": bandwidth,
        "steps": rows,
        "closed_loop": closed_loop,
    }
    report["acceptance"] = acceptance(rows, closed_loop, bandwidth)
    text = format_report(report)
    print(text)
    (output / "bench.json").write_text(json.dumps(report, indent=2))
    (output / "bench.txt").write_text(text + "\n")
    figure = plot_control_rate(rows, output / "bench_control_rate.png")
    print(f"Wrote {output / 'bench.json'}, {output / 'bench.txt'}"
          + (f" and {figure}" if figure else ""))
    return 0


def _measure_row(dimension, goal_count, distinct, min_time, peer_max_goals, have_pydmps,
                 have_mp, bandwidth):
    case = make_case(dimension, goal_count, distinct)
    bank = make_bank(case)
    row = {"D": dimension, "K": goal_count, "weights": "distinct" if distinct else "shared"}
    math_median, math_min, repeats = _timed(bank_math_step(bank, case), min_time)
    row.update(bank_math_us=_us(math_median), bank_math_min_us=_us(math_min),
               bank_math_repeats=repeats)

    # Inside the LeafSystem: several periods per timed call, so that Simulator.AdvanceTo's
    # own call cost is spread; the bank and the null system alike.
    periods = 10 if goal_count <= 10000 else 2
    for label, leaf_bank in [("leaf", make_bank(case)), ("drake_overhead", None)]:
        simulator = leaf_simulator(case, leaf_bank)
        median, minimum, _ = _timed(leaf_step(simulator, periods), min_time, warmup=1)
        row[f"{label}_us"] = _us(median / periods)
        row[f"{label}_min_us"] = _us(minimum / periods)
        del simulator
    del bank

    weight_bytes = (case.weights.nbytes if distinct else case.shared_weights.nbytes)
    row["weight_bytes"] = weight_bytes
    row["bandwidth_bound_us"] = _us(weight_bytes / (bandwidth["read_gb_per_s"] * 1e9))
    row["cache_bandwidth_bound_us"] = _us(
        weight_bytes / (bandwidth["cache_read_gb_per_s"] * 1e9))

    peer_time = max(min_time / 3, 0.02)
    for label, available, factory, limit in [
            ("pydmps_per_goal", have_pydmps, pydmps_step, peer_max_goals),
            ("mp_per_goal", have_mp, movement_primitives_step, peer_max_goals),
            ("mp_stacked", have_mp, movement_primitives_stacked_step, 10**9)]:
        row[f"{label}_us"] = None
        if available and goal_count <= limit and not (
                label == "mp_stacked" and goal_count * dimension > 600000):
            step = factory(case)
            median, _, _ = _timed(step, peer_time, max_repeats=500, min_repeats=3, warmup=1)
            row[f"{label}_us"] = _us(median)
            del step
    per_goal = [row[k] for k in ("pydmps_per_goal_us", "mp_per_goal_us") if row[k]]
    row["speedup_vs_per_goal"] = _ratio(min(per_goal) if per_goal else None,
                                        row["bank_math_us"])
    row["speedup_vs_stacked"] = _ratio(row["mp_stacked_us"], row["bank_math_us"])
    row["control_rate_hz"] = 1e6 / row["leaf_us"]
    return row


def _print_progress(row):
    print(f"  D={row['D']} K={row['K']:>6} {row['weights']:>8}: math "
          f"{row['bank_math_us']:.1f} us, in LeafSystem {row['leaf_us']:.1f} us "
          f"(Drake {row['drake_overhead_us']:.1f} us)", flush=True)


def _find(rows, dimension, goal_count, weights):
    for row in rows:
        if (row["D"], row["K"], row["weights"]) == (dimension, goal_count, weights):
            return row
    return None


def acceptance(rows, closed_loop, bandwidth):
    """The issue's acceptance numbers, each with its measured value and verdict."""
    checks = []

    def check(name, value, limit, passes, unit=""):
        checks.append({"criterion": name, "value": value, "limit": limit, "unit": unit,
                       "pass": None if value is None else bool(passes(value))})

    row = _find(rows, 3, 10000, "distinct")
    check("K=10,000, D=3, distinct: bank inside its LeafSystem <= 1 ms",
          row and row["leaf_us"], 1000.0, lambda v: v <= 1000.0, "us")
    row = _find(rows, 3, 100000, "shared")
    check("K=100,000, one shared demonstration (D=3): inside its LeafSystem <= 1 ms",
          row and row["leaf_us"], 1000.0, lambda v: v <= 1000.0, "us")
    row = _find(rows, 3, 1000, "distinct")
    check("K=1,000 (D=3, distinct): bank math >= 100x the faster one-object-per-goal peer",
          row and row["speedup_vs_per_goal"], 100.0, lambda v: v >= 100.0, "x")
    row = _find(rows, 3, 10000, "distinct")
    check("K=10,000 (D=3, distinct): bank math >= 5x movement_primitives stacked",
          row and row["speedup_vs_stacked"], 5.0, lambda v: v >= 5.0, "x")
    check("K=10,000 (D=3, distinct): bank math within 2x of weights / memory bandwidth",
          row and row["bank_math_us"] / row["bandwidth_bound_us"], 2.0,
          lambda v: v <= 2.0, "x bound")
    run = next((r for r in closed_loop if r["goals"] == 100 and not r["meshcat"]), None)
    check("HSR reaching, K=100, headless: >= 10x real time",
          run and run["realtime_factor"], 10.0, lambda v: v >= 10.0, "x real time")
    return checks


def format_report(report):
    lines = []
    bandwidth = report["memory_bandwidth"]
    lines.append(f"Memory bandwidth: read {bandwidth['read_gb_per_s']:.1f} GB/s, copy "
                 f"{bandwidth['copy_gb_per_s']:.1f} GB/s ({bandwidth['array_megabytes']} MB); "
                 f"cache-sized read {bandwidth['cache_read_gb_per_s']:.1f} GB/s. "
                 f"{report['machine']['blas']}.")
    lines.append("One step of all K DMPs from one robot state, microseconds (median); "
                 "N = 50, dt = 1 ms.")
    lines.append("math: DmpBank.advance_into; leaf: the DmpBank LeafSystem per 1 ms period "
                 "in a Simulator (includes Drake); drake: a LeafSystem with the same ports "
                 "and an empty update;")
    lines.append("bound: weight bytes / measured read bandwidth (cache-sized bound in "
                 "brackets); pydmps/goal, mp/goal: one object per goal; mp stacked: one "
                 "K*D DMP; x per-goal, x stacked: speed-ups of the bank math.")
    header = (f"{'D':>2} {'K':>7} {'weights':>8} {'math':>9} {'leaf':>9} {'drake':>7} "
              f"{'bound':>9} {'[cache]':>9} {'pydmps/goal':>12} {'mp/goal':>10} "
              f"{'mp stacked':>11} {'x per-goal':>10} {'x stacked':>9} {'rate Hz':>9}")
    lines.append(header)
    lines.append("-" * len(header))
    for row in report["steps"]:
        bound = row["bandwidth_bound_us"] if row["weights"] == "distinct" else None
        cache = row["cache_bandwidth_bound_us"] if row["weights"] == "distinct" else None
        lines.append(
            f"{row['D']:>2} {row['K']:>7} {row['weights']:>8} {_fmt(row['bank_math_us'])} "
            f"{_fmt(row['leaf_us'])} {_fmt(row['drake_overhead_us'], 7)} {_fmt(bound)} "
            f"{_fmt(cache)} {_fmt(row['pydmps_per_goal_us'], 12)} "
            f"{_fmt(row['mp_per_goal_us'], 10)} {_fmt(row['mp_stacked_us'], 11)} "
            f"{_fmt(row['speedup_vs_per_goal'], 10)} {_fmt(row['speedup_vs_stacked'], 9)} "
            f"{_fmt(row['control_rate_hz'])}")
    if report["closed_loop"]:
        lines.append("")
        lines.append("Closed loop, HSR reaching task (straight-path DMPs, virtual participant, "
                     "PBP-Alt): simulated seconds per wall second")
        for run in report["closed_loop"]:
            lines.append(f"  K = {run['goals']:>5} {'Meshcat' if run['meshcat'] else 'headless':>8}:"
                         f" {run['realtime_factor']:7.2f}x real time "
                         f"({run['simulated_s']:.1f} s in {run['wall_s']:.2f} s wall; "
                         f"built in {run['build_s']:.1f} s)")
    lines.append("")
    lines.append("Acceptance (issue 6):")
    for item in report["acceptance"]:
        verdict = {True: "PASS", False: "FAIL", None: "n/a "}[item["pass"]]
        value = "not measured" if item["value"] is None else (
            f"{item['value']:.2f} {item['unit']} (limit {item['limit']:g})")
        lines.append(f"  [{verdict}] {item['criterion']}: {value}")
    return "\n".join(lines)


def plot_control_rate(rows, path):
    """Control rate reached (1 / step time) versus K, for D = 3 (or the first D measured)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    dimensions = sorted({row["D"] for row in rows})
    dimension = 3 if 3 in dimensions else dimensions[0]
    figure, axes = plt.subplots(figsize=(7.5, 5))
    series = [("leaf_us", "distinct", "bank in LeafSystem, distinct weights", "C0", "-o"),
              ("leaf_us", "shared", "bank in LeafSystem, one shared demo", "C1", "-o"),
              ("bank_math_us", "distinct", "bank math, distinct weights", "C0", ":."),
              ("bank_math_us", "shared", "bank math, one shared demo", "C1", ":."),
              ("mp_stacked_us", "distinct", "movement_primitives, K*D stacked", "C2", "--s"),
              ("pydmps_per_goal_us", "distinct", "pydmps, one object per goal", "C3", "--^"),
              ("mp_per_goal_us", "distinct", "movement_primitives, one per goal", "C4", "--v")]
    for key, weights, label, color, style in series:
        points = [(row["K"], 1e6 / row[key]) for row in rows
                  if row["D"] == dimension and row["weights"] == weights and row.get(key)]
        if points:
            k, rate = zip(*points)
            axes.plot(k, rate, style, color=color, label=label)
    axes.axhline(1000, color="grey", lw=0.8, ls="--")
    axes.axhline(30, color="grey", lw=0.8, ls=":")
    axes.text(1, 1100, "1 kHz", color="grey")
    axes.text(1, 33, "30 Hz (paper)", color="grey")
    axes.plot([100], [30], "k*", ms=12, label="paper, Fig. 6c: 100 DMPs at 30 Hz")
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("goals K (one DMP each)")
    axes.set_ylabel("control rate reached (Hz) = 1 / step time")
    axes.set_title(f"DMP bank step, D = {dimension}, N = {BASIS} basis functions")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8, loc="lower left")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


if __name__ == "__main__":
    sys.exit(main())
