"""The bench's checks: each named for what it measures, with its limit, its verdict (pass,
fail, or skipped with the reason: a peer library not installed, or a case this run did not
measure), the summary line, and the exit code (1 when any check fails).

`--quick` runs the same checks with the same limits at fewer repeats: every check's case is
in the quick run (see `pbp_drake_bench.main.plan`)."""

import dataclasses
from collections.abc import Callable

PEERS = ("pydmps", "movement_primitives")
# The K of the goal estimators' steps (`pbp_drake_bench.estimators`; not imported: it
# imports Drake's systems, and this module is read by the CLI's reference).
ESTIMATOR_GOALS = 10_000
# The K of the arm's run at its driver's rate (`pbp_drake_bench.driver_rate`).
DRIVER_GOALS = 100


@dataclasses.dataclass(frozen=True)
class Check:
    name: str
    limit: float
    at_most: bool  # passes when value <= limit (else when value >= limit)
    unit: str
    # The row of steps, the closed-loop run (with `base_run`: the pair of runs), or the
    # replay sizes -> the measured value
    value: Callable
    row: tuple | None = None  # (D, K, weights) of the step row it reads
    pose: bool = False  # the row is the six-DoF pose bank's (`pbp_drake_bench.pose_cases`)
    # (task, K, meshcat) of the closed-loop run it reads, on the shipped robot
    # (`pbp_drake_bench.closed_loop`; with Meshcat, a client reading everything)
    run: tuple | None = None
    base_run: tuple | None = None  # ... and of the run of the same bench it compares with
    replay: tuple = ()  # the K of the replay sizes it compares (`pbp_drake_bench.replay`)
    estimator: str = ""  # the row of the goal estimators' steps it reads (`.estimators`)
    driver: bool = False  # it reads the run at the driver's rate (`.driver_rate`)
    peers: tuple = ()  # it needs one of these peer libraries
    motion: bool = False  # it reads the row's timing over a movement (`cases.motion_timing`)


_K10K = (3, 10000, "distinct")
# The K of the checked headless closed-loop run (its dynamic robot is measured beside it).
CHECKED_HSR_GOALS = 100
# The K of the checked replays: each K's size over the first's.
CHECKED_REPLAY_GOALS = (4, 1000)
_MESHCAT = "Meshcat drawing to a client (another process) that reads everything sent"
_AT_THE_DRIVER = (f"iiwa reaching task, K={DRIVER_GOALS} goals, over LCM to its driver "
                  "simulator in the same process (memq://, 200 Hz), headless")
_OVER_A_MOVEMENT = ("one step in the LeafSystem and a read of its selected reference, median "
                    "over a movement and as long after it,")


def _motion(row):
    return row.get("leaf_motion_us")


