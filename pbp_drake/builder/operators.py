"""The operator system a scenario asks for: scripted or virtual in the 2-D scenes; a person
at the keyboard or gamepad, or the virtual participant, in the tasks (HSR or arm)."""

import numpy as np

from pbp_drake.builder.pilot_operators import make_pilot
from pbp_drake.scenarios import (
    PILOT_CONFIGS, OPERATOR_DRIVES, Gamepad, Keyboard, NoOperator, ObstacleRepulsion, ScenarioError,
    ScriptedCommands, SinusoidalStep, VirtualParticipant)
from pbp_drake.systems import (
    GamepadOperator, KeyboardOperator, IdleOperator, ObstacleRepulsionOperator, ScriptedOperator,
    VirtualOperator)
from pbp_drake.systems.operators.pilot_filters import ReachKeys
from pbp_drake.systems.ports import OperatorCommand


def make_operator(scenario, dimension):
    """The operator of a 2-D scene (none at all for PBP-NoUser)."""
    config = scenario.operator
    period = scenario.control_period
    if scenario.method == "pbp_no_user" or isinstance(config, NoOperator):
        return IdleOperator(dimension, period)
    if isinstance(config, ObstacleRepulsion):
        return ObstacleRepulsionOperator(
            [o.center for o in scenario.obstacles], [o.radius for o in scenario.obstacles],
            dimension, period, config)
    if isinstance(config, SinusoidalStep):
        times, commands = sinusoidal_step_commands(config, period, scenario.duration)
        return ScriptedOperator(times, commands, period)
    if isinstance(config, ScriptedCommands):
        return ScriptedOperator(config.times, config.commands, period)
    raise TypeError(f"unknown operator config {type(config).__name__}")


def sinusoidal_step_commands(config, control_period, duration):
    """Samples a SinusoidalStep at the control ticks: times `(T,)`, commands `(T, D)`."""
    times = np.arange(0.0, duration + control_period / 2, control_period)
    elapsed = times - config.start_time
    on = (elapsed >= -1e-12) & (elapsed < config.duration - 1e-12)
    magnitude = np.where(on, config.amplitude * np.sin(2 * np.pi * elapsed / config.period), 0.0)
    axis = np.asarray(config.axis, float)
    return times, np.outer(magnitude, axis / np.linalg.norm(axis))


def make_hsr_operator(resolved, meshcat):
    """The HSR task's operator: a person at the keyboard or gamepad (they need `meshcat`),
    or the virtual participant (which watches the task's obstacles, if any). Under the
    methods of `OPERATOR_DRIVES` (teleop, hop, policy_blending) the operator drives the
    whole way, the forward key enabled; under PBP and arbitration it shows intent without
    it, as the paper's users did."""
    scenario = resolved.scenario
    config = scenario.operator
    period = scenario.control_period
    allow_forward = scenario.method in OPERATOR_DRIVES
    speed = resolved.nominal_speed
    # Objects at heights of their own (`task.z_range`): the operator moves up and down too.
    vertical = bool(getattr(scenario.task, "z_range", None))
    if scenario.method == "pbp_no_user" or isinstance(config, NoOperator):
        return IdleOperator(OperatorCommand.size, period)
    if isinstance(config, PILOT_CONFIGS):  # a surrogate pilot (`scenarios.pilots`)
        return make_pilot(resolved, lambda participant: make_hsr_operator(participant, meshcat),
                          lambda speed, rotation: ReachKeys(speed, rotation, vertical),
                          len(resolved.station.obstacles))
    if isinstance(config, VirtualParticipant):
        obstacles = resolved.station.obstacles
        return VirtualOperator(
            period, resolved.scene.objects, mode="drive" if allow_forward else "assist",
            params=config, nominal_speed=speed, seed=scenario.seed,
            obstacle_count=len(obstacles),
            obstacle_radius=obstacles[0].radius if obstacles else 0.0,
            policy_adds=scenario.method == "pbp_continuous", vertical=vertical,
            heading_range=_heading_range(resolved),
            fixed_base=resolved.station.base_pose[:2] if resolved.is_arm else None)
    if meshcat is None:
        raise ScenarioError(f"operator !{type(config).__name__} reads the browser: it needs "
                            "Meshcat (pbp-drake run without --headless)")
    if isinstance(config, Keyboard):
        return KeyboardOperator(meshcat, period, allow_forward, config, nominal_speed=speed,
                                vertical=vertical)
    if isinstance(config, Gamepad):
        return GamepadOperator(meshcat, period, allow_forward, config, nominal_speed=speed)
    raise TypeError(f"unknown operator config {type(config).__name__}")


def _heading_range(resolved):
    """(low, high) of the hand's heading under the controller's `max_heading_turn` (an
    arm's), or None (the HSR's, unbounded)."""
    turn = resolved.controller.hand_over.max_heading_turn
    if not np.isfinite(turn):
        return None
    heading = resolved.initial_ee_state[6]
    return (heading - turn, heading + turn)
