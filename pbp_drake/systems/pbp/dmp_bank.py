"""The DMP bank as a Drake system over the bank's immutable model
(`pbp_drake.core.dmp.DmpBankModel`); its state and scratch arrays live in the Context.
"""

import math

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem, ValueProducer

from pbp_drake.core.coordinates import is_real, is_whole
from pbp_drake.core.dmp import DmpBankModel
from pbp_drake.systems.pbp.dmp_bank_state import AffineState, PerGoalState
from pbp_drake.systems.ports import PortGetters, finite_fields, goal_index
from pbp_drake.systems.tick import checked_period, checked_update_offset


def checked_speed_limit(value, name):
    """`value` (None: no limit) as a float; ValueError, naming it `name`, unless positive."""
    if value is None:
        return None
    if not (is_real(value) and value > 0.0):
        raise ValueError(f"{name} must be positive (None: no limit), got {value!r}")
    return float(value)


def checked_prediction(steps, period):
    """`prediction_steps` as an int >= 0 and `prediction_period` as given (None: the
    default); ValueError naming the one that is not."""
    if not is_whole(steps):
        raise ValueError(f"prediction_steps must be a whole number >= 0, got {steps!r}")
    if period is not None:  # 0 too is refused, not taken for the default
        checked_period(period, "prediction_period")
    return int(steps)


class BankSystem(PortGetters, LeafSystem):
    """What `DmpBank` and `PoseDmpBank` share: the input ports, the step's scratch memory
    in the Context, the operator's phase lock, and the goals followed and selected."""

    def _declare_inputs(self, robot_state_size, goals_name, goals_size):
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", robot_state_size)
        self._goals_port = self.DeclareVectorInputPort(goals_name, goals_size)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._followed_goal_port = self.DeclareVectorInputPort("followed_goal", 1)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)

    def _declare_workspace(self, description, make):
        """The step's scratch, one workspace `make()` per Context. It is never calculated
        nor marked up to date (it depends on nothing and holds nothing between calls), so
        `_workspace` may always take it mutably; a cloned Context deep-copies it."""
        self._workspace_entry = self.DeclareCacheEntry(
            description,
            ValueProducer(allocate=lambda: AbstractValue.Make(make()),
                          calc=self._never_calculated),
            prerequisites_of_calc={self.nothing_ticket()})

    def _workspace(self, context):
        return self._workspace_entry.get_mutable_cache_entry_value(
            context).GetMutableValueOrThrow()

    def _never_calculated(self, context, value):
        raise RuntimeError(f"the {type(self).__name__} workspace is scratch memory, never "
                           "evaluated")

    def _locked(self, context):
        """`lock_phase_when_operator_acts` and a nonzero `operator_active`."""
        return (self._lock and self._operator_active_port.HasValue(context)
                and self._operator_active_port.Eval(context)[0] > 0.5)

    def _followed(self, context, compact):
        """`followed_goal` (None: unconnected), which the compact state needs."""
        followed = goal_index(self._followed_goal_port, context, self._goal_count)
        if followed is None and compact:
            raise RuntimeError(
                f"{type(self).__name__} with compact_state=True steps every DMP from the "
                "followed DMP's velocity: connect its followed_goal input port")
        return followed

    def _selected(self, context):
        """`selected_goal`; unconnected, the followed goal, else goal 0."""
        goal = goal_index(self._selected_goal_port, context, self._goal_count)
        if goal is None:
            goal = goal_index(self._followed_goal_port, context, self._goal_count,
                              unconnected=0)
        return goal


