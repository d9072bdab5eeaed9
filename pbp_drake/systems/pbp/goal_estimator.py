"""The goal estimator as a Drake system: which of K goals the operator means."""

import dataclasses

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.coordinates import vector_length
from pbp_drake.core.goal_estimation import (
    NO_CHALLENGER, GoalEstimatorSettings, SelectionMemory, estimate)
from pbp_drake.systems.ports import EeState, PortGetters, checked_goal_count, position_of
from pbp_drake.systems.tick import checked_period, decide_offset

# Layout of the `memory` discrete state group.
CHALLENGER, COUNT, START, PATH_LENGTH, LAST_POSITION, INITIALISED = 0, 1, 2, 5, 6, 9
MEMORY_SIZE = 10


class GoalEstimator(PortGetters, LeafSystem):
    """Estimates the intended goal every control period (`pbp_drake.core.goal_estimation`).

    .. pydrake_system::

        name: GoalEstimator
        input_ports:
        - ee_state
        - goals
        output_ports:
        - selected_goal
        - goal_probabilities

    `ee_state` is `EeState` (`[p (3), v (3), heading, heading_rate]`); `goals` is the K
    goals flattened row-major `(K, 3)`. `selected_goal` is `[index]` (the goal index as a
    float) and `goal_probabilities` the K probabilities of `settings.method`; both are read
    from the state, so they hold between updates.

    At initialisation (`Simulator.Initialize`) the estimator records the end effector's
    position as the start `S` and selects the most probable goal at once, without
    hysteresis; a Context never initialised does so at its first periodic update instead.
    Each update, at the decide stage of each control tick (`pbp_drake.systems.tick`), adds
    the distance moved since the last update to the path length (for ``bayesian``), recomputes the
    probabilities and moves the selection with hysteresis. Before initialisation the
    selection is goal 0 and the probabilities are uniform.
    """

    def __init__(self, goal_count, settings, control_period):
        super().__init__()
        goal_count = checked_goal_count(goal_count)
        if not isinstance(settings, GoalEstimatorSettings):
            raise ValueError(f"settings must be a GoalEstimatorSettings, got "
                             f"{type(settings).__name__}")
        settings.validate()
        self._goal_count = goal_count
        # A copy: the settings are a plain (mutable) dataclass the caller may change later.
        self._settings = dataclasses.replace(settings)
        self._period = checked_period(control_period)
        k = self._goal_count
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._goals_port = self.DeclareVectorInputPort("goals", 3 * k)
        self._selected_index = self.DeclareDiscreteState(np.zeros(1))
        self._probabilities_index = self.DeclareDiscreteState(np.full(k, 1.0 / k))
        memory = np.zeros(MEMORY_SIZE)
        memory[CHALLENGER] = NO_CHALLENGER
        self._memory_index = self.DeclareDiscreteState(memory)
        self._selected_goal_port = self.DeclareStateOutputPort(
            "selected_goal", self._selected_index)
        self._probabilities_port = self.DeclareStateOutputPort(
            "goal_probabilities", self._probabilities_index)
        self.DeclareInitializationDiscreteUpdateEvent(self._initialise)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, decide_offset(self._period),
                                                self._update)

    @property
    def settings(self):
        return self._settings

    def _inputs(self, context):
        ee_state = EeState(self._ee_state_port.Eval(context))
        # Validated by `estimate` (`goal_probabilities`), which every caller calls.
        goals = self._goals_port.Eval(context).reshape(self._goal_count, 3)
        return position_of(ee_state), float(ee_state.heading), goals

    def _write(self, discrete_state, result, memory):
        memory[CHALLENGER] = result.memory.challenger
        memory[COUNT] = result.memory.count
        # DiscreteValues.set_value: one pybind call a group (get_mutable_vector's: two).
        discrete_state.set_value(self._selected_index, [result.selected])
        discrete_state.set_value(self._probabilities_index, result.probabilities)
        discrete_state.set_value(self._memory_index, memory)

    def _initialise(self, context, discrete_state):
        position, heading, goals = self._inputs(context)
        memory = np.zeros(MEMORY_SIZE)
        memory[START:START + 3] = position
        memory[LAST_POSITION:LAST_POSITION + 3] = position
        memory[INITIALISED] = 1.0
        result = estimate(self._settings, goals, position, heading, None,
                          start=position, path_length=0.0)
        self._write(discrete_state, result, memory)

    def _update(self, context, discrete_state):
        # The context's DiscreteValues read once, each group off it: fewer pybind calls.
        state = context.get_discrete_state()
        memory = state.value(self._memory_index)
        if memory[INITIALISED] < 0.5:
            self._initialise(context, discrete_state)
            return
        position, heading, goals = self._inputs(context)
        memory = memory.copy()
        memory[PATH_LENGTH] += vector_length(position - memory[LAST_POSITION:LAST_POSITION + 3])
        memory[LAST_POSITION:LAST_POSITION + 3] = position
        selected = int(state.value(self._selected_index)[0])
        previous = SelectionMemory(selected, int(memory[CHALLENGER]), int(memory[COUNT]))
        result = estimate(self._settings, goals, position, heading, previous,
                          start=memory[START:START + 3], path_length=memory[PATH_LENGTH])
        self._write(discrete_state, result, memory)
