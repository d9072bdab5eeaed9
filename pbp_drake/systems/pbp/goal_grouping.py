"""Goal groups as a Drake system, between the goal estimator and the DMP bank."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem, ValueProducer

from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.core.goal_groups import group_target
from pbp_drake.systems.ports import PortGetters, checked_goal_count, goal_index


class GoalGrouping(PortGetters, LeafSystem):
    """Steers the selected goal's DMP to the group of goals the estimate cannot yet tell
    apart, and says which goal the robot shows (`pbp_drake.core.goal_groups`).

    .. pydrake_system::

        name: GoalGrouping
        input_ports:
        - goals
        - goal_probabilities
        - selected_goal
        output_ports:
        - followed_goals
        - shown_goal

    `settings` is the estimator's (`GoalEstimatorSettings`: `group_mass`, `commit_radius`,
    `commit_probability`). `goals` is the K goals `(K, 3)` row-major; `goal_probabilities`
    and `selected_goal` are the estimator's. `followed_goals` is `goals` with the selected
    goal's row moved to the group's point while the robot has not committed (what the DMP
    bank steers to); `shown_goal` is `[index]`, the selected goal once committed, else
    `NO_GOAL` (-1). Both come from one computation a change of the inputs (the estimator's
    state: once a tick).
    """

    def __init__(self, goal_count, settings):
        super().__init__()
        self._goal_count = k = checked_goal_count(goal_count)
        if not isinstance(settings, GoalEstimatorSettings):
            raise ValueError(f"settings must be a GoalEstimatorSettings, got "
                             f"{type(settings).__name__}")
        settings.validate()  # a plain dataclass: its fields may have changed since
        self._settings = (float(settings.group_mass), float(settings.commit_radius),
                          float(settings.commit_probability))
        self._goals_port = self.DeclareVectorInputPort("goals", 3 * k)
        self._probabilities_port = self.DeclareVectorInputPort("goal_probabilities", k)
        self._selected_port = self.DeclareVectorInputPort("selected_goal", 1)
        # [followed goals (3 K), shown index]: computed once for both outputs.
        self._target = self.DeclareCacheEntry(
            "followed goals and the shown goal",
            ValueProducer(allocate=lambda: AbstractValue.Make(np.zeros(3 * k + 1)),
                          calc=self._calc_target),
            prerequisites_of_calc={self.all_input_ports_ticket()})
        self.DeclareVectorOutputPort(
            "followed_goals", 3 * k,
            lambda context, output: output.SetFromVector(self._target.Eval(context)[:-1]),
            prerequisites_of_calc={self._target.ticket()})
        self.DeclareVectorOutputPort(
            "shown_goal", 1,
            lambda context, output: output.SetAtIndex(0, self._target.Eval(context)[-1]),
            prerequisites_of_calc={self._target.ticket()})

    def _calc_target(self, context, value):
        goals = self._goals_port.Eval(context).reshape(self._goal_count, 3)
        selected = goal_index(self._selected_port, context, self._goal_count)
        target = group_target(goals, self._probabilities_port.Eval(context), selected,
                              *self._settings)
        result = value.get_mutable_value()
        result[:-1] = goals.reshape(-1)
        result[3 * selected:3 * selected + 3] = target.point
        result[-1] = target.shown
