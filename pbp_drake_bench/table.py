"""The bench's report: the table of step times, the closed-loop matrix, the per-tick time
split and the replay sizes, and the checks (`pbp_drake_bench.checks`), each with its
measured value and verdict."""

from pbp_drake_bench.checks import format_results
from pbp_drake_bench.time_split import ORDER


def microseconds(seconds):
    return None if seconds is None else seconds * 1e6


def ratio(numerator, denominator):
    if numerator is None or denominator is None:
        return None
    return numerator / denominator


def _fmt(value, width=9):
    if value is None:
        return "-".rjust(width)
    if value >= 100:
        return f"{value:,.0f}".rjust(width)
    return f"{value:.1f}".rjust(width)


def _dimension(row):
    return "6p" if row.get("pose") else row["D"]


def format_report(report):
    lines = []
    bandwidth = report["memory_bandwidth"]
    lines.append(f"Memory bandwidth: read {bandwidth['read_gb_per_s']:.1f} GB/s, copy "
                 f"{bandwidth['copy_gb_per_s']:.1f} GB/s ({bandwidth['array_megabytes']} MB); "
                 f"cache-sized read {bandwidth['cache_read_gb_per_s']:.1f} GB/s. "
                 f"{report['machine']['blas']['note']}.")
    lines.append("One step of all K DMPs from one robot state, microseconds (median); "
                 "N = 50, dt = 1 ms.")
    lines.append("math: DmpBank.advance_into; leaf: the DmpBank LeafSystem per 1 ms period "
                 "in a Simulator (includes Drake), wired as the builder wires it (followed "
                 "and selected goal connected; the compact state with shared weights, the "
                 "per-goal state with distinct ones; the selected "
                 "reference read every period); drake: a LeafSystem with the same ports "
                 "and state and an empty update;")
    lines.append("bound: weight bytes / measured read bandwidth (cache-sized bound in "
                 "brackets); pydmps/goal, mp/goal: one object per goal; mp stacked: one "
                 "K*D DMP; x per-goal, x stacked: speed-ups of the bank math. D = 6p: the "
                 "six-DoF pose bank (3-D positions and unit-quaternion orientations, "
                 "PoseDmpBank with followed_goal connected, in the compact state).")
    header = (f"{'D':>2} {'K':>7} {'weights':>8} {'math':>9} {'leaf':>9} {'drake':>7} "
              f"{'bound':>9} {'[cache]':>9} {'pydmps/goal':>12} {'mp/goal':>10} "
              f"{'mp stacked':>11} {'x per-goal':>10} {'x stacked':>9} {'rate Hz':>9}")
    lines.append(header)
    lines.append("-" * len(header))
    for row in report["steps"]:
        bound = row["bandwidth_bound_us"] if row["weights"] == "distinct" else None
        cache = row["cache_bandwidth_bound_us"] if row["weights"] == "distinct" else None
        lines.append(
            f"{_dimension(row):>2} {row['K']:>7} {row['weights']:>8} {_fmt(row['bank_math_us'])} "
            f"{_fmt(row['leaf_us'])} {_fmt(row['drake_overhead_us'], 7)} {_fmt(bound)} "
            f"{_fmt(cache)} {_fmt(row['pydmps_per_goal_us'], 12)} "
            f"{_fmt(row['mp_per_goal_us'], 10)} {_fmt(row['mp_stacked_us'], 11)} "
            f"{_fmt(row['speedup_vs_per_goal'], 10)} {_fmt(row['speedup_vs_stacked'], 9)} "
            f"{_fmt(row['control_rate_hz'])}")
    every = [row for row in report["steps"] if row.get("leaf_all_references_us")]
    if every:
        lines.append("")
        lines.append("leaf reads the selected goal's reference every period, as the "
                     "builder's blender does (O(D)); reading all K references instead, "
                     "as a consumer of every DMP would (microseconds per period):")
        for row in every:
            lines.append(f"  D = {row['D']} K = {row['K']:>6} {row['weights']:>8}: "
                         f"{_fmt(row['leaf_all_references_us'])} us (leaf "
                         f"{_fmt(row['leaf_us'])} us)")
    poses = [row for row in report["steps"] if row.get("pose")]
    if poses:
        lines.append("")
        lines.append("Six-DoF pose bank in its LeafSystem against the 3-D position bank of "
                     "this run (same K and weights):")
        for row in poses:
            versus = row.get("leaf_vs_position_3d")
            lines.append(f"  K = {row['K']:>6} {row['weights']:>8}: {_fmt(row['leaf_us'])} us "
                         f"(per-goal state: {_fmt(row['leaf_per_goal_us'])} us; each DMP "
                         f"its own velocities: {_fmt(row['leaf_own_us'])} us), "
                         + (f"{versus:.2f}x the position bank" if versus else
                            "no position row"))
    moving = [row for row in report["steps"] if row.get("leaf_motion_us") is not None]
    if moving:
        lines.append("")
        lines.append("In the LeafSystem over a whole movement and as long after it (a fresh "
                     "Simulator, phase 1 to 1e-4, 0 to 2 tau): median per period, and the "
                     "slowest quarter tau's median:")
        for row in moving:
            lines.append(f"  D = {_dimension(row)} K = {row['K']:>6} {row['weights']:>8}: "
                         f"{_fmt(row['leaf_motion_us'])} us (slowest "
                         f"{_fmt(row['leaf_slowest_us'])} us)")
    if report["closed_loop"]:
        lines.append("")
        lines.extend(closed_loop_lines(report["closed_loop"]))
    if report.get("time_split"):
        lines.append("")
        lines.extend(split_lines(report["time_split"], report["closed_loop"]))
    if report.get("replay"):
        lines.append("")
        lines.extend(replay_lines(report["replay"]))
    if report.get("estimators"):
        lines.append("")
        lines.extend(format_estimators(report["estimators"]))
    if report.get("driver_rate"):
        lines.append("")
        lines.append(format_driver_rate(report["driver_rate"]))
    lines.append("")
    lines.append(format_results(report["checks"]))
    return "\n".join(lines)


