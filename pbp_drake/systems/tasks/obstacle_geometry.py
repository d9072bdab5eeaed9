"""Cylinder obstacles as SceneGraph geometry, placed by an input port."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import (
    Cylinder, FramePoseVector, GeometryFrame, GeometryInstance, MakePhongIllustrationProperties,
    ProximityProperties)
from pydrake.math import RigidTransform
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.ports import PortGetters

OBSTACLE_RGBA = [0.85, 0.15, 0.15, 1.0]


class CylinderObstacleGeometry(PortGetters, LeafSystem):
    """Upright cylinders registered with a SceneGraph, where `obstacle_positions` puts them.

    .. pydrake_system::

        name: CylinderObstacleGeometry
        input_ports:
        - obstacle_positions
        output_ports:
        - geometry_pose

    Registers one cylinder per `(radius, height)` of `cylinders` with `scene_graph` as the
    source `source_name`, with the proximity role (for distance queries) and the
    illustration role (for Meshcat). `obstacle_positions` is `(N, 3)` flattened: each
    cylinder's centre in the world. Connect `geometry_pose` to
    `scene_graph.get_source_pose_port(source_id)`. `geometry_ids` lists the cylinders'
    geometries, in order.
    """

    def __init__(self, scene_graph, cylinders, source_name="obstacles"):
        super().__init__()
        self.source_id = scene_graph.RegisterSource(source_name)
        self._frame_ids, self.geometry_ids = [], []
        for index, (radius, height) in enumerate(cylinders):
            frame = scene_graph.RegisterFrame(self.source_id, GeometryFrame(f"obstacle_{index}"))
            geometry = scene_graph.RegisterGeometry(self.source_id, frame, GeometryInstance(
                RigidTransform(), Cylinder(radius, height), f"obstacle_{index}"))
            scene_graph.AssignRole(self.source_id, geometry, ProximityProperties())
            scene_graph.AssignRole(self.source_id, geometry,
                                   MakePhongIllustrationProperties(OBSTACLE_RGBA))
            self._frame_ids.append(frame)
            self.geometry_ids.append(geometry)
        self._positions_port = self.DeclareVectorInputPort(
            "obstacle_positions", 3 * len(self._frame_ids))
        self.DeclareAbstractOutputPort(
            "geometry_pose", lambda: AbstractValue.Make(FramePoseVector()), self._calc_poses)

    def _calc_poses(self, context, output):
        centres = np.reshape(self._positions_port.Eval(context), (-1, 3))
        poses = output.get_mutable_value()
        for frame, centre in zip(self._frame_ids, centres):
            poses.set_value(frame, RigidTransform(centre))
