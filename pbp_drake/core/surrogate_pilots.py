"""The field's surrogate pilots (docs/concepts/pilots.md: the pilots, their keys and their
sources) in pure NumPy: their parameters, their random draws and how their actions map onto
our keys, a state in {-1, 0, +1} per axis of the operator frame. Every draw comes from
`(seed, tick, stream)` (`tick_uniforms`), as many numbers each tick whatever the method, so
one seed gives the same draws under every method."""

import dataclasses

import numpy as np

from pbp_drake.core.operator_frame import operator_twist, without_forward_twist
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_reach import without_forward
from pbp_drake.core.reach_task import rotate_planar

#: The step rate (Hz) of the sources' environments (LunarLander in Reddy et al., Schaff &
#: Walter and Yoneda et al.): their per-step probabilities are per 1/50 s.
SOURCE_RATE = 50.0

#: The operator frame's key axes of each task: the translations first, then the turns.
REACH_AXES = ("forward", "left", "yaw")
REACH_VERTICAL_AXES = ("forward", "left", "up", "yaw")
GRASP_AXES = ("forward", "left", "up", "yaw", "pitch", "roll")

#: Each pilot's own random stream: the third word of `(seed, tick, stream)`; the
#: participant's own noise draws from `(seed, tick)` and is not disturbed by any of them.
NOISY_STREAM = 1
LAGGY_STREAM = 2
POPULATION_STREAM = 3


@dataclasses.dataclass
class NoisyPilotParams:
    """The noisy pilot: the virtual participant whose output is, each tick with probability
    `eps`, replaced by a uniformly random key state over the keys the method enables."""

    #: The probability (0 to 1) that a tick's output is a random key state (Yoneda et al.'s
    #: Lunar Lander value).
    eps: float = 0.3
    #: The base pilot: the virtual participant's parameters.
    participant: VirtualParticipantParams = dataclasses.field(
        default_factory=VirtualParticipantParams)


@dataclasses.dataclass
class LaggyPilotParams:
    """The laggy pilot: the virtual participant that, each tick with probability
    `lag_per_tick(p, control_period)`, repeats its previous output."""

    #: The probability (0 to 1) per step of the sources' 50 Hz that the previous output is
    #: repeated (Yoneda et al.'s value); converted to our tick by `lag_per_tick`.
    p: float = 0.85
    #: The base pilot: the virtual participant's parameters.
    participant: VirtualParticipantParams = dataclasses.field(
        default_factory=VirtualParticipantParams)


@dataclasses.dataclass
class ProportionalPilotParams:
    """HOP's simulated user: `u = gain (p_goal - p_hand)` clipped to `max_speed`, toward the
    task's target, translation only; it always acts and never reads the robot's intent."""

    #: The proportional gain (1/s; the source's 10).
    gain: float = 10.0
    #: The clip (m/s) of the command's norm; 0 takes the task's operator speed (the
    #: source's 0.25 m/s was its robot's operator speed).
    max_speed: float = 0.0
    #: A command (after the keys) no faster than this (m/s) presses no key: it is then
    #: zero and inactive. 0, the source's: it acts everywhere but on the target.
    dead_zone: float = 0.0


def lag_per_tick(p, control_period):
    """The probability that one tick of `control_period` (s) repeats the previous output,
    for the sources' `p` per 1/50 s step: `p ** (50 control_period)`, so that a held
    output survives time t with the same probability, `p ** (50 t)`, as in the sources."""
    return float(p) ** (SOURCE_RATE * float(control_period))


def tick_uniforms(seed, tick, stream, count):
    """`count` uniform numbers in [0, 1) for one tick of one pilot's `stream`."""
    return np.random.default_rng([int(seed), int(tick), int(stream)]).random(int(count))


def key_state(uniforms, forward_enabled):
    """The key state (one of -1, 0, +1 per axis, as floats) drawn uniformly over the enabled
    states from one uniform number per axis: three states per axis; the first axis
    (forward/back) has two, back and none, when the forward key is disabled
    (`forward_enabled` False and the layout's forward key a button of its own, the
    reaching task's). The same numbers give the same keys on every other axis."""
    uniforms = np.asarray(uniforms, float)
    counts = np.full(len(uniforms), 3)
    if not forward_enabled:
        counts[0] = 2
    return np.floor(uniforms * counts) - 1.0


