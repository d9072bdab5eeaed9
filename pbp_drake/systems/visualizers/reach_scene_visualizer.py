"""Draws the reaching task in Meshcat: objects, every goal's probability as one point cloud,
the target, the estimated goal, and the DMP paths of the selected and the likeliest goals."""

import numpy as np
from pydrake.geometry import Box, Cylinder, Rgba, Sphere
from pydrake.math import RigidTransform
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.scene_framing import workspace_view
from pbp_drake.systems.ports import EeState, PortGetters, Target, checked_objects, position_of
from pbp_drake.systems.tick import checked_period
from pbp_drake.systems.visualizers.scene_drawing import (GoalCloud, PathDots, PathTrail,
                                                         Visibility)

OBJECT_COLOUR = Rgba(0.55, 0.35, 0.2, 1.0)
TABLE_COLOUR = Rgba(0.8, 0.75, 0.65, 1.0)
# Pure, saturated colours so that a screenshot can find them.
TARGET_COLOUR = Rgba(1.0, 0.9, 0.0, 1.0)
ESTIMATE_COLOUR = Rgba(0.1, 0.3, 1.0, 1.0)
ACTIVE_PATH_COLOUR = Rgba(0.1, 0.3, 1.0, 1.0)
OTHER_PATH_COLOUR = Rgba(0.1, 0.3, 1.0, 0.2)
# Dots per path: a replay keeps every dot's position at every path update.
PATH_DOTS = 24
# The marker at the hand (shown while the operator acts): a replay's track of the hand's
# path (`pbp-drake teach --from` reads it).
HAND_MARKER = "/task/operator"
# The hand's trail (with `hand_trail`): dots 2 cm apart (`PathTrail`: 4 cm after 8 m).
TRAIL_DOT_RADIUS, TRAIL_SPACING = 0.01, 0.02
TRAIL_COLOUR = Rgba(0.2, 0.75, 0.3, 0.9)
ACTIVE_DOT_RADIUS, OTHER_DOT_RADIUS = 0.012, 0.008
OPERATOR_COLOUR = Rgba(1.0, 0.45, 0.0, 0.6)
# Up to this many objects are drawn as tables and cylinders; more are the goal cloud alone.
SOLID_OBJECTS = 100
# The goal cloud's points float just above the objects' tops, at most the size of an object
# (smaller when many objects stand close: `cloud_point_size`).
CLOUD_LIFT, CLOUD_POINT_SIZE = 0.07, 0.05

OBJECT_RADIUS = 0.03
OBJECT_HEIGHT = 0.1
# Markers float above the objects: the target's yellow ball, and higher the estimate's blue.
TARGET_LIFT = 0.12
ESTIMATE_LIFT = 0.25


class TaskMarkers:
    """The HSR tasks' yellow ball above the target object (`/task/target`) and blue ball
    above the estimated goal's (`/task/estimated_goal`, hidden while none is shown)."""

    def __init__(self):
        self._estimate = Visibility("/task/estimated_goal")

    def draw(self, meshcat):
        meshcat.SetObject("/task/target", Sphere(0.06), TARGET_COLOUR)
        meshcat.SetObject("/task/estimated_goal", Sphere(0.045), ESTIMATE_COLOUR)
        self._estimate.forget()

    def show(self, meshcat, target, estimate, time):
        """Moves the balls above `target` (3) and `estimate` (3; None: no ball)."""
        meshcat.SetTransform("/task/target", RigidTransform(target + [0, 0, TARGET_LIFT]), time)
        self._estimate.show(meshcat, estimate is not None, time)
        if estimate is not None:
            meshcat.SetTransform("/task/estimated_goal",
                                 RigidTransform(estimate + [0, 0, ESTIMATE_LIFT]), time)


