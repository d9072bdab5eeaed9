"""The virtual participant of the grasping task, in pure NumPy: the reach participant's
honest rules (`pbp_drake.core.participant_reach`, `participant_serving`) with the hand's
orientation. It commands a world-frame twist `[v (3), omega (3)]` (m/s, rad/s): toward the
target's grasp pose with the forward key (`drive_twist`), else turning toward it and
moving along `u_target - u_picked` or insisting (`assist_twist`), never
forward (`without_forward`). Everything is a pure function of its arguments; what it
remembers (`ParticipantMemory`) is passed in and returned. Its behaviour in full:
docs/tasks/grasp.md, "The virtual participant"."""

import copy
import dataclasses
import typing

import numpy as np

from pbp_drake.core.grasp_task import approach_direction
from pbp_drake.core.participant_impairment import ParticipantImpairment, first_choice
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_reach import unit
from pbp_drake.core.participant_serving import (
    NO_INTENT, ServingMemory, keys_help, serving_step)
from pbp_drake.core.quaternion import angle_between, conjugate, exp_map, log_map, multiply

# `ParticipantMemory.known_target` before it has noticed any target.
NO_TARGET = -1


# The reach participant's calibrated defaults, the one home of those this one shares.
_REACH_DEFAULTS = VirtualParticipantParams()
# The fields `VirtualParticipantParams` names otherwise.
_REACH_NAMES = {"slow_angle": "turn_slowdown_angle"}


