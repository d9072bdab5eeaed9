"""The operator system a scenario asks for: scripted or virtual in the 2-D scenes; a person
at the keyboard or gamepad, or the virtual participant, in the tasks (HSR or arm)."""

import numpy as np
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.builder.pilot_operators import make_pilot
from pbp_drake.scenarios import (
    PILOT_CONFIGS, Gamepad, Keyboard, NoOperator, ObstacleRepulsion, ScenarioError,
    ScriptedCommands, SinusoidalStep, VirtualParticipant, forward_key_enabled, shows_intent)
from pbp_drake.core.methods import METHODS
from pbp_drake.core.participant_serving import NO_INTENT
from pbp_drake.systems import (
    GamepadOperator, KeyboardOperator, IdleOperator, ObstacleRepulsionOperator, ScriptedOperator,
    VirtualOperator)
from pbp_drake.systems.operators.pilot_filters import ReachKeys
from pbp_drake.systems.ports import OperatorCommand


def make_operator(scenario, dimension):
    """The operator of a 2-D scene (none at all under a method no operator drives)."""
    config = scenario.operator
    period = scenario.control_period
    if not METHODS[scenario.method].operated or isinstance(config, NoOperator):
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
    """The reaching tasks' operator: a person at the keyboard or gamepad (`make_person`), a
    surrogate pilot, or the virtual participant (`participant_arguments`), which reads the
    keys from its `forward_key` input, as a person sees them."""
    scenario = resolved.scenario
    config = scenario.operator
    period = scenario.control_period
    if not METHODS[scenario.method].operated or isinstance(config, NoOperator):
        return IdleOperator(OperatorCommand.size, period)
    if isinstance(config, PILOT_CONFIGS):  # a surrogate pilot (`scenarios.pilots`)
        return make_pilot(resolved, lambda participant: make_hsr_operator(participant, meshcat),
                          lambda speed, rotation: ReachKeys(speed, rotation, scenario.vertical),
                          len(resolved.station.obstacles))
    if isinstance(config, VirtualParticipant):
        return VirtualOperator(period, resolved.scene.objects, **participant_arguments(resolved))
    if isinstance(config, (Keyboard, Gamepad)):
        return make_person(resolved, meshcat, KeyboardOperator, GamepadOperator,
                           vertical=scenario.vertical)
    raise TypeError(f"unknown operator config {type(config).__name__}")


def make_person(resolved, meshcat, keyboard, gamepad, **keyboard_options):
    """A person in the browser (the scenario's `!Keyboard` or `!Gamepad`, which need
    `meshcat`): the task's `keyboard` or `gamepad` operator class, with the method's keys
    (`forward_key_enabled`: the paper disables forward under PBP and arbitration)."""
    scenario = resolved.scenario
    config = scenario.operator
    if meshcat is None:
        raise ScenarioError(f"operator !{type(config).__name__} reads the browser: it needs "
                            "Meshcat (pbp-drake run without --headless)")
    arguments = (meshcat, scenario.control_period, forward_key_enabled(scenario), config)
    if isinstance(config, Gamepad):
        return gamepad(*arguments, nominal_speed=resolved.nominal_speed)
    return keyboard(*arguments, nominal_speed=resolved.nominal_speed, **keyboard_options)


def participant_arguments(resolved):
    """The virtual participant's arguments beyond the control period and the objects, the
    same under every method."""
    scenario = resolved.scenario
    obstacles = resolved.station.obstacles
    return dict(
        params=scenario.operator, nominal_speed=resolved.nominal_speed, seed=scenario.seed,
        obstacle_count=len(obstacles),
        obstacle_radius=obstacles[0].radius if obstacles else 0.0,
        vertical=scenario.vertical,
        heading_range=_heading_range(resolved),
        fixed_base=resolved.station.base_pose[:2] if resolved.is_arm else None)


def _heading_range(resolved):
    """(low, high) of the hand's heading under the controller's `max_heading_turn` (an
    arm's), or None (the HSR's, unbounded)."""
    turn = resolved.controller.hand_over.max_heading_turn
    if not np.isfinite(turn):
        return None
    heading = resolved.initial_ee_state[6]
    return (heading - turn, heading + turn)


def shown_intent_and_keys(builder, scenario, selected_goal):
    """`(shown_goal, forward_key)` output ports: the robot's intent as the page shows it
    (the estimator's `selected_goal` port, or `NO_INTENT` where the method shows none:
    `shows_intent`) and whether the forward key works (`forward_key_enabled`). The page,
    the logs and the operator all get these, so the virtual participant sees what a
    person does."""
    if not shows_intent(scenario):
        selected_goal = builder.AddNamedSystem(
            "no_intent_shown", ConstantVectorSource([float(NO_INTENT)])).get_output_port()
    keys = builder.AddNamedSystem("keys", ConstantVectorSource(
        [1.0 if forward_key_enabled(scenario) else 0.0]))
    return selected_goal, keys.get_output_port()
