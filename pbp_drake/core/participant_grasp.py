"""The virtual participant of the grasping task, in pure NumPy: the reach participant's
honest rules (`pbp_drake.core.participant_reach`) with the hand's orientation.

It sees the true target (an object index) and notices a new one only `reaction_delay`
seconds after it appears (`notice_target`). It commands a twist `[v (3), omega (3)]`, both
in the world frame (m/s, rad/s):

- teleop (`mode="drive"`): the whole twist, `v` toward the target's grasp position at
  `speed` (slowing in proportion within `slow_radius`), `omega` about the axis of
  `Log(q_target q*)` at `rotation_speed` (in proportion within `slow_angle`; none within
  `aligned_angle`), so that both errors shrink together to the grasp pose.
- PBP and arbitration (`mode="assist"`): nothing while the estimate names the target.
  While it names another object ("picked"), it turns the hand toward the target's grasp
  orientation as when driving (what the ``pose`` estimator's orientation term reads) and
  moves along `u_target - u_picked` (the unit directions from the hand to the two grasp
  positions): the direction in which the distance to the target shrinks fastest against
  the distance to the picked one, i.e. sideways or backward, away from the picked object.
  Any forward part along the hand's approach axis z_H is removed (`without_forward`), as
  with the paper's disabled forward key. Two grasps at one place differ only in
  orientation: it then only turns.
- Once it has held the target's grasp orientation (within twice `aligned_angle`) for
  `insist_time` while the estimate still names another object, it goes to the target
  itself as far as the keys allow, as the reach participant does (`insist_twist`): along
  the direction to the target without its forward part, slowing within `slow_radius`. It
  keeps insisting until a new target appears. (Backing away from the picked object can
  walk the hand off the scene when the target stands behind it.)

Its commands carry noise drawn from `(seed, tick)` (`command_noise`): `v` rotated by
N(0, `direction_noise`) rad about an axis perpendicular to it, the whole twist scaled by
(1 + N(0, `speed_noise`)), clipped at 0. Everything is a pure function of its arguments;
the little it remembers (`ParticipantMemory`) is passed in and returned, so a LeafSystem
keeps it in its discrete state.
"""

import dataclasses
import typing

import numpy as np

from pbp_drake.core.grasp_task import approach_direction
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.quaternion import angle_between, conjugate, exp_map, log_map, multiply

GRASP_PARTICIPANT_MODES = ("assist", "drive")
# `ParticipantMemory.known_target` before it has noticed any target.
NO_TARGET = -1


# The reach participant's calibrated defaults, the one home of those this one
# shares.
_REACH_DEFAULTS = VirtualParticipantParams()
# Each field shared with `VirtualParticipantParams`, by its name there.
SHARED_WITH_REACH = {
    "speed": "speed", "rotation_speed": "rotation_speed", "reaction_delay": "reaction_delay",
    "direction_noise": "direction_noise", "speed_noise": "speed_noise",
    "slow_radius": "slow_radius", "slow_angle": "turn_slowdown_angle",
    "aligned_angle": "aligned_angle", "insist_time": "insist_time"}


