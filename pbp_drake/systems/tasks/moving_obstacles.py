"""Cylinder obstacles that wake up as the robot progresses and move to cut it off."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.obstacle_task import step_obstacles
from pbp_drake.core.reach_task import reach_progress
from pbp_drake.systems.ports import EeState, PortGetters
from pbp_drake.systems.tick import checked_period, decide_offset


class MovingObstacles(PortGetters, LeafSystem):
    """The behaviour of the dynamic-obstacle task's obstacles: where they are.

    .. pydrake_system::

        name: MovingObstacles
        input_ports:
        - ee_state
        output_ports:
        - obstacle_positions
        - floor_positions

    At the decide stage of every control tick it steps the obstacles
    (`core.obstacle_task.step_obstacles`): each wakes when the hand's progress passes its
    threshold and then moves at `speed` to the midpoint between the hand and the target.
    `obstacle_positions` is `(N, 3)` flattened, the centres of upright cylinders of
    `height` standing on the floor (the HSR station's input); `floor_positions` is `(N, 2)`
    flattened, the same on the floor.
    """

    def __init__(self, scene, start, height, speed, control_period):
        super().__init__()
        self._scene = scene
        self._start = np.asarray(start, dtype=float)
        self._height = float(height)
        self._speed = float(speed)
        self._period = checked_period(control_period)
        count = len(scene.obstacle_starts)
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._positions_index = self.DeclareDiscreteState(scene.obstacle_starts.reshape(-1))
        self._intercepts_index = self.DeclareDiscreteState(scene.obstacle_starts.reshape(-1))
        self._active_index = self.DeclareDiscreteState(np.zeros(count))
        self.DeclareVectorOutputPort(
            "obstacle_positions", 3 * count, self._calc_centres,
            prerequisites_of_calc={self.discrete_state_ticket(self._positions_index)})
        self.DeclareStateOutputPort("floor_positions", self._positions_index)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, decide_offset(self._period),
                                                self._update)

    def _calc_centres(self, context, output):
        floor = context.get_discrete_state(self._positions_index).value().reshape(-1, 2)
        centres = np.column_stack([floor, np.full(len(floor), self._height / 2)])
        output.SetFromVector(centres.reshape(-1))

    def _update(self, context, discrete_state):
        hand = self._ee_state_port.Eval(context)[:3]
        target = self._scene.target
        positions, intercepts, active = step_obstacles(
            context.get_discrete_state(self._positions_index).value().reshape(-1, 2),
            context.get_discrete_state(self._intercepts_index).value().reshape(-1, 2),
            context.get_discrete_state(self._active_index).value() > 0.5,
            reach_progress(hand, self._start, target), hand[:2], target[:2],
            self._scene.thresholds, self._speed, self._period)
        discrete_state.get_mutable_vector(self._positions_index).set_value(positions.reshape(-1))
        discrete_state.get_mutable_vector(self._intercepts_index).set_value(
            intercepts.reshape(-1))
        discrete_state.get_mutable_vector(self._active_index).set_value(active.astype(float))
