"""Layer 4: a resolved scenario in, a Drake Diagram out (`build_diagram`: the 2-D scenes in
`point_robot`, the tasks in `reach` and `grasp`, their controller in `pbp_controller`), and
runs of it (`run`, `streamed_run`)."""

from pbp_drake.builder.build import build_diagram, find_system
from pbp_drake.builder.operators import (
    make_hsr_operator, make_operator, sinusoidal_step_commands)
from pbp_drake.builder.pbp_controller import make_pbp_controller
from pbp_drake.builder.run import (
    TaskResult, Trajectory, read_log, read_trajectory, run_task, simulate)
from pbp_drake.builder.streamed_run import run_task_streamed

__all__ = ["TaskResult", "Trajectory", "build_diagram", "find_system", "make_hsr_operator",
           "make_operator", "make_pbp_controller", "read_log", "read_trajectory", "run_task",
           "run_task_streamed", "simulate", "sinusoidal_step_commands"]
