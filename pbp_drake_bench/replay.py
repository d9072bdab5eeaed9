"""Replay size: a reach run recorded as `pbp-drake run --record` records it (Meshcat's
`StartRecording(frames_per_second=30)` after the build, the run, and the page
`output_paths.recorded_replay` makes), its size in bytes for each K."""

import time

from pbp_drake_bench.closed_loop import build_simulator, new_meshcat
from pbp_drake_bench.scenes import REACH
from pbp_drake.output_paths import recorded_replay

REPLAY_GOALS = (4, 1000)
REPLAY_SECONDS = 5.0


def replay_size(goal_count, simulated_seconds=REPLAY_SECONDS, task=REACH):
    """`{"goals", "bytes", "simulated_s", "wall_s"}` of one recorded run's replay page."""
    meshcat = new_meshcat()
    began = time.perf_counter()
    simulator, _, _ = build_simulator(task, goal_count, meshcat, start_recording=True)
    simulator.AdvanceTo(simulated_seconds)
    page = recorded_replay(meshcat)
    return {"task": task, "goals": goal_count, "bytes": len(page.encode()),
            "simulated_s": simulator.get_context().get_time(),
            "wall_s": time.perf_counter() - began}


def replay_sizes(goal_counts=REPLAY_GOALS, simulated_seconds=REPLAY_SECONDS, progress=print):
    """The replay of each K (`replay_size`) and each one's size over the first's:
    `{"runs": [...], "ratio": {K: size / first size}}`."""
    runs = []
    for k in goal_counts:
        progress(f"Replay: recording a {simulated_seconds:g} s reach run, K = {k} ...")
        runs.append(replay_size(k, simulated_seconds))
    first = runs[0]["bytes"]
    return {"simulated_s": simulated_seconds, "runs": runs,
            "ratio": {str(run["goals"]): run["bytes"] / first for run in runs}}
