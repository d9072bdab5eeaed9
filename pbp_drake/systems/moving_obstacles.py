"""Cylinder obstacles that wake up as the robot progresses and move to cut it off."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import (
    Cylinder, FramePoseVector, GeometryFrame, GeometryInstance, MakePhongIllustrationProperties,
    ProximityProperties)
from pydrake.math import RigidTransform
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.obstacle_task import step_obstacles
from pbp_drake.core.reach_task import reach_progress
from pbp_drake.systems.tick import decide_offset

OBSTACLE_RGBA = [0.85, 0.15, 0.15, 1.0]


class MovingObstacles(LeafSystem):
    """The obstacles of the dynamic-obstacle task, as SceneGraph geometry.

    .. pydrake_system::

        name: MovingObstacles
        input_ports:
        - ee_state
        output_ports:
        - geometry_pose
        - obstacle_positions

    Registers one cylinder per obstacle with `scene_graph` (proximity and illustration
    roles; connect `geometry_pose` to `scene_graph.get_source_pose_port(source_id)`).
    Every control period, `update_offset` after the tick (by default the decide stage,
    `pbp_drake.systems.tick.decide_offset`), it computes the hand's progress to
    the target from `ee_state` and steps the obstacles (`core.obstacle_task.step_obstacles`):
    each wakes when the progress passes its threshold and then moves at `speed` to the
    midpoint between the hand and the target, where it stops. `obstacle_positions` is
    `(N, 2)` flattened; all state lives in the Context.
    """

    def __init__(self, scene_graph, scene, start, radius, height, speed, control_period,
                 update_offset=None):
        super().__init__()
        self._scene = scene
        self._start = np.asarray(start, dtype=float)
        self._radius = float(radius)
        self._height = float(height)
        self._speed = float(speed)
        self._period = float(control_period)
        if update_offset is None:
            update_offset = decide_offset(self._period)
        count = len(scene.obstacle_starts)
        self._count = count
        self.source_id = scene_graph.RegisterSource("moving_obstacles")
        self._frame_ids, self.geometry_ids = [], []
        for index in range(count):
            frame = scene_graph.RegisterFrame(self.source_id,
                                              GeometryFrame(f"obstacle_{index}"))
            geometry = scene_graph.RegisterGeometry(self.source_id, frame, GeometryInstance(
                RigidTransform([0.0, 0.0, height / 2]), Cylinder(radius, height),
                f"obstacle_{index}"))
            scene_graph.AssignRole(self.source_id, geometry, ProximityProperties())
            scene_graph.AssignRole(self.source_id, geometry,
                                   MakePhongIllustrationProperties(OBSTACLE_RGBA))
            self._frame_ids.append(frame)
            self.geometry_ids.append(geometry)
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", 8)
        self._positions_index = self.DeclareDiscreteState(scene.obstacle_starts.reshape(-1))
        self._intercepts_index = self.DeclareDiscreteState(scene.obstacle_starts.reshape(-1))
        self._active_index = self.DeclareDiscreteState(np.zeros(count))
        self._pose_port = self.DeclareAbstractOutputPort(
            "geometry_pose", lambda: AbstractValue.Make(FramePoseVector()), self._calc_poses,
            prerequisites_of_calc={self.discrete_state_ticket(self._positions_index)})
        self._positions_port = self.DeclareStateOutputPort(
            "obstacle_positions", self._positions_index)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, update_offset, self._update)

    @property
    def radius(self):
        return self._radius

    def get_ee_state_input_port(self):
        return self._ee_state_port

    def get_geometry_pose_output_port(self):
        return self._pose_port

    def get_obstacle_positions_output_port(self):
        return self._positions_port

    def _calc_poses(self, context, output):
        positions = context.get_discrete_state(self._positions_index).value().reshape(-1, 2)
        poses = output.get_mutable_value()
        for frame, (x, y) in zip(self._frame_ids, positions):
            poses.set_value(frame, RigidTransform([x, y, 0.0]))

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