@dataclasses.dataclass
class GraspParticipantParams:
    """How the grasping task's virtual participant behaves. Every field is one it shares
    with the reach participant (`SHARED_WITH_REACH`), whose calibrated default it takes;
    `speed`, `reaction_delay`, `insist_time`, `hold_time`, `serve_speed_fraction`,
    `serve_patience` and `impairment` mean what `VirtualParticipantParams`' do."""

    speed: float = _REACH_DEFAULTS.speed
    #: How fast it turns the hand (rad/s).
    rotation_speed: float = _REACH_DEFAULTS.rotation_speed
    reaction_delay: float = _REACH_DEFAULTS.reaction_delay
    #: Its velocity's direction is rotated by N(0, direction_noise) rad, its twist scaled by
    #: (1 + N(0, speed_noise)).
    direction_noise: float = _REACH_DEFAULTS.direction_noise
    speed_noise: float = _REACH_DEFAULTS.speed_noise
    #: It slows in proportion within this distance (m) of the grasp position.
    slow_radius: float = _REACH_DEFAULTS.slow_radius
    #: It turns in proportion within this angle (rad) of the grasp orientation (the reach
    #: participant's `turn_slowdown_angle`) ...
    slow_angle: float = _REACH_DEFAULTS.turn_slowdown_angle
    #: ... and stops turning within this angle (rad): well inside the task's 10 degrees.
    aligned_angle: float = _REACH_DEFAULTS.aligned_angle
    insist_time: float = _REACH_DEFAULTS.insist_time
    hold_time: float = _REACH_DEFAULTS.hold_time
    serve_speed_fraction: float = _REACH_DEFAULTS.serve_speed_fraction
    serve_patience: float = _REACH_DEFAULTS.serve_patience
    impairment: ParticipantImpairment = dataclasses.field(
        default_factory=ParticipantImpairment)

    @classmethod
    def from_virtual_participant(cls, params):
        """The grasp participant with the fields a `VirtualParticipantParams` shares with
        it (its `turn_slowdown_angle` is `slow_angle` here)."""
        return cls(**{name: copy.deepcopy(getattr(params, reach_name))
                      for name, reach_name in SHARED_WITH_REACH.items()})

    def validate(self):
        """Raises ValueError naming the first field that cannot be used."""
        problem = self.impairment.problem()
        if problem is not None:
            raise ValueError(f"impairment.{problem}")
        for name in ("rotation_speed", "slow_radius", "slow_angle"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be finite and positive, got {value!r}")
        for name in ("speed", "reaction_delay", "direction_noise", "speed_noise",
                     "aligned_angle", "insist_time", "hold_time", "serve_speed_fraction",
                     "serve_patience"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be finite and not negative, got {value!r}")


#: Each field of `GraspParticipantParams`, by its name in `VirtualParticipantParams`.
SHARED_WITH_REACH = {field.name: _REACH_NAMES.get(field.name, field.name)
                     for field in dataclasses.fields(GraspParticipantParams)}


class ParticipantMemory(typing.NamedTuple):
    """What it remembers between ticks: the target it acts on (`NO_TARGET` before the
    first is noticed), the newest target it has seen and since when (s), since when (s,
    -1: not) it has held the known target's orientation while the estimate named another
    object, and whether it insists; with an impairment's mistakes, how
    many targets it has come to know, the object it heads for instead of the known target
    (`NO_TARGET`: none) and until when (s)."""

    known_target: int = NO_TARGET
    seen_target: int = NO_TARGET
    seen_since: float = 0.0
    facing_since: float = -1.0
    insisting: bool = False
    targets_known: int = 0
    mistaken_for: int = NO_TARGET
    mistaken_until: float = 0.0

    @classmethod
    def from_array(cls, values):
        """The memory a system kept as floats (`np.array(memory, dtype=float)`)."""
        (known, seen, since, facing, insisting, targets_known, mistaken_for,
         mistaken_until) = values
        return cls(int(known), int(seen), float(since), float(facing), bool(insisting),
                   int(targets_known), int(mistaken_for), float(mistaken_until))


def notice_target(memory, true_target, time, reaction_delay):
    """The memory after seeing `true_target` at `time`: a new target becomes the known one
    `reaction_delay` seconds after it first appeared."""
    if int(true_target) != memory.seen_target:
        memory = memory._replace(seen_target=int(true_target), seen_since=float(time))
    # A tick's float time may fall a hair short of the delay it was meant to reach.
    if (time - memory.seen_since >= reaction_delay - 1e-9
            and memory.known_target != memory.seen_target):
        memory = memory._replace(known_target=memory.seen_target, facing_since=-1.0,
                                 insisting=False)
    return memory


def choose_first(impairment, memory, known_before, time, seed, object_count):
    """The memory after a tick that may have made a new target known (`known_before` the
    known target before it): it may first head for another of the `object_count` objects
    (`first_choice`, its `targets_known`-th target) until `mistake_time` has passed; then
    it sees its mistake, and counts its patience (`insist_time`) anew."""
    if memory.known_target != known_before and memory.known_target != NO_TARGET:
        choice = first_choice(impairment, seed, memory.targets_known, memory.known_target,
                              object_count)
        return memory._replace(
            targets_known=memory.targets_known + 1,
            mistaken_for=NO_TARGET if choice == memory.known_target else choice,
            mistaken_until=float(time) + impairment.mistake_time)
    if memory.mistaken_for != NO_TARGET and time >= memory.mistaken_until - 1e-9:
        return memory._replace(mistaken_for=NO_TARGET, facing_since=-1.0, insisting=False)
    return memory


def heads_for(memory, time):
    """The object it heads for: the known target, or the one it mistook it for while its
    mistake lasts."""
    if memory.mistaken_for != NO_TARGET and time < memory.mistaken_until - 1e-9:
        return memory.mistaken_for
    return memory.known_target


def count_insistence(params, memory, time, orientation, target_orientation, selected,
                     target):
    """The memory after a tick in which the estimate names `selected`: it starts insisting
    once it has held the orientation of the object it heads for (`target`; within twice
    `aligned_angle`, as noise moves it) for `insist_time` while `selected` was another
    object (then `assist_twist` without `picked_position`)."""
    if memory.insisting:
        return memory
    if selected == target or angle_between(
            orientation, target_orientation) > 2 * params.aligned_angle:
        return memory._replace(facing_since=-1.0)
    since = memory.facing_since if memory.facing_since >= 0.0 else float(time)
    return memory._replace(facing_since=since,
                           insisting=time - since >= params.insist_time - 1e-9)


def without_forward(velocity, orientation):
    """`velocity` (3) with its component along the approach axis removed when that
    component points forward: what the keys allow with the forward key disabled."""
    ahead = approach_direction(orientation)
    return velocity - max(float(velocity @ ahead), 0.0) * ahead


def turn_toward(params, orientation, goal_orientation):
    """The angular velocity (3, world) that turns `orientation` toward `goal_orientation`:
    `rotation_speed` about the axis of `Log(q_goal q*)`, in proportion within
    `slow_angle`, none within `aligned_angle`."""
    rotation = log_map(multiply(goal_orientation, conjugate(orientation)))
    angle = float(np.linalg.norm(rotation))
    if angle <= params.aligned_angle:
        return np.zeros(3)
    return params.rotation_speed * min(1.0, angle / params.slow_angle) * rotation / angle


def drive_twist(params, speed, position, orientation, grasp_position, grasp_orientation):
    """Teleop: `(v (3), omega (3))` toward the grasp pose, `v` at `speed` slowing within
    `slow_radius`, `omega` as `turn_toward`."""
    offset = np.asarray(grasp_position, float) - position
    distance = float(np.linalg.norm(offset))
    velocity = (np.zeros(3) if distance < 1e-9
                else speed * min(1.0, distance / params.slow_radius) * offset / distance)
    return velocity, turn_toward(params, orientation, grasp_orientation)


def assist_twist(params, speed, position, orientation, target_position, target_orientation,
                 picked_position=None):
    """`(v (3), omega (3))` without the forward key: `omega` toward the target's grasp
    orientation, `v` without a forward part, slowing within `slow_radius`, along
    `u_target - u_picked` while the estimate names `picked_position`, or toward the target's
    grasp position when it is None (insisting)."""
    offset = np.asarray(target_position, float) - position
    direction = offset if picked_position is None else (
        unit(offset) - unit(np.asarray(picked_position, float) - position))
    slow = min(1.0, float(np.linalg.norm(offset)) / params.slow_radius)
    velocity = speed * slow * without_forward(unit(direction), orientation)
    return velocity, turn_toward(params, orientation, target_orientation)


def command_noise(params, seed, tick, velocity):
    """`(velocity (3), scale)`: `velocity` turned by this tick's direction error and the
    factor the whole twist is scaled by, drawn from `(seed, tick)` alone."""
    rng = np.random.default_rng([int(seed), int(tick)])
    # abs: a file's -0.0 passes the check (>= 0), and NumPy's normal refuses its sign.
    angle = rng.normal(0.0, abs(params.direction_noise))
    scale = max(0.0, 1.0 + rng.normal(0.0, abs(params.speed_noise)))
    axis = unit(np.cross(velocity, rng.normal(size=3)))
    if not axis.any():
        return velocity, scale
    turn = exp_map(angle * axis)
    turned = multiply(multiply(turn, np.concatenate([[0.0], velocity])), conjugate(turn))[1:]
    return turned, scale


@dataclasses.dataclass(frozen=True)
class GraspParticipant:
    """The participant of one run: its parameters, speed and seed, and the grasp poses of
    the scene's objects; the same under every method. `step` is a pure function of its
    arguments.

    Attributes:
        params: `GraspParticipantParams`.
        speed: its linear speed (m/s): `params.speed`, or the nominal speed if that is 0.
        grasp_positions: (M, 3), grasp_orientations: (M, 4) the objects' grasp poses.
        seed: the run's seed (noise per tick from `(seed, tick)`).
    """

    params: GraspParticipantParams
    speed: float
    grasp_positions: np.ndarray
    grasp_orientations: np.ndarray
    seed: int = 0

    @classmethod
    def create(cls, params, nominal_speed, grasp_positions, grasp_orientations, seed=0):
        """Checks the arguments (errors name them) and takes the nominal speed when
        `params.speed` is 0."""
        params.validate()
        speed = float(params.speed) if params.speed > 0 else float(nominal_speed)
        if not (np.isfinite(speed) and speed > 0):
            raise ValueError(f"nominal_speed must be finite and positive when params.speed "
                             f"is 0, got {nominal_speed!r}")
        positions = np.asarray(grasp_positions, float)
        orientations = np.asarray(grasp_orientations, float)
        if (positions.ndim != 2 or positions.shape[1] != 3 or len(positions) == 0
                or orientations.shape != (len(positions), 4)):
            raise ValueError(f"grasp_positions must be (M, 3) with M >= 1 and "
                             f"grasp_orientations (M, 4), got shapes {positions.shape} and "
                             f"{orientations.shape}")
        return cls(params, speed, positions, orientations, int(seed))

    @property
    def motor_noise_scales(self):
        """The standard deviation of its motor noise on each axis of its twist
        `[v (3, m/s), omega (3, rad/s)]` (`ParticipantImpairment.command_noise`)."""
        noise = self.params.impairment.command_noise
        return noise * np.repeat([self.speed, self.params.rotation_speed], 3)

    def step(self, memory, serving, time, tick, position, orientation, velocity, own_motion,
             true_target, shown, forward_key, period, motor_noise=None):
        """One tick: `(twist (6,) [v, omega], active, memory, serving)`.

        `memory` (`ParticipantMemory`) and `serving` (`participant_serving.ServingMemory`)
        what it remembers; `time` (s) and `tick` (an integer, the noise's draw) of this
        tick, `period` the control period (s); the hand's `position` (3), `orientation` (4,
        w x y z) and `velocity` (3), and the robot's own motion as it perceives it
        (`own_motion` (3), `participant_serving.update_own_motion`); `true_target` the
        object the task wants; `shown` the robot's shown intent (`NO_INTENT`: none);
        `forward_key` whether the method enables the forward key; `motor_noise` (6, or
        None) this tick's motor noise (`participant_impairment.next_motor_noise`), added
        to its twist while it acts."""
        known_before = memory.known_target
        memory = notice_target(memory, true_target, time, self.params.reaction_delay)
        if self.params.impairment.mistake_probability > 0.0:
            memory = choose_first(self.params.impairment, memory, known_before, time,
                                  self.seed, len(self.grasp_positions))
        if memory.known_target != known_before:
            # A target it has just come to know: it watches the robot afresh, as the reach
            # participant does.
            serving = ServingMemory()
        target = heads_for(memory, time)
        idle = np.zeros(6)
        if target == NO_TARGET:
            return idle, False, memory, ServingMemory()
        position = np.asarray(position, float)
        orientation = np.asarray(orientation, float)
        shown = int(shown) if int(shown) >= 0 else NO_INTENT
        if not forward_key:
            memory = count_insistence(self.params, memory, time, orientation,
                                      self.grasp_orientations[target], shown, target)
        act, serving = serving_step(
            self.params, self.speed, period, serving, shown, target,
            self.grasp_positions[target] - position, velocity, own_motion)
        if not act:
            return idle, False, memory, serving
        if not forward_key and shown not in (NO_INTENT, target):
            picked = None if memory.insisting else self.grasp_positions[shown]
            velocity, angular = assist_twist(
                self.params, self.speed, position, orientation, self.grasp_positions[target],
                self.grasp_orientations[target], picked)
        else:
            velocity, angular = drive_twist(
                self.params, self.speed, position, orientation, self.grasp_positions[target],
                self.grasp_orientations[target])
            if not forward_key:
                # What is left of driving there without the forward key; when that is
                # little (the grasp ahead), no key helps and it waits.
                wanted, velocity = velocity, without_forward(velocity, orientation)
                if not keys_help(self.params, wanted, velocity):
                    return idle, False, memory, ServingMemory()
        if not (velocity.any() or angular.any()):
            return idle, False, memory, serving
        velocity, scale = command_noise(self.params, self.seed, tick, velocity)
        if not forward_key:
            # The noise may turn a sidestep forward; the forward key stays disabled.
            velocity = without_forward(velocity, orientation)
        twist = scale * np.concatenate([velocity, angular])
        if motor_noise is not None:
            twist = twist + np.asarray(motor_noise, float)
            if not forward_key:
                twist[:3] = without_forward(twist[:3], orientation)
        return twist, True, memory, serving
