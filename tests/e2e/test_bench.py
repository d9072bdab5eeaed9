"""`pbp-drake bench` cannot lie: BLAS threads pinned in the measuring process without any
optional package, each check named for what it measures, missing peers skipped (neither
passed nor failed), `--quick` keeping every check, and exit code 1 when a check fails.

The command-line tests run the real `python -m pbp_drake bench` with a `sitecustomize`
that hides the `bench` extra (threadpoolctl, pydmps, movement_primitives) as in a venv
without it, records each process's thread variables before NumPy loads, and, in the
measuring process only, replaces the timer with a fixed time per step (so a check's verdict
does not depend on the machine's speed)."""

import json
import os
import subprocess
import sys
import textwrap
import time

import pytest

from pbp_drake.bench.cases import (
    MOTION_DURATIONS, leaf_simulator, make_bank, make_case, motion_timing)
from pbp_drake.bench.checks import CHECKS, evaluate, exit_code, format_results, summary
from pbp_drake.bench.pinning import MARKER, THREAD_VARIABLES, blas_threads
from pbp_drake.bench.main import _parse, plan
from pbp_drake.bench.timing import timed_span

K10K_LEAF = ("K=10,000 goals (D=3, distinct weights): one step in the LeafSystem and a read of "
             "its selected reference, median over "
             "a movement and as long after it, <= 1 ms")

CLOSED_LOOP = ("HSR reaching task, K=100 goals, headless, the shipped (kinematic) robot: "
               "closed loop >= 20x real time")
SITECUSTOMIZE = textwrap.dedent("""
    import json, os, sys
    for name in ("threadpoolctl", "pydmps", "movement_primitives"):
        sys.modules[name] = None  # as in a venv without the bench extra
    with open(os.environ["BENCH_TEST_RECORD"], "a") as record:
        record.write(json.dumps({
            "measuring": "%(marker)s" in os.environ,
            "numpy_loaded": "numpy" in sys.modules,
            "variables": {name: os.environ.get(name) for name in %(variables)r}}) + "\\n")
    if "%(marker)s" in os.environ:
        import pbp_drake.bench.timing as timing
        seconds = float(os.environ["BENCH_TEST_STEP_SECONDS"])
        timing.timed = lambda step, min_time, **options: (seconds, seconds, 3)
        timing.timed_span = lambda step, done, **options: (seconds, seconds, 3)
""") % {"marker": MARKER, "variables": THREAD_VARIABLES}


def _row(dimension, goals, weights, leaf_us=500.0, math_us=100.0, per_goal=200.0,
         stacked=10.0, bound_us=80.0):
    return {"D": dimension, "K": goals, "weights": weights, "leaf_us": leaf_us,
            "leaf_motion_us": leaf_us, "bank_math_us": math_us, "speedup_vs_per_goal": per_goal,
            "speedup_vs_stacked": stacked, "bandwidth_bound_us": bound_us}


def _pose_row(goals, weights, leaf_us=500.0):
    return dict(_row(6, goals, weights, leaf_us), pose=True)


def _all_cases(leaf_us=500.0):
    rows = [_row(3, goals, weights, leaf_us) for goals in (1000, 10000, 100000)
            for weights in ("distinct", "shared")]
    rows.append(_pose_row(10000, "distinct", leaf_us))
    return rows, [{"goals": 100, "meshcat": False, "realtime_factor": 24.0},
                  {"goals": 100, "meshcat": False, "realtime_factor": 11.0,
                   "motion": "dynamic", "shipped_robot": False}]


def test_the_closed_loop_check_reads_the_shipped_robot_not_the_dynamic_one():
    rows, closed_loop = _all_cases()
    verdict = {r["check"]: r["verdict"] for r in evaluate(rows, closed_loop[1:], set())}
    assert verdict[CLOSED_LOOP] == "skipped"  # only the dynamic robot's run: not checked
    closed_loop[0]["realtime_factor"] = 19.0
    verdict = {r["check"]: r["verdict"] for r in evaluate(rows, closed_loop, set())}
    assert verdict[CLOSED_LOOP] == "fail"  # under 20x, whatever the dynamic robot did


def test_every_check_passes_and_the_exit_code_is_0():
    rows, closed_loop = _all_cases()
    results = evaluate(rows, closed_loop, {"pydmps", "movement_primitives"})
    assert [r["verdict"] for r in results] == ["pass"] * len(CHECKS)
    assert exit_code(results) == 0


def test_a_slow_step_fails_its_check_and_the_exit_code_is_1():
    # The reported run: K = 10,000 took 14.3 ms.
    rows, closed_loop = _all_cases(leaf_us=14300.0)
    results = evaluate(rows, closed_loop, {"pydmps", "movement_primitives"})
    failed = [r["check"] for r in results if r["verdict"] == "fail"]
    assert K10K_LEAF in failed
    assert exit_code(results) == 1
    text = format_results(results)
    assert f"[FAIL] {K10K_LEAF}: 14300.00 us (limit 1000)" in text
    assert "exit code 1" in text.splitlines()[-1]


def test_missing_peers_are_skipped_neither_passed_nor_failed():
    rows, closed_loop = _all_cases()
    results = evaluate(rows, closed_loop, installed=set())
    skipped = {r["check"]: r["reason"] for r in results if r["verdict"] == "skipped"}
    assert len(skipped) == 2
    assert set(skipped.values()) == {"pydmps, movement_primitives not installed",
                                     "movement_primitives not installed"}
    assert exit_code(results) == 0
    assert summary(results).startswith(
        "Checks: 5 passed, 0 failed, 2 skipped (pydmps, movement_primitives not installed: 1;"
        " movement_primitives not installed: 1)")
    # One peer is enough for the per-goal check.
    results = evaluate(rows, closed_loop, installed={"pydmps"})
    assert [r["verdict"] for r in results].count("skipped") == 1


