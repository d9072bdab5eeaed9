"""The six-DoF DMP bank as a Drake system, over the NumPy banks `DmpBankModel` (D = 3)
and `OrientationDmpBank`."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import ValueProducer

from pbp_drake.core import quaternion
from pbp_drake.core.coordinates import check_positions
from pbp_drake.core.dmp import DmpBankModel, OrientationDmpBank
from pbp_drake.core.dmp.orientation_kernels import jacobian_of_one_values
from pbp_drake.core.dmp.stepping import limit_speeds
from pbp_drake.core.pose_arbitration import PoseReference
from pbp_drake.systems.pbp.dmp_bank import (
    BankSystem, checked_prediction, checked_speed_limit)
from pbp_drake.systems.pbp.pose_dmp_bank_state import (
    AT_START, COMPACT_TAIL_SIZE, HEAD_SIZE, ON_ROBOT, STEPPING, PoseWorkspace, SteppedDmps,
    compact_inputs, hold_into, per_goal_arrays, split_head, step_all)
from pbp_drake.systems.ports import GoalPose, PoseState, finite_pose_state
from pbp_drake.systems.tick import checked_period, checked_update_offset


class PoseDmpBank(BankSystem):
    """Steps K pose DMPs (one per goal pose) every control period from the hand's pose.

    .. pydrake_system::

        name: PoseDmpBank
        input_ports:
        - robot_state
        - goal_poses
        - operator_active (optional)
        - followed_goal (optional)
        - selected_goal (optional)
        output_ports:
        - references
        - selected_reference
        - phase
        - predicted_poses (with prediction_steps > 0)

    docs/concepts/six-dof.md ("The pose DMP bank") tabulates the ports and explains the
    step and the state. Both parts share one phase, so one lock stops both;
    `lock_phase_when_operator_acts`, `followed_goal` and `max_speed` are `DmpBank`'s,
    `max_angular_speed` (rad/s) the angular part's anti-windup limit. `predicted_poses`
    holds `prediction_steps + 1` poses every `prediction_period` (default: the duration over
    `prediction_steps`). The state is 12 K numbers, or 16 with `compact_state=True` (which
    needs `followed_goal` connected). The bank updates at the decide stage of each tick
    (`update_offset` overrides it).
    """

    def __init__(self, position_bank, orientation_bank, control_period,
                 lock_phase_when_operator_acts=False, update_offset=None, max_speed=None,
                 max_angular_speed=None, prediction_steps=0, prediction_period=None,
                 compact_state=False):
        super().__init__()
        _check_banks(position_bank, orientation_bank, control_period)
        self._max_speed = checked_speed_limit(max_speed, "max_speed")
        self._max_angular_speed = checked_speed_limit(max_angular_speed, "max_angular_speed")
        self._positions, self._orientations = position_bank, orientation_bank
        # Equal settings and durations: both parts' steps contract one basis.
        self._shared_basis = (position_bank.settings == orientation_bank.settings
                              and position_bank.duration == orientation_bank.duration)
        self._period = float(control_period)
        self._decay = position_bank.decay(self._period)  # the phase factor of one update
        self._lock = bool(lock_phase_when_operator_acts)
        update_offset = checked_update_offset(update_offset, self._period)
        k = self._goal_count = position_bank.goal_count
        self._declare_inputs(PoseState.size, "goal_poses", k * GoalPose.size)
        self._compact = bool(compact_state)
        initial = np.zeros(self.state_size(k, self._compact))
        phase, held, _, q, _ = split_head(initial)
        phase[0], held[0] = 1.0, AT_START
        q[:, 0] = quaternion.IDENTITY
        if not self._compact:
            per_goal_arrays(initial, k)[0][0] = position_bank.starts  # from p = 0
        self._state_index = self.DeclareDiscreteState(initial)
        self._goals_entry = self.DeclareCacheEntry(
            "goal poses, validated, (7, K): positions then quaternions",
            ValueProducer(allocate=lambda: AbstractValue.Make(np.zeros((GoalPose.size, k))),
                          calc=self._calc_goals),
            prerequisites_of_calc={self._goals_port.ticket()})
        self._declare_workspace("PoseWorkspace: scratch arrays of the banks' step",
                                lambda: PoseWorkspace(position_bank, orientation_bank))
        if self._compact:
            self._stepped_entry = self.DeclareCacheEntry(
                "SteppedDmps: the K DMPs stepped from the compact state, [y' - p, z', e', z'] "
                "(12 K)",
                ValueProducer(allocate=lambda: AbstractValue.Make(SteppedDmps(k)),
                              calc=self._calc_stepped),
                prerequisites_of_calc={self.xd_ticket(), self._goals_entry.ticket()})
        self._references_port = self.DeclareVectorOutputPort(
            "references", k * PoseState.size, self._calc_references,
            prerequisites_of_calc={self.xd_ticket(), self._goals_port.ticket()})
        self._selected_reference_port = self.DeclareVectorOutputPort(
            "selected_reference", PoseState.size, self._calc_selected_reference,
            prerequisites_of_calc={self.xd_ticket(), self._goals_port.ticket(),
                                   self._selected_goal_port.ticket(),
                                   self._followed_goal_port.ticket()})
        self._phase_port = self.DeclareVectorOutputPort(
            "phase", k, self._calc_phase, prerequisites_of_calc={self.xd_ticket()})
        self._prediction_steps = checked_prediction(prediction_steps, prediction_period)
        self._prediction_period = float(
            position_bank.duration / max(self._prediction_steps, 1)
            if prediction_period is None else prediction_period)
        self._predicted_poses_port = None
        if self._prediction_steps > 0:
            self._predicted_poses_port = self.DeclareVectorOutputPort(
                "predicted_poses", (self._prediction_steps + 1) * GoalPose.size,
                self._calc_predicted_poses,
                prerequisites_of_calc={self.xd_ticket(), self._goals_port.ticket(),
                                       self._selected_goal_port.ticket(),
                                       self._followed_goal_port.ticket()})
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, update_offset, self._update)

    @staticmethod
    def state_size(goal_count, compact_state=False):
        """The length of the one state vector (class docstring)."""
        return HEAD_SIZE + (COMPACT_TAIL_SIZE if compact_state else 12 * goal_count)

    @property
    def position_bank(self):
        return self._positions

    def _stepped(self, context, vector):
        """The K DMPs' stepped arrays `[y' - p, z']` and `[e', z']` (2, 3, K): views of
        `vector` per goal, or of the compact layout's cache entry."""
        if self._compact:
            return per_goal_arrays(self._stepped_entry.Eval(context).numbers, self._goal_count)
        return per_goal_arrays(vector, self._goal_count)

    def _goal_numbers(self, context, vector, k):
        """Goal `k`'s stepped numbers `[y' - p (3), z' (3), e' (3), z' (3)]` as 12 floats,
        and the compact layout's `SteppedDmps` they were read from (None per goal)."""
        count = self._goal_count
        if self._compact:
            stepped = self._stepped_entry.Eval(context)
            return stepped.numbers[k::count].tolist(), stepped
        return vector[len(vector) - 12 * count + k::count].tolist(), None

    def _calc_stepped(self, context, value):
        vector = context.get_discrete_state(self._state_index).get_value()
        _, held, robot, q, eta = split_head(vector)
        phase, velocity = compact_inputs(vector)
        result = value.get_mutable_value()
        result.eta_goal = -1  # the numbers change below
        stepped, log_state = per_goal_arrays(result.numbers, self._goal_count)
        if held[0] != STEPPING:
            hold_into(held[0], robot, velocity, self._positions.starts, stepped)
            return
        step_all(self._positions, self._orientations, self._shared_basis, phase, robot, q,
                 velocity, eta, self._goals_entry.Eval(context), self._period, stepped,
                 log_state, self._workspace(context))

    def _calc_goals(self, context, value):
        rows = np.asarray(self._goals_port.Eval(context), dtype=float).reshape(
            self._goal_count, GoalPose.size)
        check_positions(rows[:, :3], "goal_poses position")
        orientations = quaternion.unit_quaternions(rows[:, 3:], "goal_poses orientation")
        goals = value.get_mutable_value()
        goals[:3] = rows[:, :3].T
        goals[3:] = orientations.T
        self._workspace(context).goals_changed = True

    def _robot(self, context):
        """The measured position (3,), orientation (4,), velocity (3,) and angular velocity
        (3,), checked."""
        state = finite_pose_state(self._robot_state_port.Eval(context), "robot_state")
        norm = quaternion.unit_norm(state[3:7], "robot_state orientation")
        return state[:3], state[3:7] / norm, state[7:10], state[10:13]

    def _update(self, context, discrete_state):
        vector = discrete_state.get_mutable_value(self._state_index)
        # Every input before the workspace (an input may reach this system's outputs).
        hand = self._robot(context)
        lock = self._locked(context)
        goals = self._goals_entry.Eval(context)
        followed = self._followed(context, self._compact)
        if self._compact:
            self._update_compact(context, vector, hand, lock, followed)
        else:
            self._update_per_goal(context, vector, hand, lock, goals, followed)

    def _update_compact(self, context, vector, hand, lock, followed):
        """The compact state's update: what the next step starts from, no work of size K."""
        phase, held, robot, q, eta = split_head(vector)
        # The tail: the phase and `z` the last step started from.
        step_phase, step_velocity = compact_inputs(vector)
        position, orientation, velocity, angular_velocity = hand
        if held[0] == STEPPING:
            # Every DMP continues from the followed DMP's velocities at the end of the last
            # step; its eta = J(e') z' is the last selected reference's when the same goal.
            numbers, stepped = self._goal_numbers(context, vector, followed)
            step_velocity[:, 0] = numbers[3:6]
            eta[:, 0] = (stepped.eta if stepped.eta_goal == followed
                         else jacobian_of_one_values(numbers[6:9], numbers[9:12]))
            limit_speeds(step_velocity, self._max_speed, self._positions.duration)
            limit_speeds(eta, self._max_angular_speed, self._orientations.duration)
        robot[:, 0] = position
        q[:, 0] = orientation
        if lock:
            # Both phases frozen: the DMPs sit at the hand's pose and follow its twist.
            held[0] = ON_ROBOT
            eta[:, 0] = angular_velocity * self._orientations.duration
            np.multiply(velocity[:, np.newaxis], self._positions.duration, out=step_velocity)
            return
        held[0] = STEPPING
        step_phase[0] = phase[0]
        phase *= self._decay

    def _update_per_goal(self, context, vector, hand, lock, goals, followed):
        """The per-goal state's update: every DMP stepped into the state."""
        positions, orientations, period = self._positions, self._orientations, self._period
        phase, held, robot, q, eta_state = split_head(vector)
        stepping = held[0] == STEPPING
        position, orientation, velocity, angular_velocity = hand
        stepped, log_state = self._stepped(context, vector)
        offsets, velocities = stepped
        workspace = self._workspace(context)
        # The velocities the step starts from: the followed DMP's (one column), else each's.
        if followed is not None:
            scaled_velocity, eta = workspace.column, workspace.eta_column
            if stepping:
                numbers = self._goal_numbers(context, vector, followed)[0]
                scaled_velocity[:, 0] = numbers[3:6]
                eta[:, 0] = jacobian_of_one_values(numbers[6:9], numbers[9:12])
            else:
                scaled_velocity[:, 0] = velocities[:, followed]
                eta[...] = eta_state  # the robot's (locked) or 0 (at the start)
        else:
            scaled_velocity = workspace.velocities
            np.copyto(scaled_velocity, velocities)
            if stepping:
                orientations.orientations_from_log_into(
                    log_state[0], log_state[1], goals[3:], q,
                    workspace.orientations, workspace.eta, workspace.orientation)
                eta = workspace.eta
            else:
                eta = np.array(eta_state)
        if stepping:
            limit_speeds(scaled_velocity, self._max_speed, positions.duration)
            limit_speeds(eta, self._max_angular_speed, orientations.duration)
        robot[:, 0] = position
        q[:, 0] = orientation
        if lock:
            # Both phases frozen: the DMPs sit at the hand's pose and follow its twist.
            held[0] = ON_ROBOT
            eta_state[:, 0] = angular_velocity * orientations.duration
            offsets.fill(0.0)
            np.multiply(velocity[:, np.newaxis], positions.duration, out=velocities)
            return
        held[0] = STEPPING
        step_all(positions, orientations, self._shared_basis, phase, robot, q,
                 scaled_velocity, eta, goals, period, stepped, log_state, workspace)
        phase *= self._decay

    def dmp_states(self, context):
        """The K DMPs after the last update: phases (K,), positions (3, K), orientations
        (4, K), and the scaled velocities `tau v` and `tau omega` (3, K), new arrays."""
        vector = context.get_discrete_state(self._state_index).get_value()
        phase, held, robot, q, eta_held = split_head(vector)
        k = self._goal_count
        (offsets, velocities), log_state = self._stepped(context, vector)
        rotations = np.empty((4, k))
        eta = np.empty((3, k))
        if held[0] != STEPPING:
            rotations[...] = self._orientations.starts if held[0] == AT_START else q
            eta[...] = eta_held
        else:
            goals = self._goals_entry.Eval(context)
            self._orientations.orientations_from_log_into(
                log_state[0], log_state[1], goals[3:], q, rotations, eta,
                self._workspace(context).orientation)
        return np.full(k, phase[0]), robot + offsets, rotations, np.array(velocities), eta

    def _calc_references(self, context, output):
        _, stepped, rotations, velocity, eta = self.dmp_states(context)
        rows = output.get_mutable_value().reshape(self._goal_count, PoseState.size)
        rows[:, :3] = stepped.T
        rows[:, 3:7] = rotations.T
        rows[:, 7:10] = velocity.T / self._positions.duration
        rows[:, 10:13] = eta.T / self._orientations.duration

    def selected_reference(self, context):
        """The `PoseReference` of `selected_goal` (unconnected: the followed goal, else 0)."""
        return PoseReference.from_vector(self._selected_numbers(context))

    def _selected_numbers(self, context):
        """`selected_reference`'s 13 numbers (`PoseState`'s layout) as floats (at one goal,
        cheaper than NumPy calls)."""
        k = self._selected(context)
        vector = context.get_discrete_state(self._state_index).get_value()
        head = vector[:HEAD_SIZE].tolist()  # [phase, held, p (3), q (4), eta (3)]
        numbers, stepped = self._goal_numbers(context, vector, k)
        tau, tau_w = self._positions.duration, self._orientations.duration
        position = [p + offset for p, offset in zip(head[2:5], numbers[0:3])]
        velocity = [value / tau for value in numbers[3:6]]
        held = head[1]
        if held != STEPPING:
            start = self._orientations.starts[:, k].tolist() if held == AT_START else head[5:9]
            return position + start + velocity + [value / tau_w for value in head[9:12]]
        goal = self._goals_entry.Eval(context)[3:, k].tolist()
        rotation = quaternion.exp_times_aligned_values(numbers[6:9], goal, head[5:9])
        eta = jacobian_of_one_values(numbers[6:9], numbers[9:12])
        if stepped is not None:
            # The next update reuses it when this goal is the followed one (`SteppedDmps`).
            stepped.eta_goal, stepped.eta = k, eta
        return position + rotation + velocity + [value / tau_w for value in eta]

    def _calc_selected_reference(self, context, output):
        output.get_mutable_value()[:] = self._selected_numbers(context)

    def _calc_phase(self, context, output):
        phase = split_head(context.get_discrete_state(self._state_index).get_value())[0]
        output.get_mutable_value()[:] = phase[0]

    def _calc_predicted_poses(self, context, output):
        k = self._selected(context)
        phase, positions, orientations, velocity, eta = self.dmp_states(context)
        goals = self._goals_entry.Eval(context)[:, [k]]
        # The selected DMP alone is rolled out: the same path, at a cost independent of K.
        dt, steps = self._prediction_period, self._prediction_steps
        path = self._positions.subset([k]).predict(
            phase[[k]], positions[:, [k]], velocity[:, [k]], goals[:3], dt, steps)[0]
        turns = self._orientations.subset([k]).predict(
            phase[[k]], orientations[:, [k]], eta[:, [k]], goals[3:], dt, steps)[0]
        output.SetFromVector(np.hstack([path, turns]).reshape(-1))


def _check_banks(position_bank, orientation_bank, control_period):
    """The two banks must describe the same K goals with one phase."""
    for name, bank, kind in [("position_bank", position_bank, DmpBankModel),
                             ("orientation_bank", orientation_bank, OrientationDmpBank)]:
        if not isinstance(bank, kind):
            raise ValueError(f"{name} must be {kind.__name__}, got {type(bank).__name__}")
    if position_bank.dimension != 3:
        raise ValueError(f"the position bank must be 3-D, got D = {position_bank.dimension}")
    if position_bank.goal_count != orientation_bank.goal_count:
        raise ValueError(f"the banks have {position_bank.goal_count} and "
                         f"{orientation_bank.goal_count} goals; a pose bank needs one count")
    period = checked_period(control_period)
    if position_bank.decay(period) != orientation_bank.decay(period):
        raise ValueError("the position and orientation banks must share one phase: give them "
                         "the same duration and alpha_x")
