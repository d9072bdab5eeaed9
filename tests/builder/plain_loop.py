"""Alg. 1 and Alg. 2 of the paper as a plain NumPy loop, no Drake: the oracle for the diagram.

Same timing as the diagram: at tick k the operator reads the robot, the DMP steps from the
robot's state, the blender forms the command, and the robot makes its plant steps.
"""

import numpy as np

from pbp_drake.builder import sinusoidal_step_commands
from pbp_drake.core.arbitration import blend
from pbp_drake.core.dmp import DmpBankModel
from pbp_drake.core.point_robot import MassSpringDamper
from pbp_drake.core.toy_scene import repulsion_command
from pbp_drake.scenarios import (
    METHODS, NoOperator, ObstacleRepulsion, SinusoidalStep, demonstration_samples)


def plain_loop(scenario):
    """Returns the robot's positions (T, D) at the control ticks."""
    period = scenario.control_period
    times, demo = (None, None) if scenario.demonstration is None else (
        demonstration_samples(scenario.demonstration))
    start = np.asarray(scenario.start or demo[0], float)
    goals = np.asarray(scenario.goals or demo[-1:], float)
    robot = MassSpringDamper(scenario.robot.mass, scenario.robot.stiffness,
                             scenario.robot.damping, scenario.robot.time_step)
    plant_steps = int(round(period / scenario.robot.time_step))
    ticks = int(round(scenario.duration / period))
    mode = METHODS[scenario.method].blend_mode
    settings = scenario.dmp
    if demo is not None:
        bank = DmpBankModel.from_demonstration(times, demo, len(goals), settings, start,
                                          scenario.dmp_duration or None)
    else:
        bank = DmpBankModel.straight(start, len(goals), scenario.dmp_duration, settings)
    phase, _, scaled_velocity = bank.initial_state()
    goals_dk = bank.goals_matrix(goals)
    operator = scenario.operator
    if isinstance(operator, SinusoidalStep):
        script_times, script = sinusoidal_step_commands(operator, period, scenario.duration)

    position, velocity = start.copy(), np.zeros_like(start)
    positions = []
    for tick in range(ticks + 1):
        positions.append(position.copy())
        if tick == ticks:
            break
        now = tick * period
        if scenario.method == "pbp_no_user" or isinstance(operator, NoOperator):
            command, active = np.zeros_like(start), False
        elif isinstance(operator, ObstacleRepulsion):
            command, active = repulsion_command(
                position, [o.center for o in scenario.obstacles],
                [o.radius for o in scenario.obstacles], operator.distance_threshold,
                operator.speed, operator.axis or None)
        else:
            index = max(0, int(np.searchsorted(script_times, now, side="right")) - 1)
            command = script[index]
            active = bool(np.any(command != 0))
        if mode == "fixed_alpha":
            reference = [np.interp(now + period, times - times[0], column) for column in demo.T]
            slope = np.gradient(demo, times - times[0], axis=0)
            slope[-1] = 0
            reference_velocity = [np.interp(now + period, times - times[0], column, right=0.0)
                                  for column in slope.T]
            policy_position, policy_velocity = np.array(reference), np.array(reference_velocity)
        else:
            phase, dmp_positions, scaled_velocity = bank.advance(
                phase, position[:, None], scaled_velocity, goals_dk, period,
                locked=active if mode == "pbp_alternated" else None, robot_velocity=velocity)
            policy_position = dmp_positions[:, 0]
            policy_velocity = scaled_velocity[:, 0] / bank.duration
        target, target_velocity = blend(mode, position, policy_position, policy_velocity,
                                        command, active, period, scenario.alpha)
        for _ in range(plant_steps):
            position, velocity = robot.step(position, velocity, target, target_velocity)
    return np.array(positions)