CHECKS = (
    Check(f"K=10,000 goals (D=3, distinct weights): {_OVER_A_MOVEMENT} <= 1 ms",
          1000.0, True, "us", _motion, row=_K10K, motion=True),
    Check(f"K=10,000 goals, 6-DoF pose, distinct weights: {_OVER_A_MOVEMENT} <= 0.7 ms",
          700.0, True, "us", _motion, row=(6, 10000, "distinct"), pose=True, motion=True),
    Check("K=100,000 goals sharing one demonstration (D=3, the compact state): "
          f"{_OVER_A_MOVEMENT} <= 1 ms",
          1000.0, True, "us", _motion, row=(3, 100000, "shared"), motion=True),
    Check("K=1,000 goals (D=3, distinct weights): bank math >= 100x faster than one DMP "
          "object per goal (the faster of pydmps and movement_primitives)", 100.0, False, "x",
          lambda row: row["speedup_vs_per_goal"], row=(3, 1000, "distinct"), peers=PEERS),
    Check("K=10,000 goals (D=3, distinct weights): bank math >= 5x faster than "
          "movement_primitives with the goals stacked into one K*D DMP", 5.0, False, "x",
          lambda row: row["speedup_vs_stacked"], row=_K10K,
          peers=("movement_primitives",)),
    Check("K=10,000 goals (D=3, distinct weights): bank math <= 2x the memory-bandwidth "
          "bound (weight bytes / measured read bandwidth)", 2.0, True, "x the bound",
          lambda row: row["bank_math_us"] / row["bandwidth_bound_us"], row=_K10K),
    Check(f"HSR reaching task, K={CHECKED_HSR_GOALS} goals, headless, the shipped "
          "(kinematic) robot: closed loop >= 20x real time", 20.0, False, "x real time",
          lambda run: run["realtime_factor"], run=("reach", CHECKED_HSR_GOALS, False)),
    Check("HSR reaching task, headless, the shipped robot: closed loop at K=10,000 goals >= "
          "0.5x its speed at K=4 goals (both medians of the same bench)", 0.5, False,
          "x the K=4 speed", lambda pair: pair[0]["realtime_factor"] / pair[1]["realtime_factor"],
          run=("reach", 10000, False), base_run=("reach", 4, False)),
    Check(f"HSR reaching task, K=10,000 goals, {_MESHCAT}: closed loop >= 1x real time", 1.0,
          False, "x real time", lambda run: run["realtime_factor"], run=("reach", 10000, True)),
    Check(f"HSR reaching task, K=1,000 goals, {_MESHCAT}: closed loop >= 2x real time", 2.0,
          False, "x real time", lambda run: run["realtime_factor"], run=("reach", 1000, True)),
    Check(f"HSR grasping task (six-DoF), K=1,000 grasp targets, {_MESHCAT}: closed loop >= 1x "
          "real time", 1.0, False, "x real time", lambda run: run["realtime_factor"],
          run=("grasp", 1000, True)),
    Check(f"K={ESTIMATOR_GOALS:,} goals: the intent_filter estimator, a control period's "
          "step <= 2x the angle estimator's (same run)", 2.0, True,
          "x angle", lambda row: row["vs_angle"], estimator="intent_filter"),
    Check(f"{_AT_THE_DRIVER}: closed loop >= 5x real time", 5.0, False, "x real time",
          lambda run: run["realtime_factor"], driver=True),
    Check(f"{_AT_THE_DRIVER}: a control tick's wall time, 99th percentile <= 3x the median "
          "(no stalls at the driver's rate)", 3.0, True, "x the median",
          lambda run: run["p99_over_median"], driver=True),
    Check("Replay of a 5 s HSR reaching run as pbp-drake run --record saves it: K=1,000 goals "
          "<= 3x the size of K=4's", 3.0, True, "x the K=4 replay",
          lambda sizes: sizes[1000] / sizes[4], replay=CHECKED_REPLAY_GOALS),
)


# The step rows timed over a movement too: ((D, K, weights), pose).
MOTION_ROWS = frozenset((check.row, check.pose) for check in CHECKS if check.motion)


def evaluate(rows, closed_loop, installed, blas=None, replay=None, estimators=None,
             driver_rate=None):
    """Every check's result: {"check", "value", "limit", "unit", "verdict", "reason"}, the
    verdict "pass", "fail" or "skipped" (then "reason" says why). `installed` is the set of
    peer libraries present; `blas` (from `pinning.blas_threads`) adds the pinning check;
    `replay` is `pbp_drake_bench.replay.replay_sizes`' result (None: not recorded);
    `estimators` `pbp_drake_bench.estimators.estimator_steps`' (None: not measured);
    `driver_rate` `pbp_drake_bench.driver_rate.driver_rate_run`'s (None: not run)."""
    results = []
    for check in CHECKS:
        result = {"check": check.name, "value": None, "limit": check.limit,
                  "unit": check.unit, "verdict": "skipped", "reason": None}
        results.append(result)
        if check.peers and not set(check.peers) & set(installed):
            result["reason"] = f"{', '.join(check.peers)} not installed"
            continue
        source, where = _source(check, rows, closed_loop, replay, estimators, driver_rate)
        value = None if source is None else check.value(source)
        if value is None:
            result["reason"] = ("not measured: " + where if source is None else
                                "not measured: no timing over a movement" if check.motion
                                else "not measured: K above --peer-max-goals")
            continue
        result["value"] = float(value)
        passes = value <= check.limit if check.at_most else value >= check.limit
        result["verdict"] = "pass" if passes else "fail"
    if blas is not None:
        results.append(_blas_check(blas))
    return results


