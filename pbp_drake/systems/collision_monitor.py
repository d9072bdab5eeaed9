"""Whether the robot touches an obstacle, from SceneGraph distance queries."""

from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject
from pydrake.systems.framework import LeafSystem


class CollisionMonitor(LeafSystem):
    """Reports whether any robot geometry overlaps any obstacle geometry.

    .. pydrake_system::

        name: CollisionMonitor
        input_ports:
        - query_object
        output_ports:
        - in_collision
        - clearance

    Connect `query_object` to `scene_graph.get_query_output_port()`. The pairs are queried
    one by one with `ComputeSignedDistancePairClosestPoints`, which ignores collision
    filters: the builder filters robot-obstacle contact out of the plant (the obstacles
    are measured, they do not push), and this monitor still sees the overlap.
    `in_collision` is 1 when some pair's signed distance is negative; `clearance` is the
    smallest signed distance (m).
    """

    def __init__(self, robot_geometry_ids, obstacle_geometry_ids):
        super().__init__()
        self._pairs = [(a, b) for a in robot_geometry_ids for b in obstacle_geometry_ids]
        if not self._pairs:
            raise ValueError("CollisionMonitor needs robot and obstacle geometries")
        self._query_port = self.DeclareAbstractInputPort(
            "query_object", AbstractValue.Make(QueryObject()))
        self._collision_port = self.DeclareVectorOutputPort(
            "in_collision", 1, lambda context, output: output.SetFromVector(
                [1.0 if self._clearance(context) < 0.0 else 0.0]))
        self._clearance_port = self.DeclareVectorOutputPort(
            "clearance", 1,
            lambda context, output: output.SetFromVector([self._clearance(context)]))

    def get_query_object_input_port(self):
        return self._query_port

    def get_in_collision_output_port(self):
        return self._collision_port

    def get_clearance_output_port(self):
        return self._clearance_port

    def _clearance(self, context):
        query = self._query_port.Eval(context)
        return min(query.ComputeSignedDistancePairClosestPoints(a, b).distance
                   for a, b in self._pairs)
