"""A virtual participant for the HSR tasks: stands in for the paper's users in automated runs."""

import numpy as np

from pbp_drake.core.reach_task import heading_error
from pbp_drake.systems.sampled_operator import SampledOperator

PARTICIPANT_MODES = ("assist", "drive")
# How far the HSR's hand stands in front of its base in the task's start pose (m).
HAND_AHEAD_OF_BASE = 0.53
# Within this distance of the target (m) the participant no longer steps around obstacles.
FINAL_APPROACH = 0.3
# How much closer the arm may pass an obstacle than the base (m).
BASE_WIDER_THAN_ARM = 0.15


class VirtualParticipant(SampledOperator):
    """Sees the true target and the robot, and acts as a person would.

    .. pydrake_system::

        name: VirtualParticipant
        input_ports:
        - ee_state
        - target
        - selected_goal
        - obstacle_positions (optional)
        output_ports:
        - operator_command
        - operator_active

    `mode="assist"` (PBP and arbitration): acts only when needed. While the estimated goal
    (`selected_goal`) is not the target, it turns the end effector toward the target and
    sidesteps toward it; otherwise it lets go. It never pushes forward, as in the paper
    where the forward key is disabled. Facing the target while the estimate is still another
    object (the two almost in line), it steps aside, to the side that widens the angle
    between them, to tell them apart; it sees all the `objects` (M, 3). `mode="drive"` (teleoperation): it drives the whole
    way, toward the target at `speed` (slowing within `slow_radius`), turning to face it.

    It notices a new target only `reaction_delay` seconds after it appears, and its
    commands carry noise: the direction rotated by N(0, `direction_noise`) rad, the speed
    scaled by (1 + N(0, `speed_noise`)). The noise is drawn from `(seed, tick)`, so a run
    is reproducible and the system keeps no state outside its Context.

    With `obstacle_count > 0` it also watches `obstacle_positions` `(N, 2)` and, in every
    mode, steps aside (and backs off when one is close) while an obstacle stands within
    `obstacle_keep_out` of the path its robot will sweep, as people did in the paper.

    Inputs: `ee_state` `[p (3), v (3), heading, heading_rate]`, `target` `[p (3), index]`,
    `selected_goal` `[index]`, `obstacle_positions` (optional). Output `operator_command` is `[vx, vy, vz, yaw_rate]` in the
    world frame (vz = 0).
    """

    def __init__(self, control_period, objects, mode="assist", speed=0.2, rotation_speed=0.6,
                 reaction_delay=0.3, direction_noise=0.1, speed_noise=0.1, seed=0,
                 slow_radius=0.15, aligned_angle=0.05, obstacle_count=0,
                 obstacle_keep_out=0.0, dodge_time=0.5):
        if mode not in PARTICIPANT_MODES:
            raise ValueError(f"participant mode {mode!r} is unknown; use one of "
                             f"{PARTICIPANT_MODES}")
        super().__init__(4, control_period)
        self._mode = mode
        self._objects = np.asarray(objects, dtype=float)
        self._speed = float(speed)
        self._rotation_speed = float(rotation_speed)
        self._reaction_ticks = int(round(reaction_delay / control_period))
        self._direction_noise = float(direction_noise)
        self._speed_noise = float(speed_noise)
        self._seed = int(seed)
        self._slow_radius = float(slow_radius)
        self._aligned_angle = float(aligned_angle)
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", 8)
        self._target_port = self.DeclareVectorInputPort("target", 4)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._obstacle_keep_out = float(obstacle_keep_out)
        self._obstacles_port = None
        self._dodge_ticks = max(1, int(round(dodge_time / control_period)))
        # [ticks of the current sidestep still to go, its direction (2)].
        self._dodge_index = self.DeclareDiscreteState(np.zeros(3))
        if obstacle_count > 0:
            self._obstacles_port = self.DeclareVectorInputPort(
                "obstacle_positions", 2 * int(obstacle_count))
        # What the participant believes: the target index it knows and how many ticks a
        # different target has been on screen.
        self._belief_index = self.DeclareDiscreteState(np.array([-1.0, 0.0]))
        self._declare_operator_outputs()

    def get_ee_state_input_port(self):
        return self._ee_state_port

    def get_target_input_port(self):
        return self._target_port

    def get_selected_goal_input_port(self):
        return self._selected_goal_port

    def get_obstacle_positions_input_port(self):
        return self._obstacles_port

    def _update(self, context, discrete_state):
        # The belief moves first, and the command of this tick acts on the new belief.
        known, unseen_ticks = context.get_discrete_state(self._belief_index).value()
        shown = self._target_port.Eval(context)[3]
        if known < 0:
            known, unseen_ticks = shown, 0  # the first target is known from the start
        elif shown != known:
            unseen_ticks += 1
            if unseen_ticks > self._reaction_ticks:
                known, unseen_ticks = shown, 0
        discrete_state.get_mutable_vector(self._belief_index).set_value([known, unseen_ticks])
        dodge = None
        if self._obstacles_port is not None:
            # A person commits to a sidestep for a moment rather than twitching each tick.
            ticks_left, *direction = context.get_discrete_state(self._dodge_index).value()
            if ticks_left > 0:
                dodge, ticks_left = np.array(direction), ticks_left - 1
            else:
                ee_state = self._ee_state_port.Eval(context)
                dodge = self._dodge(ee_state[:3], ee_state[6],
                                    self._target_port.Eval(context)[:2],
                                    self._obstacles_port.Eval(context).reshape(-1, 2))
                if dodge is not None:
                    ticks_left, direction = self._dodge_ticks - 1, dodge
            discrete_state.get_mutable_vector(self._dodge_index).set_value(
                [ticks_left, *direction])
        command, active = self._decide(context, int(known), dodge)
        self._store_sample(discrete_state, command, active)

    def _aside_direction(self, position, heading, target, selected):
        """+1 (left) or -1: the sidestep that widens the angle between the target and the
        object picked instead, when the two stand almost in line.

        Stepping left by d turns the view of a point at distance r by -d / r, so the gap
        `angle(picked) - angle(target)` changes by `-d (1 / r_picked - 1 / r_target)`.
        """
        picked = self._objects[selected]
        gap = (_apparent_angle(position, heading, picked)
               - _apparent_angle(position, heading, target[:3]))
        closeness = (1.0 / max(np.linalg.norm(picked[:2] - position[:2]), 1e-6)
                     - 1.0 / max(np.linalg.norm(target[:2] - position[:2]), 1e-6))
        direction = -np.sign(gap) * np.sign(closeness)
        return direction if direction != 0 else 1.0

    def _dodge(self, position, heading, target_xy, obstacles):
        """The unit direction that takes the robot off an obstacle's way, or None.

        The robot's footprint runs from its base (about 0.53 m behind the hand) to the
        hand. An obstacle is in the way when its centre comes within `obstacle_keep_out` of
        the path the base will sweep to the target; the participant then steps sideways,
        away from it, and also backs off when the obstacle is already at the hand. Each
        sidestep lasts `dodge_time` at least.
        """
        facing = np.array([np.cos(heading), np.sin(heading)])
        base = position[:2] - HAND_AHEAD_OF_BASE * facing
        path = target_xy - base
        length = np.linalg.norm(path)
        if length < 1e-9:
            return None
        along_unit = path / length
        left = np.array([-along_unit[1], along_unit[0]])
        relative = obstacles - base
        along = relative @ along_unit
        across = relative @ left
        # On the last stretch people push on through.
        if np.linalg.norm(target_xy - position[:2]) < FINAL_APPROACH:
            return None
        # The base stops short of the target by the hand's reach; beyond that only the
        # thinner arm passes.
        keep_out = np.where(along < length - HAND_AHEAD_OF_BASE, self._obstacle_keep_out,
                            max(self._obstacle_keep_out - BASE_WIDER_THAN_ARM, 0.0))
        ahead = (along > -self._obstacle_keep_out) & (along < length)
        blocking = ahead & (np.abs(across) < keep_out)
        if not np.any(blocking):
            return None
        nearest = np.flatnonzero(blocking)[np.argmin(along[blocking])]
        side = -np.sign(across[nearest]) or 1.0
        direction = side * left
        if along[nearest] < HAND_AHEAD_OF_BASE + 0.5 * self._obstacle_keep_out:
            direction = direction - 0.5 * along_unit
        return direction / np.linalg.norm(direction)

    def _decide(self, context, known_target, dodge=None):
        ee_state = self._ee_state_port.Eval(context)
        position, heading = ee_state[:3], ee_state[6]
        target = self._target_port.Eval(context)
        if known_target != int(target[3]):
            return np.zeros(4), False  # has not noticed the new target yet
        angle = heading_error(heading, position, target[:3])
        rng = np.random.default_rng([self._seed, int(round(context.get_time() / self._period))])
        noise_angle = rng.normal(0.0, self._direction_noise)
        speed_scale = max(0.0, 1.0 + rng.normal(0.0, self._speed_noise))
        offset = target[:2] - position[:2]
        distance = np.linalg.norm(offset)
        if dodge is not None:
            if self._mode == "drive" and distance > 1e-9:
                # Keep driving on, around the obstacle.
                dodge = dodge + offset / distance
                dodge /= np.linalg.norm(dodge)
            velocity = self._speed * speed_scale * _rotate(dodge, noise_angle)
            return np.array([velocity[0], velocity[1], 0.0, 0.0]), True
        if self._mode == "assist":
            selected = int(round(self._selected_goal_port.Eval(context)[0]))
            if selected == int(target[3]):
                return np.zeros(4), False
            # Sidestep toward the target: the part of its direction across the heading.
            left = np.array([-np.sin(heading), np.cos(heading)])
            lateral = (offset / max(distance, 1e-9)) @ left
            if abs(angle) <= 2 * self._aligned_angle:
                lateral = 0.5 * self._aside_direction(position, heading, target, selected)
            velocity = self._speed * speed_scale * lateral * _rotate(left, noise_angle)
        else:
            if distance < 1e-9:
                return np.zeros(4), False
            speed = self._speed * speed_scale * min(1.0, distance / self._slow_radius)
            velocity = speed * _rotate(offset / distance, noise_angle)
        yaw_rate = 0.0
        if abs(angle) > self._aligned_angle:
            yaw_rate = np.sign(angle) * self._rotation_speed * min(1.0, abs(angle) / 0.3)
        return np.array([velocity[0], velocity[1], 0.0, yaw_rate]), True


def _apparent_angle(position, heading, point):
    return heading_error(heading, position, point)


def _rotate(vector, angle):
    cos, sin = np.cos(angle), np.sin(angle)
    return np.array([cos * vector[0] - sin * vector[1], sin * vector[0] + cos * vector[1]])
