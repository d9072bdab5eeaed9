"""Simulating a scenario and reading back its time series."""

import dataclasses

import numpy as np
from pydrake.systems.analysis import Simulator

from pbp_drake.builder import build_diagram


@dataclasses.dataclass
class Trajectory:
    """One simulation, sampled at the control ticks.

    Attributes:
        times: (T,). positions, velocities: (T, D) of the robot.
        operator_active: (T,) bools; operator_command: (T, D).
        command: (T, 2 D) the blender's output from each tick on.
        phase: (T, K) DMP phases after each tick's update, or None without DMPs.
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    operator_active: np.ndarray
    operator_command: np.ndarray
    command: np.ndarray
    phase: np.ndarray | None


def simulate(scenario, meshcat=None, realtime_rate=0.0, diagram=None):
    """Simulates `scenario` for its duration and returns its Trajectory."""
    diagram = build_diagram(scenario, meshcat) if diagram is None else diagram
    simulator = Simulator(diagram)
    simulator.set_target_realtime_rate(realtime_rate)
    simulator.Initialize()
    simulator.AdvanceTo(scenario.duration)
    return read_trajectory(diagram, simulator.get_context())


def read_trajectory(diagram, context):
    def log(name):
        if not diagram.HasSubsystemNamed(name):
            return None, None
        sink = diagram.GetSubsystemByName(name)
        found = sink.FindLog(context)
        return found.sample_times(), found.data().T

    times, state = log("robot_state_log")
    dimension = state.shape[1] // 2
    phase = log("phase_log")[1]
    return Trajectory(
        times=times,
        positions=state[:, :dimension],
        velocities=state[:, dimension:],
        operator_active=log("operator_active_log")[1][:, 0] > 0.5,
        operator_command=log("operator_command_log")[1],
        command=log("command_log")[1],
        phase=phase,
    )
