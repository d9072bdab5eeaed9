"""A virtual participant for the HSR tasks: stands in for the paper's users in automated runs."""

import copy
import dataclasses
import math

import numpy as np

from pbp_drake.core.avoidance import (
    WATCH_SIZE, footprint_clearance, is_pushing_through, policy_path, predict_obstacles,
    robot_closes_in, start_watch, update_watch)
from pbp_drake.core.coordinates import is_real, is_whole
from pbp_drake.core.participant_impairment import (
    delay_ticks, first_choice, initial_motor_noise, is_noisy, next_motor_noise)
from pbp_drake.core.participant_reach import (
    assist_motion, can_point_at, drive_motion, faces_target, reposition_motion,
    without_forward)
from pbp_drake.core.participant_serving import (
    NO_INTENT, SERVING_MEMORY_SIZE, ServingMemory, keys_help, robot_pulls, serving_step,
    update_own_motion)
from pbp_drake.core.reach_task import rotate_planar, wrap_angle
from pbp_drake.systems.ports import (
    EeState, OperatorCommand, Target, checked_objects, position_of)
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.systems.operators.sampled_operator import SampledOperator, operator_speed


class ParticipantOperator(SampledOperator):
    """What the virtual participants (`VirtualOperator`, `PoseVirtualOperator`) share, in
    discrete state: their `ServingMemory`, the robot's own motion as they sense it
    (`_sense_own_motion`) and their impairment's motor noise (`_next_noise`)."""

    def _declare_participant(self, impairment, seed, scales):
        """Declares that state, the motor noise of `impairment` at `scales` (one per axis of
        the command; `_noise_scales` None when it has none) drawn from `(seed, tick)`."""
        # `participant_serving.ServingMemory`, and the robot's own motion as it senses it.
        self._serving_index = self.DeclareDiscreteState(np.zeros(SERVING_MEMORY_SIZE))
        self._own_motion_index = self.DeclareDiscreteState(np.zeros(3))
        self._impairment, self._seed = impairment, int(seed)
        self._noise_scales = scales if is_noisy(impairment) else None
        if self._noise_scales is not None:
            self._noise_index = self.DeclareDiscreteState(initial_motor_noise(seed, scales))

    def _sense_own_motion(self, context, discrete_state, params, velocity):
        """The robot's own motion (3) as it perceives it after this tick, the hand moving at
        `velocity` (3)."""
        sent = self._held(context)
        own = update_own_motion(
            params, self._period, context.get_discrete_state(self._own_motion_index).value(),
            velocity, sent[:3] if sent[-1] > 0.5 else np.zeros(3))
        discrete_state.set_value(self._own_motion_index, own)
        return own

    def _next_noise(self, context, discrete_state, tick):
        """The motor noise of control tick `tick`, stored (None without motor noise)."""
        if self._noise_scales is None:
            return None
        noise = next_motor_noise(
            self._impairment, self._period, self._seed, tick,
            context.get_discrete_state(self._noise_index).value(), self._noise_scales)
        discrete_state.set_value(self._noise_index, noise)
        return noise