def _source(check, rows, closed_loop, replay, estimators=None, driver_rate=None):
    if check.driver:
        return ((driver_rate, None) if driver_rate else
                (None, "no run at the driver's rate (--no-driver-rate, or --hsr-goals empty)"))
    if check.estimator:
        found = [row for row in (estimators or {}).get("rows", ())
                 if row["estimator"] == check.estimator]
        return (found[0], None) if found else (None, "no goal estimator steps (--no-estimators)")
    if check.replay:
        sizes = {run["goals"]: run["bytes"] for run in (replay or {}).get("runs", ())}
        if all(k in sizes for k in check.replay):
            return sizes, None
        return None, (f"no replays of K={', '.join(f'{k:,}' for k in check.replay)} "
                      "(--hsr-goals empty or --no-meshcat)")
    if check.base_run is not None:
        runs = [_find_run(closed_loop, key) for key in (check.run, check.base_run)]
        if None in runs:
            return None, ("no " + " and ".join(_run_words(key) for key, run in
                                               zip((check.run, check.base_run), runs)
                                               if run is None))
        return tuple(runs), None
    if check.row is not None:
        dimension, goals, weights = check.row
        for row in rows:
            if ((row["D"], row["K"], row["weights"]) == check.row
                    and bool(row.get("pose")) == check.pose):
                return row, None
        if check.pose:
            return None, f"6-DoF pose, K={goals:,}, {weights} weights not in --goals"
        return None, f"D={dimension}, K={goals:,}, {weights} weights not in --dimensions/--goals"
    run = _find_run(closed_loop, check.run)
    return (run, None) if run is not None else (None, "no " + _run_words(check.run))


def _find_run(closed_loop, key):
    task, goals, meshcat = key
    for run in closed_loop:
        if ((run.get("task", "reach"), run["goals"], run["meshcat"]) == (task, goals, meshcat)
                and run.get("shipped_robot", True)):
            return run
    return None


def _run_words(key):
    task, goals, meshcat = key
    return (f"{'Meshcat' if meshcat else 'headless'} HSR {task} run with K={goals:,} in "
            "--hsr-goals/--tasks" + (" (or --no-meshcat)" if meshcat else ""))


def _blas_check(blas):
    requested = blas["requested"]
    result = {"check": f"BLAS threads in the measuring process = {requested} "
                       "(--blas-threads), as the BLAS library reports them",
              "value": blas["library_threads"], "limit": requested, "unit": "threads",
              "verdict": "skipped", "reason": None}
    if requested <= 0:
        result["reason"] = "--blas-threads 0 (library default)"
    elif blas["library_threads"] is None:
        result["reason"] = "the BLAS library's thread count cannot be read here"
    else:
        result["verdict"] = "pass" if blas["library_threads"] == requested else "fail"
    return result


def exit_code(results):
    """1 when any check failed, else 0 (skipped checks count neither way)."""
    return 1 if any(result["verdict"] == "fail" for result in results) else 0


def summary(results):
    """One line: how many passed, failed and were skipped (and why), and the exit code."""
    counts = {verdict: sum(r["verdict"] == verdict for r in results)
              for verdict in ("pass", "fail", "skipped")}
    # Grouped by why: "pydmps, movement_primitives not installed", "not measured", ...
    reasons = [r["reason"].split(":")[0] for r in results if r["verdict"] == "skipped"]
    skipped = f"{counts['skipped']} skipped"
    if reasons:
        skipped += " (" + "; ".join(f"{reason}: {reasons.count(reason)}"
                                    for reason in dict.fromkeys(reasons)) + ")"
    return (f"Checks: {counts['pass']} passed, {counts['fail']} failed, {skipped}; "
            f"skipped checks count neither as passes nor as failures; exit code "
            f"{exit_code(results)}")


def format_results(results):
    """The checks' lines and the summary line."""
    lines = ["Checks (each against its limit):"]
    for result in results:
        verdict = {"pass": "PASS", "fail": "FAIL", "skipped": "SKIP"}[result["verdict"]]
        if result["verdict"] == "skipped":
            detail = f"skipped: {result['reason']}"
        else:
            detail = (f"{result['value']:.2f} {result['unit']} "
                      f"(limit {result['limit']:g})")
        lines.append(f"  [{verdict}] {result['check']}: {detail}")
    lines.append(summary(results))
    return "\n".join(lines)
