"""Which few of K goals a drawing shows: the selected one and the most probable others."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.ports import PortGetters, checked_count, goal_index


def likely_goal_indices(selected, probabilities, count):
    """`count` goal indices: `selected` first, then the most probable other goals in order
    of decreasing probability (ties by index). O(K) with a partial sort, whatever `count`."""
    probabilities = np.asarray(probabilities, dtype=float)
    others = count - 1
    if others <= 0:
        return np.array([selected])
    # One more than needed, so that `selected` may be among them and still leave `others`.
    candidates = min(others + 1, len(probabilities))
    top = (np.argpartition(-probabilities, candidates - 1)[:candidates]
           if candidates < len(probabilities) else np.arange(len(probabilities)))
    top = top[np.lexsort((top, -probabilities[top]))]
    return np.concatenate([[selected], top[top != selected][:others]])


class LikelyGoals(PortGetters, LeafSystem):
    """The indices of the goals worth drawing: `selected_goal` first, then the `count - 1`
    most probable others (`goal_probabilities`), so that a drawing of their paths costs the
    same whatever the goal count K.

    .. pydrake_system::

        name: LikelyGoals
        input_ports:
        - selected_goal
        - goal_probabilities
        output_ports:
        - goal_indices

    `count` is at most K.
    """

    def __init__(self, goal_count, count):
        super().__init__()
        goal_count = checked_count(goal_count, "goal_count")
        count = checked_count(count, "count")
        if not 1 <= count <= goal_count:
            raise ValueError(f"count must be in [1, {goal_count}] (the goal count), got {count}")
        self._goal_count, self._count = goal_count, count
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._probabilities_port = self.DeclareVectorInputPort("goal_probabilities", goal_count)
        self._indices_port = self.DeclareVectorOutputPort("goal_indices", count, self._calc)

    def _calc(self, context, output):
        selected = goal_index(self._selected_goal_port, context, self._goal_count,
                              unconnected=0)
        probabilities = self._probabilities_port.Eval(context)
        output.SetFromVector(likely_goal_indices(selected, probabilities, self._count))