def test_quick_keeps_every_check_with_the_same_limits():
    quick, full = plan(_parse(["--quick"])), plan(_parse([]))
    for settings in (quick, full):
        rows = [_row(d, k, w) for d in settings["dimensions"] for k in settings["goals"]
                for w in ("distinct", "shared")]
        rows += [_pose_row(k, w) for k in settings["pose_goals"] for w in ("distinct", "shared")]
        closed_loop = [{"goals": k, "meshcat": False, "realtime_factor": 24.0}
                       for k in settings["hsr_goals"]]
        results = evaluate(rows, closed_loop, {"pydmps", "movement_primitives"})
        assert [(r["check"], r["limit"], r["verdict"]) for r in results] == [
            (check.name, check.limit, "pass") for check in CHECKS]
    assert quick["min_time"] < full["min_time"]
    assert quick["hsr_seconds"] < full["hsr_seconds"]


def test_no_check_is_named_after_an_issue():
    for check in CHECKS:
        assert "issue" not in check.name.lower() and "acceptance" not in check.name.lower()


def test_an_unpinned_process_says_so():
    # pytest's process was not started by the bench: its header must not claim pinning.
    blas = blas_threads(1)
    assert not blas["pinned_before_numpy"]
    assert blas["note"].startswith("BLAS threads: NOT pinned to 1")
    wrong = dict(blas, library_threads=2)
    assert evaluate([], [], set(), wrong)[-1]["verdict"] == "fail"


@pytest.mark.slow  # two bench processes each (about 10 s on a loaded 2-core machine)
@pytest.mark.parametrize("step_seconds, code", [(1e-9, 0), (0.05, 1)],
                         ids=["all-measured-pass", "slow-steps-fail"])
def test_the_bench_command_pins_blas_and_exits_with_the_checks(
        repo, tmp_path, step_seconds, code):
    (tmp_path / "sitecustomize.py").write_text(SITECUSTOMIZE)
    record = tmp_path / "record.jsonl"
    environment = {name: value for name, value in os.environ.items()
                   if name not in THREAD_VARIABLES and name != MARKER}
    environment.update(
        PYTHONPATH=os.pathsep.join([str(tmp_path), str(repo)]),
        BENCH_TEST_RECORD=str(record), BENCH_TEST_STEP_SECONDS=str(step_seconds))
    output = tmp_path / "bench"
    result = subprocess.run(
        [sys.executable, "-m", "pbp_drake", "bench", "--quick", "--goals", "10000",
         "--hsr-goals", "--output", str(output)],
        capture_output=True, text=True, timeout=300, env=environment, cwd=tmp_path)
    assert result.returncode == code, result.stdout + result.stderr

    # The measuring process started with every thread variable at 1, before NumPy.
    processes = [json.loads(line) for line in record.read_text().splitlines()]
    measuring = [p for p in processes if p["measuring"]]
    assert len(measuring) == 1 and len(processes) == 2
    assert not measuring[0]["numpy_loaded"]
    assert set(measuring[0]["variables"].values()) == {"1"}
    # ... and OpenBLAS, read without threadpoolctl, runs one thread.
    blas = json.loads((output / "bench.json").read_text())["machine"]["blas"]
    assert blas["pinned_before_numpy"] and blas["library_threads"] == 1
    assert blas["library"].startswith("openblas (")

    lines = result.stdout.splitlines()
    assert lines[0].endswith("BLAS threads: 1 (OMP_NUM_THREADS, OPENBLAS_NUM_THREADS, "
                             "MKL_NUM_THREADS and the others set to 1 before NumPy loaded; "
                             f"{blas['library']} reports 1)")
    assert "threadpoolctl" not in result.stdout and "Acceptance" not in result.stdout
    verdict = "PASS" if code == 0 else "FAIL"
    assert f"[{verdict}] {K10K_LEAF}: " in result.stdout
    passed, failed = (4, 0) if code == 0 else (1, 3)
    assert (f"Checks: {passed} passed, {failed} failed, 4 skipped (not measured: 2; "
            "pydmps, movement_primitives not installed: 1; movement_primitives not "
            "installed: 1)") in result.stdout
    assert f"exit code {code}" in result.stdout


def test_the_movement_timing_runs_a_fresh_simulator_over_two_durations():
    # The LeafSystem checks read a run from phase 1 to 1e-4 (0 to 2 tau), not its first
    # moments: the step's cost moves with the phase.
    case = make_case(3, 10, True)
    bank = make_bank(case)
    simulator = leaf_simulator(case, bank)
    median, slowest = motion_timing(simulator, bank.duration, 10)
    assert simulator.get_context().get_time() == pytest.approx(MOTION_DURATIONS * bank.duration)
    assert 0.0 < median <= slowest


def test_the_slowest_stretch_of_a_timed_span_is_reported():
    calls = []

    def step():
        calls.append(None)
        if len(calls) > 40:
            time.sleep(0.002)  # the last stretch is slow

    median, slowest, repeats = timed_span(step, lambda: len(calls) >= 48, stretches=6)
    assert repeats == 48
    assert slowest >= 0.002 > median
