"""Layer 4: a resolved scenario in, a Drake Diagram out, and runs of it.

- `build`: `build_diagram` (the one entry point) and `find_system`;
- `point_robot`: the 2-D scenes; `hsr`: the HSR tasks, with `pbp_controller` (the PBP loop
  as one Diagram) and `pbp_drake.robots.make_hsr_station`; `operators`: who drives;
- `run`: `simulate`, `run_task`, `read_log` and their results; `streamed_run`:
  `run_task_streamed`, a task whose per-tick rows go to a CSV file as it runs
  (`time_series`: the CSV's columns and rows, shared with a study's trial files).
"""

from pbp_drake.builder.build import build_diagram, check_buildable, find_system
from pbp_drake.builder.operators import (
    make_hsr_operator, make_operator, sinusoidal_step_commands)
from pbp_drake.builder.pbp_controller import make_pbp_controller
from pbp_drake.builder.run import (
    TaskResult, Trajectory, read_log, read_trajectory, run_task, simulate)
from pbp_drake.builder.streamed_run import run_task_streamed

__all__ = ["TaskResult", "Trajectory", "build_diagram", "check_buildable", "find_system",
           "make_hsr_operator", "make_operator", "make_pbp_controller", "read_log",
           "read_trajectory", "run_task", "run_task_streamed", "simulate",
           "sinusoidal_step_commands"]