class ReachSceneVisualizer(PortGetters, LeafSystem):
    """Publishes the reaching task's markers to Meshcat under `/task`.

    .. pydrake_system::

        name: ReachSceneVisualizer
        input_ports:
        - target
        - selected_goal
        - operator_active (optional)
        - ee_state (optional)
        - predicted_paths (optional)
        - goal_probabilities (optional)

    At each initialisation (after deleting `/task`) the objects are drawn on small tables
    (up to `SOLID_OBJECTS`) and as the goal cloud `/task/goal_cloud` (`GoalCloud`), whose
    colours follow `goal_probabilities` (K) each `cloud_period`. Each publish moves the
    `TaskMarkers` and shows an orange ring around the hand while the operator acts. Each
    `path_period` the `path_count` paths on `predicted_paths` (each `prediction_steps + 1`
    points, the selected goal's first) are drawn as `PathDots`: the first bold
    `/task/predictions/selected`, the others faint `/task/predictions/likely/{i}`. All with
    `time_in_recording`, so that a recording replays them. The camera (`camera`,
    `(position, target)`) stands behind and above the HSR, or is framed on the robot's
    `workspace` (points `(N, 3)`, `workspace_view`). Call from the thread that made
    `meshcat`.
    """

    def __init__(self, meshcat, objects, prediction_steps=0, path_count=1,
                 publish_period=1.0 / 30.0, path_period=0.1, cloud_period=0.25,
                 workspace=None, hand_trail=False):
        super().__init__()
        self._meshcat = meshcat
        self._objects = checked_objects(objects)
        checked_period(publish_period, "publish_period")
        self.camera = (behind_the_robot(self._objects) if workspace is None
                       else workspace_view(workspace))
        self._markers = TaskMarkers()
        self._hand_marker = Visibility(HAND_MARKER)
        self._prediction_steps = int(prediction_steps)
        k = len(self._objects)
        path_count = int(path_count)
        if not 1 <= path_count <= k:
            raise ValueError(f"path_count must be in [1, {k}] (the object count), got "
                             f"{path_count}")
        self._path_count = path_count
        self._target_port = self.DeclareVectorInputPort("target", Target.size)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._predicted_paths_port = self.DeclareVectorInputPort(
            "predicted_paths", max(1, path_count * (self._prediction_steps + 1) * 3))
        self._probabilities_port = self.DeclareVectorInputPort("goal_probabilities", k)
        self._active_path = PathDots("/task/predictions/selected", PATH_DOTS,
                                     ACTIVE_DOT_RADIUS, ACTIVE_PATH_COLOUR)
        self._other_paths = [PathDots(f"/task/predictions/likely/{index}", PATH_DOTS,
                                      OTHER_DOT_RADIUS, OTHER_PATH_COLOUR)
                             for index in range(1, path_count)]
        self._cloud = GoalCloud("/task/goal_cloud", self._objects + [0.0, 0.0, CLOUD_LIFT],
                                CLOUD_POINT_SIZE)
        # The hand's path as it grows (`pbp-drake teach`: the demonstration being recorded).
        self._trail = (PathTrail("/task/hand_trail", TRAIL_DOT_RADIUS, TRAIL_COLOUR,
                                 TRAIL_SPACING) if hand_trail else None)
        self.DeclarePeriodicPublishEvent(publish_period, 0.0, self._publish)
        if self._prediction_steps:
            self.DeclarePeriodicPublishEvent(path_period, 0.0, self._publish_paths)
        self.DeclarePeriodicPublishEvent(self._cloud.period(cloud_period), 0.0,
                                         self._publish_cloud)
        self.DeclareInitializationPublishEvent(self._initialise)

    def _initialise(self, context):
        self._draw_scene()
        if self._trail is not None:
            self._trail.draw(self._meshcat, context.get_time())
        self._publish(context)
        if self._prediction_steps:
            self._publish_paths(context)
        self._publish_cloud(context)

    def _draw_scene(self):
        meshcat = self._meshcat
        meshcat.Delete("/task")
        self._cloud.restart()  # drawn by the `_publish_cloud` that follows
        for index, point in enumerate(self._objects if len(self._objects) <= SOLID_OBJECTS
                                      else ()):
            table = [point[0], point[1], point[2] - OBJECT_HEIGHT / 2]
            draw_table_object(meshcat, index, table, (0.3, 0.3), point,
                              (OBJECT_RADIUS, OBJECT_HEIGHT))
        self._markers.draw(meshcat)
        meshcat.SetObject(HAND_MARKER, Cylinder(0.09, 0.01), OPERATOR_COLOUR)
        meshcat.SetProperty(HAND_MARKER, "visible", False)
        self._hand_marker.forget()
        if self._prediction_steps:
            for dots in [self._active_path, *self._other_paths]:
                dots.draw(meshcat)
        meshcat.SetCameraPose(*self.camera)

    def _publish(self, context):
        time = context.get_time()
        meshcat = self._meshcat
        selected = int(self._selected_goal_port.Eval(context)[0])  # -1: no intent shown
        self._markers.show(meshcat, position_of(Target(self._target_port.Eval(context))),
                           self._objects[selected] if selected >= 0 else None, time)
        if self._ee_state_port.HasValue(context):
            position = position_of(EeState(self._ee_state_port.Eval(context)))
            meshcat.SetTransform(HAND_MARKER, RigidTransform(position), time)
            if self._trail is not None:
                self._trail.extend(meshcat, position, time)
            if self._operator_active_port.HasValue(context):
                active = bool(self._operator_active_port.Eval(context)[0] > 0.5)
                self._hand_marker.show(meshcat, active, time)

    def _publish_paths(self, context):
        if not self._predicted_paths_port.HasValue(context):
            return
        time = context.get_time()
        paths = self._predicted_paths_port.Eval(context).reshape(
            self._path_count, self._prediction_steps + 1, 3)
        for dots, path in zip([self._active_path, *self._other_paths], paths):
            dots.show(self._meshcat, path, time)

    def _publish_cloud(self, context):
        port = self._probabilities_port
        self._cloud.show(self._meshcat, port.Eval(context) if port.HasValue(context) else None)


def draw_table_object(meshcat, index, table, table_size, centre, object_shape):
    """Draws object `index`, a cylinder `(radius, height)` at `centre`, and its table, a box
    of `table_size` (x, y) standing on the floor under `table` (its top face's centre; none
    where that is on the floor: the object stands there)."""
    if table[2] > 0.0:
        meshcat.SetObject(f"/task/tables/{index}", Box(*table_size, table[2]), TABLE_COLOUR)
        meshcat.SetTransform(f"/task/tables/{index}",
                             RigidTransform([table[0], table[1], table[2] / 2]))
    meshcat.SetObject(f"/task/objects/{index}", Cylinder(*object_shape), OBJECT_COLOUR)
    meshcat.SetTransform(f"/task/objects/{index}", RigidTransform(centre))


def behind_the_robot(objects):
    """A camera `(position, target)` behind and above the HSR that sees it and every object
    `(M, 3)` of the task."""
    return np.array([-1.6, -1.2, 2.6]), np.array([0.55 * objects.mean(axis=0)[0], 0.0, 0.4])
