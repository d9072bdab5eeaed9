"""The DMP bank as a Drake system: K DMPs re-integrated each control step from the robot."""

import numpy as np
from pydrake.systems.framework import LeafSystem


class DmpBank(LeafSystem):
    """Steps K DMPs (one per goal) every control period from the robot's measured state.

    .. pydrake_system::

        name: DmpBank
        input_ports:
        - robot_state
        - goals
        - operator_active (optional)
        output_ports:
        - references
        - phase
        - predicted_paths

    `robot_state` is `[position (D), velocity (D)]`; `goals` is K goals flattened row-major
    `(K, D)`. Each period the bank advances every DMP one exact step from the robot's position
    (keeping each DMP's own velocity, see `pbp_drake.core.dmp`). With
    `lock_phase_when_operator_acts` (PBP-Alt), a nonzero `operator_active` freezes the phases
    and the DMPs follow the robot until the operator lets go.

    `references` is the K next states `[positions (K*D), velocities (K*D)]`, `phase` the K
    phases; `predicted_paths` (declared when `prediction_steps > 0`) is each DMP's open-loop
    path from its current state, `(K, prediction_steps + 1, D)` flattened, for drawing,
    sampled every `prediction_period` (default: the control period).
    All state lives in the Context.

    The bank updates `update_offset` seconds after each control tick. Discrete updates at
    one instant all see the values from before that instant, so a bank updating exactly at
    the tick would lock on the operator's decision of the previous tick; a small offset
    (the builder uses a quarter of the plant step, before the plant moves) lets it lock on
    the decision of the same tick, as Alg. 2 does.
    """

    def __init__(self, bank, control_period, lock_phase_when_operator_acts=False,
                 prediction_steps=0, update_offset=0.0, prediction_period=None):
        super().__init__()
        self._bank = bank
        self._period = float(control_period)
        # Drawing a long horizon at the control period would cost hundreds of steps a frame;
        # the exact zero-order-hold step is as exact at any step size.
        self._prediction_period = float(prediction_period or control_period)
        self._lock = bool(lock_phase_when_operator_acts)
        self._prediction_steps = int(prediction_steps)
        k, d = bank.goal_count, bank.dimension
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", 2 * d)
        self._goals_port = self.DeclareVectorInputPort("goals", k * d)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        phase, positions, scaled_velocity = bank.initial_state()
        self._phase_index = self.DeclareDiscreteState(phase)
        self._position_index = self.DeclareDiscreteState(positions.reshape(-1))
        self._velocity_index = self.DeclareDiscreteState(scaled_velocity.reshape(-1))
        # The outputs depend on the bank's own state (and the goals) only: say so, so that
        # Drake does not recompute them after every plant step.
        self._references_port = self.DeclareVectorOutputPort(
            "references", 2 * k * d, self._calc_references,
            prerequisites_of_calc={self.xd_ticket()})
        self._phase_port = self.DeclareStateOutputPort("phase", self._phase_index)
        self._predicted_paths_port = None
        if self._prediction_steps > 0:
            self._predicted_paths_port = self.DeclareVectorOutputPort(
                "predicted_paths", k * (self._prediction_steps + 1) * d,
                self._calc_predicted_paths,
                prerequisites_of_calc={self.xd_ticket(),
                                       self._goals_port.ticket()})
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, update_offset, self._update)

    @property
    def bank(self):
        return self._bank

    def get_robot_state_input_port(self):
        return self._robot_state_port

    def get_goals_input_port(self):
        return self._goals_port

    def get_operator_active_input_port(self):
        return self._operator_active_port

    def get_references_output_port(self):
        return self._references_port

    def get_phase_output_port(self):
        return self._phase_port

    def get_predicted_paths_output_port(self):
        return self._predicted_paths_port

    def _state(self, context):
        """Read-only views of the phase (K,), positions and scaled velocities (D, K)."""
        d, k = self._bank.dimension, self._bank.goal_count
        return (context.get_discrete_state(self._phase_index).get_value(),
                context.get_discrete_state(self._position_index).get_value().reshape(d, k),
                context.get_discrete_state(self._velocity_index).get_value().reshape(d, k))

    def _update(self, context, discrete_state):
        # Ports are read through views (no copies) and the step is written straight into the
        # discrete state's vectors, which Drake fills with the current state beforehand.
        bank = self._bank
        d, k = bank.dimension, bank.goal_count
        robot_state = self._robot_state_port.EvalAbstract(context).get_value().get_value()
        goals = bank.goals_matrix(self._goals_port.EvalAbstract(context).get_value().get_value())
        locked = None
        if self._lock and self._operator_active_port.HasValue(context):
            locked = bool(self._operator_active_port.Eval(context)[0] > 0.5)
        phase = discrete_state.get_mutable_vector(self._phase_index).get_mutable_value()
        positions = discrete_state.get_mutable_vector(
            self._position_index).get_mutable_value().reshape(d, k)
        scaled_velocity = discrete_state.get_mutable_vector(
            self._velocity_index).get_mutable_value().reshape(d, k)
        bank.advance_into(phase, robot_state[:d, np.newaxis], scaled_velocity, goals,
                          self._period, phase, positions, scaled_velocity,
                          locked=locked, robot_velocity=robot_state[d:])

    def _calc_references(self, context, output):
        _, positions, scaled_velocity = self._state(context)
        d, k = self._bank.dimension, self._bank.goal_count
        references = output.get_mutable_value().reshape(2, k, d)
        references[0] = positions.T
        np.divide(scaled_velocity.T, self._bank.duration, out=references[1])

    def _calc_predicted_paths(self, context, output):
        phase, positions, scaled_velocity = self._state(context)
        goals = self._bank.goals_matrix(self._goals_port.Eval(context))
        paths = self._bank.predict(phase, positions, scaled_velocity, goals,
                                   self._prediction_period, self._prediction_steps)
        output.SetFromVector(paths.reshape(-1))