def closed_loop_lines(runs):
    """The closed-loop matrix (task x K: headless and with Meshcat and a client), then each
    run's details."""
    lines = ["Closed loop, HSR tasks with K goals on a jittered grid (the target the first, no "
             "switches; virtual participant, PBP-Alt; the robot of the scenario file unless "
             "named): real-time factor = simulated s / wall s of AdvanceTo after Initialize "
             "(with Meshcat, to the end of Meshcat.Flush()); headless: median of the repeats "
             "(in rounds over every case); Meshcat: one run drawing to a client (another "
             "process) reading everything, its bytes and messages per simulated second"]
    header = (f"  {'task':<6} {'K':>6} {'headless':>10} {'Meshcat':>10} {'MB/sim s':>9} "
              f"{'msgs/sim s':>11}")
    lines += [header, "  " + "-" * (len(header) - 2)]
    shipped = [run for run in runs if run.get("shipped_robot", True)]
    cases = dict.fromkeys((run.get("task", "reach"), run["goals"]) for run in shipped)
    for task, goals in cases:
        found = {run["meshcat"]: run for run in shipped
                 if (run.get("task", "reach"), run["goals"]) == (task, goals)}
        headless, meshcat = found.get(False), found.get(True)
        lines.append(
            f"  {task:<6} {goals:>6} {_factor(headless):>10} {_factor(meshcat):>10} "
            f"{_number(meshcat and meshcat['bytes_per_s'] / 1e6, 9, 2)} "
            f"{_number(meshcat and meshcat['messages_per_s'], 11, 0)}")
    lines.append("  each run:")
    for run in runs:
        where = ("Meshcat" if run["meshcat"] else "headless") + (
            "" if run.get("shipped_robot", True) else f", {run['motion']} robot")
        factors = run.get("realtime_factors", ())
        of = (f"median of {', '.join(f'{factor:.1f}' for factor in factors)}; "
              if len(factors) > 1 else "")
        capped = (f"; stopped at the {run['wall_cap_s']:g} s wall cap"
                  if run.get("capped") else "")
        lines.append(f"  {run.get('task', 'reach'):<6} K = {run['goals']:>5} {where:>8}:"
                     f" {run['realtime_factor']:7.2f}x real time ({of}"
                     f"{run['simulated_s']:.2f} s in {run['wall_s']:.2f} s wall{capped}; "
                     f"built in {run['build_s']:.1f} s)")
    return lines


