"""The goal estimator as a Drake system: which of K goals the operator means.
`GoalEstimatorBase` holds what every goal estimator system shares."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.coordinates import vector_length
from pbp_drake.core.goal_estimation import (
    NO_CHALLENGER, GoalEstimatorSettings, SelectionMemory, check_hysteresis,
    goal_probabilities, update_selection)
from pbp_drake.systems.ports import (
    EeState, PortGetters, checked_count, checked_settings, position_of)
from pbp_drake.systems.tick import checked_period, decide_offset

# Layout of the `memory` discrete state group.
CHALLENGER, COUNT, START, PATH_LENGTH, LAST_POSITION, INITIALISED = 0, 1, 2, 5, 6, 9
MEMORY_SIZE = 10


class GoalEstimatorBase(PortGetters, LeafSystem):
    """What the goal estimator systems share: the checked `settings` (a copy, of type
    `_SETTINGS`), the selection's hysteresis (`update_selection`, with `margin` and
    `hold_steps`; None: the settings') and the outputs `selected_goal` (`[index]`, goal 0
    before the first update) and `goal_probabilities` (K, uniform before the first update),
    which hold between updates. The `memory` group starts with `SelectionMemory`'s
    `[challenger, count]`; `memory_size` > 2 leaves room for a subclass's own. A subclass
    declares its input ports in `_declare_inputs(goal_count)` and updates in `_update`, at
    the decide stage of each control tick."""

    _SETTINGS = GoalEstimatorSettings

    def __init__(self, goal_count, settings, control_period, margin=None, hold_steps=None,
                 memory_size=2):
        super().__init__()
        k = self._goal_count = checked_count(goal_count, "goal_count")
        settings = self._settings = checked_settings(settings, self._SETTINGS)
        # Settings without a hysteresis (HOP's, the intent filter's) give None: refused.
        margin = getattr(settings, "margin", None) if margin is None else margin
        hold_steps = getattr(settings, "hold_steps", None) if hold_steps is None else hold_steps
        check_hysteresis(margin, hold_steps)
        self._margin, self._hold_steps = float(margin), int(hold_steps)
        self._period = checked_period(control_period)
        self._declare_inputs(k)
        self._selected_index = self.DeclareDiscreteState(np.zeros(1))
        self._probabilities_index = self.DeclareDiscreteState(np.full(k, 1.0 / k))
        memory = np.zeros(memory_size)
        memory[CHALLENGER] = NO_CHALLENGER
        self._memory_index = self.DeclareDiscreteState(memory)
        self._selected_goal_port = self.DeclareStateOutputPort(
            "selected_goal", self._selected_index)
        self._probabilities_port = self.DeclareStateOutputPort(
            "goal_probabilities", self._probabilities_index)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, decide_offset(self._period),
                                                self._update)

    @property
    def settings(self):
        return self._settings

    @property
    def margin(self):
        return self._margin

    @property
    def hold_steps(self):
        return self._hold_steps

    def _previous(self, state):
        """The `SelectionMemory` in the discrete `state` (the Context's `DiscreteValues`)."""
        challenger, count = state.value(self._memory_index)[:2]
        return SelectionMemory(int(state.value(self._selected_index)[0]), int(challenger),
                               int(count))

    def _select(self, discrete_state, probabilities, previous, memory=None, hold=False):
        """Writes this update's K `probabilities` and the selection moved from `previous`
        (None: the most probable goal at once; with `hold`, kept) into `discrete_state`,
        with `memory`, when given, as the rest of the memory group."""
        if hold:
            selection = SelectionMemory(previous.selected)
        else:
            selection = update_selection(probabilities, previous, self._margin,
                                         self._hold_steps)
        memory = np.zeros(2) if memory is None else memory
        memory[CHALLENGER] = selection.challenger
        memory[COUNT] = selection.count
        # DiscreteValues.set_value: one pybind call a group (get_mutable_vector's: two).
        discrete_state.set_value(self._selected_index, [selection.selected])
        discrete_state.set_value(self._probabilities_index, probabilities)
        discrete_state.set_value(self._memory_index, memory)


class GoalEstimator(GoalEstimatorBase):
    """Estimates the intended goal every control period (`pbp_drake.core.goal_estimation`).

    .. pydrake_system::

        name: GoalEstimator
        input_ports:
        - ee_state
        - goals
        output_ports:
        - selected_goal
        - goal_probabilities

    `ee_state` is `EeState`; `goals` is the K goals flattened row-major `(K, 3)`;
    `goal_probabilities` are those of `settings.method`. At initialisation (or the first
    update of a Context never initialised) it records the hand's position as the start `S`
    and selects the most probable goal at once; each update adds the distance moved to the
    path length (for ``bayesian``) and moves the selection with hysteresis.
    """

    def __init__(self, goal_count, settings, control_period):
        super().__init__(goal_count, settings, control_period, memory_size=MEMORY_SIZE)
        self.DeclareInitializationDiscreteUpdateEvent(self._initialise)

    def _declare_inputs(self, goal_count):
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._goals_port = self.DeclareVectorInputPort("goals", 3 * goal_count)

    def _inputs(self, context):
        ee_state = EeState(self._ee_state_port.Eval(context))
        # Validated by `goal_probabilities`, which every caller calls.
        goals = self._goals_port.Eval(context).reshape(self._goal_count, 3)
        return position_of(ee_state), float(ee_state.heading), goals

    def _initialise(self, context, discrete_state):
        position, heading, goals = self._inputs(context)
        memory = np.zeros(MEMORY_SIZE)
        memory[START:START + 3] = position
        memory[LAST_POSITION:LAST_POSITION + 3] = position
        memory[INITIALISED] = 1.0
        probabilities = goal_probabilities(self._settings, goals, position, heading,
                                           start=position, path_length=0.0)
        self._select(discrete_state, probabilities, None, memory)

    def _update(self, context, discrete_state):
        state = context.get_discrete_state()
        memory = state.value(self._memory_index)
        if memory[INITIALISED] < 0.5:
            self._initialise(context, discrete_state)
            return
        position, heading, goals = self._inputs(context)
        memory = memory.copy()
        memory[PATH_LENGTH] += vector_length(position - memory[LAST_POSITION:LAST_POSITION + 3])
        memory[LAST_POSITION:LAST_POSITION + 3] = position
        probabilities = goal_probabilities(self._settings, goals, position, heading,
                                           start=memory[START:START + 3],
                                           path_length=memory[PATH_LENGTH])
        self._select(discrete_state, probabilities, self._previous(state), memory)