class DmpBank(BankSystem):
    """Steps K DMPs (one per goal) every control period from the robot's measured state.

    .. pydrake_system::

        name: DmpBank
        input_ports:
        - robot_state
        - goals
        - operator_active (optional)
        - followed_goal (optional)
        - selected_goal (optional)
        - predicted_goals (with prediction_steps > 0 and predicted_goal_count)
        output_ports:
        - references
        - selected_reference
        - phase
        - predicted_paths (with prediction_steps > 0)

    `robot_state` is `[position (D), velocity (D)]`; `goals` is K goals flattened row-major
    `(K, D)`. Each period every DMP advances one step from the robot's position;
    docs/concepts/dmp.md ("PBP: re-integrating from the robot every step") explains
    `lock_phase_when_operator_acts` (a nonzero `operator_active` freezes the phase), the
    `followed_goal` input (connected, every DMP steps from the followed DMP's velocity) and
    `max_speed` (m/s, anti-windup).

    `references` is the K next states `[positions (K*D), velocities (K*D)]`;
    `selected_reference` the next state `[position (D), velocity (D)]` of `selected_goal`
    alone (unconnected: the followed goal, else goal 0). `phase` is the K phases.
    `predicted_paths` (with `prediction_steps > 0`) is each DMP's open-loop path,
    `(K, prediction_steps + 1, D)` flattened, every `prediction_period` (default: the
    control period); with `predicted_goal_count` M, the paths of the M goals whose indices
    come in on `predicted_goals` (unconnected: goals 0 to M - 1).

    `compact_state=True` keeps `2 + 6 D` numbers (`state_size`) whatever K, for a bank
    `affine_in_goal` with `followed_goal` connected (docs/concepts/dmp.md). The bank updates
    at the decide stage (`pbp_drake.systems.tick`) or `update_offset` s after each tick.
    """

    def __init__(self, bank, control_period, lock_phase_when_operator_acts=False,
                 prediction_steps=0, update_offset=None, prediction_period=None,
                 max_speed=None, compact_state=False, predicted_goal_count=None):
        super().__init__()
        if not isinstance(bank, DmpBankModel):
            raise ValueError(f"bank must be a DmpBankModel, got {type(bank).__name__}")
        self._bank = bank
        self._max_speed = checked_speed_limit(max_speed, "max_speed")
        self._period = checked_period(control_period)
        self._prediction_steps = checked_prediction(prediction_steps, prediction_period)
        self._prediction_period = float(
            control_period if prediction_period is None else prediction_period)
        self._lock = bool(lock_phase_when_operator_acts)
        update_offset = checked_update_offset(update_offset, self._period)
        k = self._goal_count = bank.goal_count
        d = bank.dimension
        if compact_state and not bank.affine_in_goal:
            raise ValueError(
                "compact_state=True needs DMPs that share weights and start (a bank whose "
                "attractor terms are affine in the goal); this bank's are not: use the "
                "per-goal state (compact_state=False)")
        self._layout = (AffineState if compact_state else PerGoalState)(
            bank, self._period, self._max_speed)
        self._declare_inputs(2 * d, "goals", k * d)
        self._state_fields = [f"{kind}[{i}]" for kind in ("position", "velocity")
                              for i in range(d)]
        self._state_index = self.DeclareDiscreteState(self._layout.initial())
        self._goals_dk = self.DeclareCacheEntry(
            "goals, validated, (D, K) contiguous",
            ValueProducer(allocate=lambda: AbstractValue.Make(np.zeros((d, k))),
                          calc=self._calc_goals_dk),
            prerequisites_of_calc={self._goals_port.ticket()})
        self._declare_workspace("DmpWorkspace: scratch arrays of the bank's step",
                                bank.make_workspace)
        # The outputs depend on the bank's state (and the compact layout's on the goals).
        state = {self.xd_ticket()}
        if self._layout.reads is not None:
            state.add(self._goals_port.ticket())
        self._references_port = self.DeclareVectorOutputPort(
            "references", 2 * k * d, self._calc_references, prerequisites_of_calc=state)
        self._selected_reference_port = self.DeclareVectorOutputPort(
            "selected_reference", 2 * d, self._calc_selected_reference,
            prerequisites_of_calc=state | {self._selected_goal_port.ticket(),
                                           self._followed_goal_port.ticket()})
        self._phase_port = self.DeclareVectorOutputPort(
            "phase", k, self._calc_phase, prerequisites_of_calc={self.xd_ticket()})
        self._predicted_paths_port = self._predicted_goals_port = None
        if self._prediction_steps > 0:
            paths = k
            prerequisites = {self.xd_ticket(), self._goals_port.ticket()}
            if predicted_goal_count is not None:
                if not (is_real(predicted_goal_count) and predicted_goal_count in range(1, k + 1)):
                    raise ValueError(f"predicted_goal_count must be in [1, {k}] (the goal "
                                     f"count), got {predicted_goal_count!r}")
                paths = int(predicted_goal_count)
                self._predicted_goals_port = self.DeclareVectorInputPort(
                    "predicted_goals", paths)
                prerequisites.add(self._predicted_goals_port.ticket())
            self._predicted_paths_port = self.DeclareVectorOutputPort(
                "predicted_paths", paths * (self._prediction_steps + 1) * d,
                self._calc_predicted_paths, prerequisites_of_calc=prerequisites)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, update_offset, self._update)

    @staticmethod
    def state_size(goal_count, dimension, compact_state=False):
        """The length of the one state vector: `2 + D + 3 K D`; compact, `2 + 6 D`."""
        return (AffineState if compact_state else PerGoalState).size_of(goal_count, dimension)

    @property
    def bank(self):
        return self._bank

    def _state(self, context):
        return context.get_discrete_state(self._state_index).get_value()

    def _given(self, context):
        """The goals `(D, K)` where the layout `reads` them, else None."""
        return self._goals_dk.Eval(context) if self._layout.reads == "goals" else None

    def dmp_states(self, context):
        """The K DMPs' state after the last update: phases (K,), positions and scaled
        velocities (D, K), new arrays (what `references` reads out)."""
        state = self._state(context)
        positions, velocity = self._layout.read(state, self._given(context),
                                                self._workspace(context))
        return np.full(self._bank.goal_count, self._layout.phase(state)), positions, velocity

    def selected_reference(self, context):
        """`[position (D), velocity (D)]` of `selected_goal` (unconnected: the followed
        goal, else goal 0) after the last update, a new array."""
        position, velocity = self._layout.read(
            self._state(context), self._given(context), self._workspace(context),
            self._selected(context))
        return np.concatenate([position[:, 0], velocity[:, 0] / self._bank.duration])

    def _update(self, context, discrete_state):
        # Every input before the workspace: an input may reach this system's outputs,
        # which use the same workspace.
        robot_state = self._robot_state_port.EvalAbstract(context).get_value().get_value()
        if not math.isfinite(sum(robot_state.tolist())):
            finite_fields(robot_state, "robot_state", self._state_fields)
        lock = self._locked(context)
        goals_dk = None if lock else self._goals_dk.Eval(context)
        followed = self._followed(context, self._layout.needs_followed_goal)
        self._layout.update(
            discrete_state.get_mutable_vector(self._state_index).get_mutable_value(),
            robot_state, lock, goals_dk, followed, self._workspace(context))

    def _calc_goals_dk(self, context, value):
        goals = self._bank.goals_matrix(self._goals_port.Eval(context))
        value.get_mutable_value()[...] = goals

    def _calc_references(self, context, output):
        _, positions, scaled_velocity = self.dmp_states(context)
        d, k = self._bank.dimension, self._bank.goal_count
        references = output.get_mutable_value().reshape(2, k, d)
        references[0] = positions.T
        np.divide(scaled_velocity.T, self._bank.duration, out=references[1])

    def _calc_selected_reference(self, context, output):
        output.SetFromVector(self.selected_reference(context))

    def _calc_phase(self, context, output):
        output.get_mutable_value()[:] = self._layout.phase(self._state(context))

    def _calc_predicted_paths(self, context, output):
        phase, positions, scaled_velocity = self.dmp_states(context)
        goals = self._goals_dk.Eval(context)
        bank, workspace = self._bank, self._workspace(context)
        if self._predicted_goals_port is not None:
            indices = np.arange(self._predicted_goals_port.size())
            if self._predicted_goals_port.HasValue(context):
                indices = self._predicted_goals_port.Eval(context).astype(int)
            bank, workspace = bank.subset(indices), None  # subset checks the indices
            phase, positions = phase[indices], positions[:, indices]
            scaled_velocity, goals = scaled_velocity[:, indices], goals[:, indices]
        paths = bank.predict(phase, positions, scaled_velocity, goals,
                             self._prediction_period, self._prediction_steps, workspace)
        output.SetFromVector(paths.reshape(-1))