def _number(value, width, digits):
    return "-".rjust(width) if value is None else f"{value:,.{digits}f}".rjust(width)


def _factor(run):
    if run is None:
        return "-"
    return f"{run['realtime_factor']:.2f}x" + ("*" if run.get("capped") else "")


def split_lines(runs, closed_loop=()):
    """The per-tick time split of the reach runs (`pbp_drake_bench.time_split`), beside the
    wall time per tick of the same case in the matrix (no profiler)."""
    lines = ["Where a control tick's wall time goes, reach task, one run under cProfile: "
             "each function's own time given to its category (code outside pbp_drake split "
             "over its callers); ms per control tick (share). cProfile inflates the "
             "Python-heavy parts against Drake's C++; Drake's own MeshcatVisualizer of the "
             "robot runs in C++ and counts in rest; bank includes the DMP paths it rolls out "
             "for the drawing (with Meshcat only)."]
    header = (f"  {'K':>6} {'where':>8} {'ticks':>5} {'total':>6} {'matrix':>6} "
              + " ".join(f"{name:>14}" for name in ORDER))
    lines += [header, "  " + "-" * (len(header) - 2)]
    for run in runs:
        split = run["split"]
        where = "Meshcat" if run["meshcat"] else "headless"
        cells = " ".join(f"{split['ms_per_tick'][name]:6.3f} ({100 * split['share'][name]:3.0f}%)"
                         .rjust(14) for name in ORDER)
        same = [other for other in closed_loop if other.get("shipped_robot", True) and (
            other.get("task", "reach"), other["goals"], other["meshcat"]) == (
            "reach", run["goals"], run["meshcat"])]
        matrix = (1e3 * same[0]["control_period_s"] / same[0]["realtime_factor"]
                  if same else None)
        lines.append(f"  {run['goals']:>6} {where:>8} {split['ticks']:5.0f} "
                     f"{split['profiled_ms_per_tick']:6.2f} {_number(matrix, 6, 2)} {cells}")
    lines.append("  total: profiled ms per tick (the categories' sum); matrix: wall ms per "
                 "tick of the same case in the matrix above, without the profiler")
    return lines


def replay_lines(replay):
    """The replay sizes (`pbp_drake_bench.replay`)."""
    first = replay["runs"][0]
    sizes = "; ".join(f"K = {run['goals']:,}: {run['bytes'] / 1e6:.2f} MB"
                      + (f" ({run['bytes'] / first['bytes']:.2f}x K = {first['goals']:,})"
                         if run is not first else "")
                      for run in replay["runs"])
    return [f"Replay of a {replay['simulated_s']:g} s reach run as pbp-drake run --record saves "
            f"it (Meshcat recording at 30 frames/s, StaticHtml): {sizes}"]


def format_estimators(estimators):
    """The report's lines of the estimator steps."""
    lines = [f"Goal estimator step, K = {estimators['goals']:,} goals (a control period's "
             "update and the outputs' read, median; x the angle estimator's):"]
    for row in estimators["rows"]:
        lines.append(f"  {row['estimator']:<24} {row['step_us']:9.0f} us  "
                     f"{row['vs_angle']:5.2f}x")
    return lines


def format_driver_rate(run):
    """The report's line of the arm's run at its driver's rate."""
    return (f"The {run['driver']} over LCM at its driver's rate ({run['driver_period_s'] * 1000:g} "
            f"ms), K = {run['goals']} goals, headless: {run['realtime_factor']:.1f}x real time "
            f"over {run['simulated_s']:.2f} s; a control tick ({run['control_period_s'] * 1000:g}"
            f" ms) took {run['tick_median_ms']:.2f} ms (median), {run['tick_p99_ms']:.2f} ms "
            f"(99th percentile, {run['p99_over_median']:.2f}x the median)")