def noisy_draw(seed, tick, eps, axis_count, forward_enabled):
    """`(corrupted, keys)`: whether this tick's output is replaced (probability `eps`), and
    the key state that replaces it (`key_state`; drawn every tick, so the stream is the
    same under every method)."""
    uniforms = tick_uniforms(seed, tick, NOISY_STREAM, 1 + axis_count)
    return bool(uniforms[0] < eps), key_state(uniforms[1:], forward_enabled)


def laggy_draw(seed, tick, p_tick):
    """Whether this tick repeats the previous output (probability `p_tick`)."""
    return bool(tick_uniforms(seed, tick, LAGGY_STREAM, 1)[0] < p_tick)


def _along(vector, length):
    """`vector` scaled to `length` (zero stays zero): held keys give one direction."""
    norm = np.linalg.norm(vector)
    return vector * (length / norm) if norm > 0 else np.zeros_like(vector, dtype=float)


def reach_key_command(keys, heading, speed, rotation_speed):
    """The reaching task's command `[vx, vy, vz, yaw_rate]` (world frame) of a key state
    over `REACH_AXES` (3) or `REACH_VERTICAL_AXES` (4), the hand at `heading`, and whether
    any key is pressed."""
    keys = np.asarray(keys, float)
    local = np.array([keys[0], keys[1], keys[2] if len(keys) == 4 else 0.0])
    local = _along(local, speed)
    velocity = rotate_planar(local[:2], heading)
    return (np.array([velocity[0], velocity[1], local[2], rotation_speed * keys[-1]]),
            bool(np.any(keys != 0)))


def grasp_key_command(keys, orientation, speed, rotation_speed, forward_enabled):
    """The grasping task's twist `[v (3), omega (3)]` (world frame) of a key state over
    `GRASP_AXES` (6), the hand at `orientation` (unit quaternion), and whether a key is
    pressed whose own motion is not wholly dropped (the forward part along the approach
    axis is, with the forward key disabled)."""
    keys = np.asarray(keys, float)

    def twist(translation, rotation):
        twist = operator_twist(orientation, _along(translation, speed),
                               _along(rotation, rotation_speed))
        return twist if forward_enabled else without_forward_twist(twist, orientation)

    active = any(np.any(np.abs(twist(*np.split(row, 2))) > 1e-12)
                 for row in np.diag(keys) if np.any(row != 0))
    return twist(keys[:3], keys[3:]), bool(active)


def proportional_velocity(params, hand, goal, max_speed):
    """HOP's simulated user's velocity (same size as `hand`, `goal`): `gain (goal - hand)`,
    its norm clipped to `max_speed` (m/s)."""
    velocity = params.gain * (np.asarray(goal, float) - np.asarray(hand, float))
    norm = np.linalg.norm(velocity)
    return velocity * (max_speed / norm) if norm > max_speed else velocity


def reach_proportional_command(params, hand, heading, goal, max_speed, vertical,
                               forward_enabled):
    """The reaching task's command `[vx, vy, vz, 0]` of `proportional_velocity` (floor only
    unless `vertical`; its forward part removed with the forward key disabled,
    `participant_reach.without_forward`), and whether it acts (any motion)."""
    size = 3 if vertical else 2
    velocity = np.zeros(3)
    velocity[:size] = proportional_velocity(params, hand[:size], goal[:size], max_speed)
    if not forward_enabled:
        velocity[:2] = without_forward(velocity[:2], heading)
    return _pressed(np.array([velocity[0], velocity[1], velocity[2], 0.0]), params.dead_zone)


def grasp_proportional_command(params, hand, orientation, goal, max_speed, forward_enabled):
    """The grasping task's twist `[v (3), 0 (3)]` of `proportional_velocity` toward the
    grasp position (its forward part along the approach axis removed with the forward key
    disabled), and whether it acts."""
    twist = np.concatenate([proportional_velocity(params, hand, goal, max_speed),
                            np.zeros(3)])
    if not forward_enabled:
        twist = without_forward_twist(twist, orientation)
    return _pressed(twist, params.dead_zone)


def _pressed(command, dead_zone):
    """`(command, active)`: a command no faster than `dead_zone` presses no key."""
    if np.linalg.norm(command) <= dead_zone:
        return np.zeros_like(command), False
    return command, True

