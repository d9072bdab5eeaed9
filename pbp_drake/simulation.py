"""Simulating a scenario and reading back its time series."""

import dataclasses

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator

from pbp_drake.builder import build_diagram
from pbp_drake.scenarios import ResolvedScenario, resolve


@dataclasses.dataclass
class Trajectory:
    """One simulation, indexed by control tick k = 0..T-1 (`t_k = k * control_period`).

    Attributes:
        times: (T,). positions, velocities: (T, D) the robot's state at `t_k`.
        operator_active: (T,) bools, the operator's decision at tick k;
        operator_command: (T, D) its command at tick k.
        command: (T, 2 D) the reference the blender sent from tick k on.
        phase: (T, K) the DMP phases with which tick k stepped, or None without DMPs.
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    operator_active: np.ndarray
    operator_command: np.ndarray
    command: np.ndarray
    phase: np.ndarray | None


def simulate(scenario, meshcat=None, realtime_rate=None, diagram=None):
    """Simulates `scenario` for its duration and returns its Trajectory."""
    resolved = scenario if isinstance(scenario, ResolvedScenario) else resolve(scenario)
    scenario = resolved.scenario
    diagram = build_diagram(resolved, meshcat) if diagram is None else diagram
    simulator = Simulator(diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    if realtime_rate is not None:
        simulator.set_target_realtime_rate(realtime_rate)
    simulator.Initialize()
    # One tick past the end: the loggers record tick k's decisions at t_(k+1) (see below).
    ticks = int(round(scenario.duration / scenario.control_period))
    simulator.AdvanceTo((ticks + 1) * scenario.control_period)
    return read_trajectory(diagram, simulator.get_context(), ticks + 1)


def read_log(diagram, context, name, tick_count, shift=0):
    """Tick times `(T,)` and samples `(T, n)` of the first `tick_count` ticks of the logger
    `name`, or (None, None) when the diagram has none.

    Drake dispatches the publish events of an instant (the loggers) before its discrete
    updates, so a logger at `t_k` sees the plant's state at `t_k` but the decisions of tick
    k - 1 (operator, blender, estimator): read those with `shift=1`, one sample later, from
    a simulation run one tick past the last tick read.
    """
    if not diagram.HasSubsystemNamed(name):
        return None, None
    found = diagram.GetSubsystemByName(name).FindLog(context)
    if found.num_samples() < tick_count + shift:
        raise ValueError(f"{name} has {found.num_samples()} samples; "
                         f"{tick_count + shift} are needed")
    return found.sample_times()[:tick_count], found.data().T[shift:shift + tick_count]


def read_trajectory(diagram, context, tick_count):
    """The first `tick_count` ticks of the loggers the builder adds (see `read_log`)."""
    def log(name, shift=0):
        return read_log(diagram, context, name, tick_count, shift)

    times, state = log("robot_state_log")
    dimension = state.shape[1] // 2
    return Trajectory(
        times=times,
        positions=state[:, :dimension],
        velocities=state[:, dimension:],
        operator_active=log("operator_active_log", shift=1)[1][:, 0] > 0.5,
        operator_command=log("operator_command_log", shift=1)[1],
        command=log("command_log", shift=1)[1],
        phase=log("phase_log")[1],
    )
