"""Whether the robot touches an obstacle, from SceneGraph distance queries."""

from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.ports import PortGetters


class CollisionMonitor(PortGetters, LeafSystem):
    """Reports the robot's clearance to the obstacles and whether it touches one.

    .. pydrake_system::

        name: CollisionMonitor
        input_ports:
        - query_object
        output_ports:
        - in_collision
        - clearance

    Connect `query_object` to `scene_graph.get_query_output_port()`. The pairs are queried
    one by one with `ComputeSignedDistancePairClosestPoints`, which ignores collision
    filters: robot-obstacle contact is filtered out of the plant (the obstacles are
    measured, they do not push), and this monitor still sees the overlap.
    `clearance` is the smallest signed distance over the pairs (m); `in_collision` is 1
    when it is negative.
    """

    def __init__(self, robot_geometry_ids, obstacle_geometry_ids):
        super().__init__()
        self._pairs = [(a, b) for a in robot_geometry_ids for b in obstacle_geometry_ids]
        if not self._pairs:
            raise ValueError("CollisionMonitor needs robot and obstacle geometries")
        self._query_port = self.DeclareAbstractInputPort(
            "query_object", AbstractValue.Make(QueryObject()))
        self.DeclareVectorOutputPort(
            "in_collision", 1, self._calc_in_collision)
        self._clearance_port = self.DeclareVectorOutputPort(
            "clearance", 1, self._calc_clearance)

    def _calc_clearance(self, context, output):
        query = self._query_port.Eval(context)
        output.SetAtIndex(0, min(query.ComputeSignedDistancePairClosestPoints(a, b).distance
                                 for a, b in self._pairs))

    def _calc_in_collision(self, context, output):
        output.SetAtIndex(0, 1.0 if self._clearance_port.Eval(context)[0] < 0.0 else 0.0)