@dataclasses.dataclass
class GraspParticipantParams:
    """How the grasping task's virtual participant behaves (module docstring). Every field
    is one it shares with the reach participant (`SHARED_WITH_REACH`) and takes its
    calibrated default from `VirtualParticipantParams`;
    `from_virtual_participant` takes them from a scenario's
    `operator: !VirtualParticipant {...}`."""

    #: Its speed (m/s); 0 takes the task's nominal speed, that of its DMPs.
    speed: float = _REACH_DEFAULTS.speed
    #: How fast it turns the hand (rad/s).
    rotation_speed: float = _REACH_DEFAULTS.rotation_speed
    #: It notices a new target this long (s) after it appears.
    reaction_delay: float = _REACH_DEFAULTS.reaction_delay
    #: Its velocity's direction is rotated by N(0, direction_noise) rad, its twist scaled by
    #: (1 + N(0, speed_noise)).
    direction_noise: float = _REACH_DEFAULTS.direction_noise
    speed_noise: float = _REACH_DEFAULTS.speed_noise
    #: It slows in proportion within this distance (m) of the grasp position.
    slow_radius: float = _REACH_DEFAULTS.slow_radius
    #: It turns in proportion within this angle (rad) of the grasp orientation, so that it
    #: does not overshoot (the reach participant's `turn_slowdown_angle`) ...
    slow_angle: float = _REACH_DEFAULTS.turn_slowdown_angle
    #: ... and stops turning within this angle (rad): well inside the task's 10 degrees.
    aligned_angle: float = _REACH_DEFAULTS.aligned_angle
    #: Assisting, once it has held the target's orientation this long (s) and the estimate
    #: still names another object, it goes to the target itself (`insist_twist`).
    insist_time: float = _REACH_DEFAULTS.insist_time

    @classmethod
    def from_virtual_participant(cls, params):
        """The grasp participant with the fields a `VirtualParticipantParams` shares with
        it (its `turn_slowdown_angle` is `slow_angle` here)."""
        return cls(**{name: getattr(params, reach_name)
                      for name, reach_name in SHARED_WITH_REACH.items()})

    def validate(self):
        """Raises ValueError naming the first field that cannot be used."""
        for name in ("rotation_speed", "slow_radius", "slow_angle"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be finite and positive, got {value!r}")
        for name in ("speed", "reaction_delay", "direction_noise", "speed_noise",
                     "aligned_angle", "insist_time"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be finite and not negative, got {value!r}")


class ParticipantMemory(typing.NamedTuple):
    """What it remembers between ticks: the target it acts on (`NO_TARGET` before the
    first is noticed), the newest target it has seen and since when (s), since when (s,
    -1: not) it has held the known target's orientation while the estimate named another
    object, and whether it insists (`insist_twist`)."""

    known_target: int = NO_TARGET
    seen_target: int = NO_TARGET
    seen_since: float = 0.0
    facing_since: float = -1.0
    insisting: bool = False

    @classmethod
    def from_array(cls, values):
        """The memory a system kept as floats (`np.array(memory, dtype=float)`)."""
        known, seen, since, facing, insisting = values
        return cls(int(known), int(seen), float(since), float(facing), bool(insisting))


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


def count_insistence(params, memory, time, orientation, target_orientation, selected):
    """The memory after a tick in which the estimate names `selected`: it starts insisting
    once it has held the known target's orientation (within twice `aligned_angle`, as noise
    moves it) for `insist_time` while `selected` was another object."""
    if memory.insisting:
        return memory
    if selected == memory.known_target or angle_between(
            orientation, target_orientation) > 2 * params.aligned_angle:
        return memory._replace(facing_since=-1.0)
    since = memory.facing_since if memory.facing_since >= 0.0 else float(time)
    return memory._replace(facing_since=since,
                           insisting=time - since >= params.insist_time - 1e-9)


def unit(vector):
    """`vector` scaled to length 1 (zero stays zero)."""
    norm = np.linalg.norm(vector)
    return vector / norm if norm > 1e-9 else np.zeros_like(vector)


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
    """Teleop: `(v (3), omega (3))` toward the grasp pose (module docstring)."""
    offset = np.asarray(grasp_position, float) - position
    distance = float(np.linalg.norm(offset))
    velocity = (np.zeros(3) if distance < 1e-9
                else speed * min(1.0, distance / params.slow_radius) * offset / distance)
    return velocity, turn_toward(params, orientation, grasp_orientation)


def assist_twist(params, speed, position, orientation, target_position, target_orientation,
                 picked_position):
    """Assisting while the estimate names `picked`: `(v (3), omega (3))`, `v` along
    `u_target - u_picked` without a forward part, `omega` toward the target's grasp
    orientation."""
    offset = np.asarray(target_position, float) - position
    apart = unit(offset) - unit(np.asarray(picked_position, float) - position)
    slow = min(1.0, float(np.linalg.norm(offset)) / params.slow_radius)
    velocity = speed * slow * without_forward(unit(apart), orientation)
    return velocity, turn_toward(params, orientation, target_orientation)


def insist_twist(params, speed, position, orientation, target_position, target_orientation):
    """Insisting: `(v (3), omega (3))`, `v` toward the target's grasp position without a
    forward part, slowing within `slow_radius`, `omega` holding the grasp orientation."""
    offset = np.asarray(target_position, float) - position
    slow = min(1.0, float(np.linalg.norm(offset)) / params.slow_radius)
    velocity = speed * slow * without_forward(unit(offset), orientation)
    return velocity, turn_toward(params, orientation, target_orientation)


def command_noise(params, seed, tick, velocity):
    """`(velocity (3), scale)`: `velocity` turned by this tick's direction error and the
    factor the whole twist is scaled by, drawn from `(seed, tick)` alone."""
    rng = np.random.default_rng([int(seed), int(tick)])
    angle = rng.normal(0.0, params.direction_noise)
    scale = max(0.0, 1.0 + rng.normal(0.0, params.speed_noise))
    axis = unit(np.cross(velocity, rng.normal(size=3)))
    if not axis.any():
        return velocity, scale
    w, x, y, z = exp_map(angle * axis)
    turned = multiply(multiply(np.array([w, x, y, z]), np.concatenate([[0.0], velocity])),
                      conjugate(np.array([w, x, y, z])))[1:]
    return turned, scale


@dataclasses.dataclass(frozen=True)
class GraspParticipant:
    """The participant of one run: its parameters, mode, speed and seed, and the grasp poses
    of the scene's objects. `step` is a pure function of its arguments.

    Attributes:
        params: `GraspParticipantParams`.
        mode: "drive" (teleop) or "assist" (PBP, arbitration).
        speed: its linear speed (m/s): `params.speed`, or the nominal speed if that is 0.
        grasp_positions: (M, 3), grasp_orientations: (M, 4) the objects' grasp poses.
        seed: the run's seed (noise per tick from `(seed, tick)`).
    """

    params: GraspParticipantParams
    mode: str
    speed: float
    grasp_positions: np.ndarray
    grasp_orientations: np.ndarray
    seed: int = 0

    @classmethod
    def create(cls, params, mode, nominal_speed, grasp_positions, grasp_orientations,
               seed=0):
        """Checks the arguments (errors name them) and takes the nominal speed when
        `params.speed` is 0."""
        params.validate()
        if mode not in GRASP_PARTICIPANT_MODES:
            raise ValueError(f"participant mode {mode!r} is unknown; use one of "
                             f"{GRASP_PARTICIPANT_MODES}")
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
        return cls(params, mode, speed, positions, orientations, int(seed))

    def step(self, memory, time, tick, position, orientation, true_target, selected):
        """One tick: `(twist (6,) [v, omega], active, memory)`.

        `time` (s) and `tick` (an integer, the noise's draw) of this tick; the hand's
        `position` (3) and `orientation` (4, w x y z); `true_target` the object the task
        wants; `selected` the estimator's selection (ignored in teleop)."""
        memory = notice_target(memory, true_target, time, self.params.reaction_delay)
        target = memory.known_target
        idle = np.zeros(6)
        if target == NO_TARGET:
            return idle, False, memory
        position = np.asarray(position, float)
        orientation = np.asarray(orientation, float)
        if self.mode == "assist":
            memory = count_insistence(self.params, memory, time, orientation,
                                      self.grasp_orientations[target], int(selected))
            if int(selected) == target:
                return idle, False, memory
            if memory.insisting:
                velocity, angular = insist_twist(
                    self.params, self.speed, position, orientation,
                    self.grasp_positions[target], self.grasp_orientations[target])
            else:
                velocity, angular = assist_twist(
                    self.params, self.speed, position, orientation,
                    self.grasp_positions[target], self.grasp_orientations[target],
                    self.grasp_positions[int(selected)])
        else:
            velocity, angular = drive_twist(
                self.params, self.speed, position, orientation, self.grasp_positions[target],
                self.grasp_orientations[target])
        if not (velocity.any() or angular.any()):
            return idle, False, memory
        velocity, scale = command_noise(self.params, self.seed, tick, velocity)
        if self.mode == "assist":
            # The noise may turn a sidestep forward; the forward key stays disabled.
            velocity = without_forward(velocity, orientation)
        return scale * np.concatenate([velocity, angular]), True, memory
