"""Running one HSR task to its end and reading back its result and time series."""

import dataclasses

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator

from pbp_drake.builder import build_diagram
from pbp_drake.scenarios import ResolvedScenario, resolve
from pbp_drake.simulation import read_log
from pbp_drake.systems.layouts import TaskStatus


@dataclasses.dataclass
class TaskResult:
    """One run of an HSR task, its metrics and its time series indexed by control tick k.

    Attributes:
        success: the end effector came within the success distance of the final target.
        task_time: seconds until success (the time limit when it failed).
        intervention_ratio: ticks with operator input / ticks of the task.
        switches: how many times the target switched.
        times: (T,) tick times. ee_positions: (T, 3); headings: (T,).
        commands: (T, 7) `[p, v, heading]` sent from tick k on.
        operator_active: (T,) bools; operator_commands: (T, 4).
        selected_goals, targets: (T,) object indices (estimate and truth) at tick k.
        objects: (M, 3).
        collision_ratio: ratio of ticks with the robot in collision (obstacle tasks; 0 in
            tasks without obstacles). in_collision: (T,) bools, or None without obstacles.
    """

    success: bool
    task_time: float
    intervention_ratio: float
    switches: int
    times: np.ndarray
    ee_positions: np.ndarray
    headings: np.ndarray
    commands: np.ndarray
    operator_active: np.ndarray
    operator_commands: np.ndarray
    selected_goals: np.ndarray
    targets: np.ndarray
    objects: np.ndarray
    collision_ratio: float = 0.0
    in_collision: np.ndarray | None = None

    def summary_line(self):
        outcome = "success" if self.success else "FAILED"
        return (f"{outcome} in {self.task_time:.2f} s, intervention ratio "
                f"{self.intervention_ratio:.3f}, {self.switches} target switches")


def run_task(scenario, meshcat=None, realtime_rate=None, diagram=None):
    """Simulates an HSR task until success or `scenario.duration` (the time limit)."""
    resolved = scenario if isinstance(scenario, ResolvedScenario) else resolve(scenario)
    scenario = resolved.scenario
    diagram = build_diagram(resolved, meshcat) if diagram is None else diagram
    monitor = diagram.GetSubsystemByName("task_monitor")
    status_port = monitor.get_task_status_output_port()
    simulator = Simulator(diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    if realtime_rate is not None:
        simulator.set_target_realtime_rate(realtime_rate)
    # The task monitor itself ends the simulation at success.
    simulator.Initialize()
    period = scenario.control_period
    ticks = int(round(scenario.duration / period))
    simulator.AdvanceTo((ticks + 1) * period)
    context = simulator.get_context()
    status = TaskStatus(status_port.Eval(monitor.GetMyContextFromRoot(context)))
    return _read_result(diagram, context, status, monitor)


def _read_result(diagram, context, status, monitor):
    # The last sample holds only the decisions of the tick before it (see read_log).
    tick_count = diagram.GetSubsystemByName("ee_state_log").FindLog(context).num_samples() - 1

    def decisions(name):
        return read_log(diagram, context, name, tick_count, shift=1)[1]

    times, ee_state = read_log(diagram, context, "ee_state_log", tick_count)
    # Measured on the plant's state, like ee_state: not shifted.
    in_collision = read_log(diagram, context, "in_collision_log", tick_count)[1]
    return TaskResult(
        success=bool(status.success > 0.5),
        task_time=float(status.task_time),
        intervention_ratio=float(status.intervention_ratio),
        switches=int(status.stage),
        times=times,
        ee_positions=ee_state[:, :3],
        headings=ee_state[:, 6],
        commands=decisions("command_log"),
        operator_active=decisions("operator_active_log")[:, 0] > 0.5,
        operator_commands=decisions("operator_command_log"),
        selected_goals=decisions("selected_goal_log")[:, 0].astype(int),
        targets=decisions("target_log")[:, 3].astype(int),
        objects=monitor.objects.copy(),
        collision_ratio=float(status.collision_ratio),
        in_collision=None if in_collision is None else in_collision[:, 0] > 0.5,
    )