class VirtualOperator(ParticipantOperator):
    """Sees the true target and the robot, and acts as a person would.

    .. pydrake_system::

        name: VirtualOperator
        input_ports:
        - ee_state
        - target
        - selected_goal
        - forward_key
        - obstacle_positions (with obstacle_count > 0)
        output_ports:
        - operator_command
        - operator_active

    The virtual participant: docs/tasks/reach.md ("The virtual participant") says when it
    acts and what it presses, docs/tasks/obstacles.md how it plans around obstacles, and
    `VirtualParticipantParams` documents each field. It is built from the same arguments
    under every method: `selected_goal` is the robot's shown intent (-1: none) and
    `forward_key` 1 when the method enables the forward key. `objects` (M, 3) is the scene.

    `vertical=True` (a reaching task whose objects stand at different heights) moves in
    3-D, its motor noise shaking vz as a last axis; it is refused with obstacles.
    `heading_range` (low, high) is how far the hand turns (None: all the way, as the HSR's
    base). `fixed_base` (x, y) is a fixed-base arm's base, whose footprint among obstacles
    is the arm from there to the hand (`footprint_clearance`). With `obstacle_count > 0` it
    watches `obstacle_positions` `(N, 2)`, cylinders of `obstacle_radius`, and keeps the
    robot's footprint `obstacle_margin` clear of them. Its noise is drawn from
    `(seed, tick)`, so a run is reproducible and all its state lives in the Context. Its
    `impairment` (`pbp_drake.core.participant_impairment`) adds motor noise, delays its
    commands and makes it head for a wrong object first, now and then.

    Output `operator_command` is `[vx, vy, vz, yaw_rate]` in the world frame (vz = 0
    unless `vertical`).
    """

    def __init__(self, control_period, objects, params=VirtualParticipantParams(),
                 nominal_speed=None, seed=0, obstacle_count=0, obstacle_radius=0.0,
                 obstacle_margin=0.06, vertical=False, heading_range=None, fixed_base=None):
        if not is_whole(obstacle_count):
            raise ValueError(f"obstacle_count must be a whole number >= 0, got "
                             f"{obstacle_count!r}")
        if vertical and obstacle_count > 0:
            raise ValueError(f"vertical=True is for the reaching task; the participant "
                             f"avoids obstacles on the floor only (got obstacle_count "
                             f"{obstacle_count}): use vertical=False with obstacles")
        super().__init__(OperatorCommand.size, control_period)
        if not isinstance(params, VirtualParticipantParams):
            raise ValueError(f"params must be VirtualParticipantParams, got "
                             f"{type(params).__name__}")
        for field in dataclasses.fields(params):
            value = getattr(params, field.name)
            if field.type is float and not (is_real(value) and math.isfinite(value)
                                            and value >= 0):
                raise ValueError(f"params.{field.name} must be finite and not negative, got "
                                 f"{value!r}")
        self._vertical = bool(vertical)
        self._fixed_base = None if fixed_base is None else _base_position(fixed_base)
        if heading_range is not None and not _ordered_pair(heading_range):
            raise ValueError(f"heading_range must be (lowest, highest) finite headings (rad), "
                             f"got {heading_range!r}")
        self._heading_range = None if heading_range is None else tuple(
            float(bound) for bound in heading_range)
        self._objects = checked_objects(objects)
        if not is_whole(seed):
            raise ValueError(f"seed must be a whole number >= 0, got {seed!r}")
        self.params = copy.deepcopy(params)
        self._plan_times = np.array(params.plan_times, dtype=float)
        self._speed = operator_speed(params.speed, nominal_speed)
        self._rotation_speed = float(params.rotation_speed)
        self._reaction_ticks = int(round(params.reaction_delay / control_period))
        # abs: a file's -0.0 passes the check (>= 0), and NumPy's normal refuses its sign.
        self._direction_noise = abs(float(params.direction_noise))
        self._speed_noise = abs(float(params.speed_noise))
        self._slow_radius = float(params.slow_radius)
        impairment = params.impairment
        problem = impairment.problem()
        if problem is not None:
            raise ValueError(f"params.impairment.{problem}")
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._target_port = self.DeclareVectorInputPort("target", Target.size)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._forward_key_port = self.DeclareVectorInputPort("forward_key", 1)
        self._obstacles_port = None
        if obstacle_count > 0 and not (is_real(obstacle_radius)
                                       and 0 < obstacle_radius < math.inf):
            raise ValueError(f"obstacle_radius must be positive with obstacles, got "
                             f"{obstacle_radius}")
        # A NaN margin failed every clearance test, a negative one passed collisions.
        if not (is_real(obstacle_margin) and 0 <= obstacle_margin < math.inf):
            raise ValueError(f"obstacle_margin must be a finite distance >= 0, got "
                             f"{obstacle_margin!r}")
        self._obstacle_radius = float(obstacle_radius)
        self._obstacle_margin = float(obstacle_margin)
        self._release_heading_gap = params.release_heading_gap
        self._hold_ticks = int(round(params.hold_time / control_period))
        if obstacle_count > 0:
            self._obstacles_port = self.DeclareVectorInputPort(
                "obstacle_positions", 2 * int(obstacle_count))
            # [seen (0/1), the hand's start (2), ticks it still keeps control,
            #  the obstacles' positions at the last tick (2N), the stall watch of
            #  `avoidance.update_watch` (WATCH_SIZE)].
            self._track_index = self.DeclareDiscreteState(
                np.zeros(4 + 2 * int(obstacle_count) + WATCH_SIZE))
        # The target index it knows, and how many ticks a different one has been shown.
        self._belief_index = self.DeclareDiscreteState(np.array([-1.0, 0.0]))
        # `_count_insistence`'s [target counted for, ticks facing it, ticks repositioning].
        self._insist_index = self.DeclareDiscreteState(np.array([-1.0, 0.0, 0.0]))
        self._insist_ticks = int(round(params.insist_time / control_period))
        self._reposition_ticks = int(round(params.reposition_time / control_period))
        # The motor noise of `impairment`, [vx, vy, yaw rate] (and vz last when vertical).
        axes = [self._speed, self._speed, self._rotation_speed] + (
            [self._speed] if self._vertical else [])
        self._declare_participant(impairment, seed, impairment.command_noise * np.array(axes))
        # Wrong first choices of target: [targets known so far, the object it heads for
        # instead (-1: none), ticks left before it sees its mistake].
        self._mistakes = impairment.mistake_probability > 0.0
        if self._mistakes:
            self._mistake_index = self.DeclareDiscreteState(np.array([0.0, -1.0, 0.0]))
            self._mistake_ticks = delay_ticks(impairment.mistake_time, control_period)
        self._declare_operator_outputs(delay_ticks(impairment.command_delay, control_period))

    def _forward_key(self, context):
        """Whether the method enables the forward key."""
        return self._forward_key_port.Eval(context)[0] > 0.5

    def _shown_goal(self, context):
        """The object the robot shows it means (`NO_INTENT`: the method shows none)."""
        shown = int(round(self._selected_goal_port.Eval(context)[0]))
        return shown if shown >= 0 else NO_INTENT

    def _update(self, context, discrete_state):
        # The belief moves first; this tick's command acts on the new belief.
        known, unseen_ticks = context.get_discrete_state(self._belief_index).value()
        known_before = known
        shown = Target(self._target_port.Eval(context)).index
        if known < 0:
            known, unseen_ticks = shown, 0  # the first target is known from the start
        elif shown != known:
            unseen_ticks += 1
            if unseen_ticks > self._reaction_ticks:
                known, unseen_ticks = shown, 0
        discrete_state.set_value(self._belief_index, [known, unseen_ticks])
        ee_state = EeState(self._ee_state_port.Eval(context))
        own_motion = self._sense_own_motion(context, discrete_state, self.params,
                                            np.array([ee_state.vx, ee_state.vy, ee_state.vz]))
        # A target it has just come to know: it watches the robot afresh.
        serving = (ServingMemory() if known != known_before else ServingMemory.from_vector(
            context.get_discrete_state(self._serving_index).value()))
        if self._obstacles_port is not None:
            command, active = self._avoid(context, discrete_state, int(known), own_motion,
                                          serving)
            if active and not self._forward_key(context):
                # What the keys allow of its plan, as in the reaching task (`_decide`).
                planar = without_forward(command[:2], ee_state.heading)
                command, active = ((np.array([*planar, 0.0, command[3]]), True)
                                   if keys_help(self.params, command[:2], planar)
                                   else (np.zeros(4), False))
        else:
            heads_for = (self._heads_for(context, discrete_state, int(known))
                         if self._mistakes else int(known))
            command, active = self._decide(context, discrete_state, int(known), heads_for,
                                           own_motion, serving)
        if self._noise_scales is not None:
            command = self._add_motor_noise(context, discrete_state, command, active)
        self._store_sample(discrete_state, command, active)

    def _heads_for(self, context, discrete_state, known):
        """The object it heads for: the known target, or for `mistake_time` after it came
        to know it, the wrong object it chose first (`first_choice`)."""
        count, wrong, ticks_left = context.get_discrete_state(self._mistake_index).value()
        counted_for = context.get_discrete_state(self._belief_index).value()[0]
        if known != counted_for or count == 0:
            # It has just come to know this target (the first one at the start).
            choice = first_choice(self._impairment, self._seed, int(count), known,
                                  len(self._objects))
            count += 1
            wrong, ticks_left = ((choice, self._mistake_ticks) if choice != known
                                 else (-1.0, 0.0))
        heads_for = int(wrong) if ticks_left > 0 else known
        if ticks_left > 0:
            ticks_left -= 1
        discrete_state.set_value(self._mistake_index, [count, wrong, ticks_left])
        return heads_for

    def _add_motor_noise(self, context, discrete_state, command, active):
        """The command with this tick's motor noise added while it acts (the noise runs
        every tick, so one seed gives the same noise under every method)."""
        noise = self._next_noise(context, discrete_state,
                                 int(round(context.get_time() / self._period)))
        if not active:
            return command
        command = np.array(command, dtype=float)
        command[:2] += noise[:2]
        command[3] += noise[2]
        if self._vertical:
            command[2] += noise[3]
        if not self._forward_key(context):
            # The forward key stays disabled, however the hand shakes.
            heading = EeState(self._ee_state_port.Eval(context)).heading
            command[:2] = without_forward(command[:2], heading)
        return command

    def _noise(self, context):
        """This tick's direction error (rad) and speed factor, drawn from `(seed, tick)`."""
        rng = np.random.default_rng([self._seed, int(round(context.get_time() / self._period))])
        return (rng.normal(0.0, self._direction_noise),
                max(0.0, 1.0 + rng.normal(0.0, self._speed_noise)))

    def _avoid(self, context, discrete_state, known_target, own_motion, serving):
        """`(command, active)` while obstacles are about: a local plan around them."""
        ee_state = EeState(self._ee_state_port.Eval(context))
        hand = np.array([ee_state.x, ee_state.y])
        velocity = np.array([ee_state.vx, ee_state.vy])
        heading = ee_state.heading
        target = Target(self._target_port.Eval(context))
        target_xy = np.array([target.x, target.y])
        obstacles = self._obstacles_port.Eval(context).reshape(-1, 2)
        track = np.array(context.get_discrete_state(self._track_index).value())
        count = len(obstacles)
        remembered = slice(4, 4 + 2 * count)
        watch = slice(4 + 2 * count, None)
        if track[0] < 0.5:
            track[0], track[1:3], track[remembered] = 1.0, hand, obstacles.reshape(-1)
            track[watch] = start_watch(np.linalg.norm(target_xy - hand))
        start = track[1:3]
        obstacle_velocity = (obstacles - track[remembered].reshape(count, 2)) / self._period
        hold = track[3]
        track[3] = max(hold - 1.0, 0.0)
        track[remembered] = obstacles.reshape(-1)
        # Its own last decision (the robot gets it later if delayed).
        decided = self._latest(context)
        was_active = decided[4] > 0.5
        last_command = decided[:2] if was_active else np.zeros(2)

        def finish(command, active, hold_ticks=None):
            if hold_ticks is not None:
                track[3] = hold_ticks
            discrete_state.set_value(self._track_index, track)
            return command, active

        if known_target != int(target.index):
            return finish(np.zeros(4), False)
        offset = target_xy - hand
        distance = np.linalg.norm(offset)
        noise_angle, speed_scale = self._noise(context)
        # Where the robot shows its intent it judges the path shown, else the motion seen.
        shows = self._shown_goal(context) != NO_INTENT
        params = self.params
        track[watch] = update_watch(params, track[watch], distance, self._period)
        pushing_through = is_pushing_through(track[watch])
        if not shows:
            act, memory = serving_step(
                params, self._speed, self._period, serving, NO_INTENT,
                known_target, offset, velocity, own_motion[:2])
            discrete_state.set_value(self._serving_index, memory.as_vector())
            if not act:
                return finish(np.zeros(4), False)
        if distance < params.final_approach_radius:
            # The last few centimetres: straight on, whatever stands there; where the robot
            # shows its intent, only when it does not get there by itself.
            if shows and robot_closes_in(params, velocity, offset, self._speed):
                return finish(np.zeros(4), False, 0.0)
            speed = self._speed * speed_scale * min(1.0, distance / self._slow_radius)
            step = speed * rotate_planar(offset / max(distance, 1e-9), noise_angle)
            return finish(np.array([step[0], step[1], 0.0, 0.0]), True)

        predicted = predict_obstacles(obstacles, obstacle_velocity, hand, target_xy,
                                       self._plan_times)
        settled = predict_obstacles(obstacles, obstacle_velocity, hand, target_xy,
                                     np.array([params.settle_time]))[0]
        goal_heading = self._goal_heading(heading, target_xy, settled)
        heading_gap = abs(wrap_angle(heading - goal_heading))
        if shows and not pushing_through:
            # Would the robot, left alone on the path it shows, keep clear?
            policy_clear = footprint_clearance(
                policy_path(hand, start, target_xy, self._speed, self._plan_times), heading,
                predicted, self._obstacle_radius, self._fixed_base).min()
            if was_active:
                release = (hold <= 0 and heading_gap < self._release_heading_gap
                           and policy_clear >= params.release_factor * self._obstacle_margin)
            else:
                moving_clear = footprint_clearance(
                    hand + velocity * self._plan_times[:, None], heading, predicted,
                    self._obstacle_radius, self._fixed_base).min()
                release = (heading_gap < 2 * self._release_heading_gap
                           and min(policy_clear, moving_clear) >= self._obstacle_margin)
            if release:
                return finish(np.zeros(4), False)

        planned, yaw_rate, clear = self._plan(hand, heading, target_xy, predicted,
                                              goal_heading, last_command)
        if pushing_through or (clear < 0.0 and distance < params.push_through_radius):
            # Boxed in next to the target, or no closer for a long while
            # (`avoidance.update_watch`): on through, as people did.
            planned = self._speed * min(1.0, distance / self._slow_radius) * offset / distance
            yaw_rate = 0.0
        command = speed_scale * rotate_planar(planned, noise_angle)
        if robot_pulls(params, self._speed, own_motion):
            command = self._against_policy(context, ee_state, command)
        hold_ticks = track[3] if was_active or not shows else self._hold_ticks
        return finish(np.array([command[0], command[1], 0.0, yaw_rate]), True, hold_ticks)

    def _goal_heading(self, heading, target_xy, obstacles):
        """The heading nearest the present one whose footprint, hand on the target, keeps
        clear of where the obstacles will stand; the clearest one when none does."""
        turns = np.deg2rad(np.arange(-180.0, 180.0, 15.0))
        headings = heading + turns
        clear = footprint_clearance(np.broadcast_to(target_xy, (len(turns), 2)), headings,
                                    np.broadcast_to(obstacles, (len(turns),) + obstacles.shape),
                                    self._obstacle_radius, self._fixed_base)
        fine = clear >= self.params.goal_margin_factor * self._obstacle_margin
        if np.any(fine):
            return headings[fine][np.argmin(np.abs(turns[fine]))]
        return headings[np.argmax(clear)]

    def _plan(self, hand, heading, target_xy, predicted, goal_heading, last_command):
        """The best velocity (2) and yaw rate over a short horizon, and its clearance."""
        params, plan_times = self.params, self._plan_times
        offset = target_xy - hand
        distance = np.linalg.norm(offset)
        toward = offset / max(distance, 1e-9)
        speed = self._speed * min(1.0, max(distance, 0.02) / self._slow_radius)
        angles = np.arctan2(toward[1], toward[0]) + np.linspace(
            0.0, 2 * np.pi, params.plan_directions, endpoint=False)
        directions = np.vstack([np.stack([np.cos(angles), np.sin(angles)], 1), [[0.0, 0.0]]])
        yaw = min(self._rotation_speed, params.max_turn_rate)
        velocities = np.repeat(speed * directions, 3, axis=0)
        yaw_rates = np.tile([0.0, yaw, -yaw], len(directions))
        hands = hand + velocities[:, None, :] * plan_times[None, :, None]
        headings = heading + yaw_rates[:, None] * plan_times[None, :]
        clear = footprint_clearance(hands, headings, predicted[None],
                                    self._obstacle_radius, self._fixed_base).min(axis=1)
        progress = velocities @ toward / self._speed
        gap_now = abs(wrap_angle(heading - goal_heading))
        gap_then = np.abs(wrap_angle(headings[:, -1] - goal_heading))
        turning = (gap_now - gap_then) / (params.max_turn_rate * plan_times[-1])
        last_norm = np.linalg.norm(last_command)
        keep_on = (velocities @ last_command / (self._speed * last_norm) if last_norm > 1e-9
                   else np.zeros(len(velocities)))
        shortfall = np.maximum(self._obstacle_margin - clear, 0.0)
        score = (progress + params.turn_weight * turning + params.keep_on_weight * keep_on
                 - 20.0 * shortfall - 5.0 * (shortfall > 0))
        best = int(np.argmax(score))
        return velocities[best], yaw_rates[best], clear[best]

    def _decide(self, context, discrete_state, known_target, heads_for, own_motion, serving):
        """`(command, active)` in the reaching task, toward object `heads_for` (the known
        target, unless it has mistaken it for another)."""
        ee_state = EeState(self._ee_state_port.Eval(context))
        position, heading = position_of(ee_state), ee_state.heading
        target = Target(self._target_port.Eval(context))
        if known_target != int(target.index):
            # It has not noticed the new target yet: it watches afresh once it has.
            discrete_state.set_value(self._serving_index, ServingMemory().as_vector())
            return np.zeros(4), False
        target_position = position_of(target)
        if heads_for != known_target:
            target_position, known_target = self._objects[heads_for], heads_for
        noise_angle, speed_scale = self._noise(context)
        shown = self._shown_goal(context)
        forward = self._forward_key(context)
        insisting = repositioning = False
        if not forward:
            insisting, repositioning = self._count_insistence(
                context, discrete_state, known_target, shown, position, heading,
                target_position)
        axes = 3 if self._vertical else 2
        velocity_now = np.array([ee_state.vx, ee_state.vy, ee_state.vz])[:axes]
        act, memory = serving_step(
            self.params, self._speed, self._period, serving, shown,
            known_target, (target_position - position)[:axes], velocity_now,
            own_motion[:axes])
        discrete_state.set_value(self._serving_index, memory.as_vector())
        if not act or np.linalg.norm((target_position - position)[:axes]) < 1e-9:
            return np.zeros(4), False
        if not forward and shown not in (NO_INTENT, known_target):
            # No forward key, and the robot means another object: it shows the target.
            if repositioning:
                velocity, yaw_rate = reposition_motion(
                    self.params, self._speed, position, heading, target_position,
                    self._heading_range, vertical=self._vertical)
            else:
                velocity, yaw_rate = assist_motion(
                    self.params, self._speed, position, heading, target_position,
                    self._objects[shown], insisting, vertical=self._vertical,
                    heading_range=self._heading_range)
        else:
            velocity, yaw_rate = drive_motion(self.params, self._speed, position, heading,
                                              target_position, vertical=self._vertical)
            if not forward:
                # Without the forward key, what is left of driving there; when that is
                # little (the target ahead), no key helps and it waits.
                wanted = np.array(velocity, float)
                velocity = wanted.copy()
                velocity[:2] = without_forward(velocity[:2], heading)
                if not keys_help(self.params, wanted, velocity):
                    discrete_state.set_value(self._serving_index, ServingMemory().as_vector())
                    return np.zeros(4), False
        # Going to the target where the robot does not, it pushes against the pull it sees
        # (PBP-Cont's DMP of the picked object keeps pulling the hand there).
        against = (insisting or repositioning) and robot_pulls(self.params, self._speed,
                                                               own_motion)
        # The noise turns the horizontal part and scales all of it (vz with `vertical`).
        command = speed_scale * rotate_planar(velocity, noise_angle)
        if self._vertical:
            command = np.append(command, speed_scale * velocity[2])
        if against:
            command = self._against_policy(context, ee_state, command)
        vz = command[2] if self._vertical else 0.0
        return np.array([command[0], command[1], vz, yaw_rate]), True

    def _against_policy(self, context, ee_state, wanted):
        """The command that moves the hand at `wanted` (2, on the floor; or 3) under an
        additive blend: `wanted` minus the policy's own motion (what the hand does minus
        what was asked of it), at most `policy_compensation` times `speed`."""
        held = self._held(context)
        size = len(wanted)
        last_command = held[:size] if held[4] > 0.5 else np.zeros(size)
        policy_velocity = np.array([ee_state.vx, ee_state.vy, ee_state.vz][:size]) - last_command
        command = wanted - policy_velocity
        norm = np.linalg.norm(command)
        limit = self.params.policy_compensation * self._speed
        if norm > limit:
            command *= limit / norm
        return command

    def _count_insistence(self, context, discrete_state, known_target, selected, position,
                          heading, target_position):
        """`(insisting, repositioning)` while the estimate names another object: it insists
        once it has faced `known_target` `insist_time` or repositioned `reposition_time`, and
        keeps on until a new target appears; it repositions while the tool cannot point at
        the target (`participant_reach.can_point_at`)."""
        counted_target, ticks, moved = context.get_discrete_state(self._insist_index).value()
        if counted_target != known_target:
            counted_target, ticks, moved = known_target, 0.0, 0.0
        insisting = ticks >= self._insist_ticks or moved > self._reposition_ticks
        repositioning = False
        if not insisting and selected != known_target:
            if not can_point_at(self.params, position, target_position, self._heading_range,
                                self._vertical):
                moved += 1.0
                # Its `reposition_time` (0: none) spent, it goes to the target itself.
                insisting = moved > self._reposition_ticks
                repositioning = not insisting
            elif faces_target(self.params, position, heading, target_position):
                ticks += 1.0
        discrete_state.set_value(self._insist_index, [counted_target, ticks, moved])
        return insisting, repositioning


def _base_position(fixed_base):
    """`fixed_base`'s `(x, y)` (a pose's first two entries) as a float array; ValueError
    naming it unless they are two finite numbers."""
    base = np.asarray(fixed_base, float)
    if base.ndim != 1 or base.size < 2 or not np.isfinite(base[:2]).all():
        raise ValueError(f"fixed_base must be the arm's base (x, y), two finite numbers, got "
                         f"{fixed_base!r}")
    return base[:2]


def _ordered_pair(bounds):
    """Whether `bounds` is a pair of finite numbers, the first below the second."""
    try:
        low, high = bounds
    except (TypeError, ValueError):
        return False
    return (is_real(low) and is_real(high) and math.isfinite(low) and math.isfinite(high)
            and low < high)
