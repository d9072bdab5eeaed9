"""Draws a point-robot scene in Meshcat: obstacles, goals, demonstration, robot, the path it
has travelled, DMP paths; and `LEGEND`, what each colour means, for a replay's key."""

import numpy as np
from pydrake.geometry import Cylinder, Rgba, Sphere
from pydrake.math import RigidTransform
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.scene_framing import page_view, scene_bounds
from pbp_drake.systems.ports import PortGetters
from pbp_drake.systems.tick import checked_period
from pbp_drake.systems.visualizers.scene_drawing import (PathDots, PathTrail, Visibility,
                                                         frame_top_down)

# Saturated colours of distinct hues, so that a screenshot tells the markers apart.
ROBOT_COLOUR = Rgba(0.1, 0.3, 0.9, 1.0)
OPERATOR_HALO = Rgba(1.0, 0.55, 0.0, 0.5)
GOAL_COLOUR = Rgba(0.1, 0.7, 0.2, 1.0)
START_COLOUR = Rgba(0.85, 0.1, 0.85, 1.0)
OBSTACLE_COLOUR = Rgba(0.85, 0.15, 0.15, 0.8)
PATH_COLOUR = Rgba(0.0, 0.65, 0.65, 1.0)
DEMONSTRATION_COLOUR = Rgba(0.3, 0.3, 0.3, 1.0)
# The executed path is the robot's trail, in its blue.
EXECUTED_COLOUR = ROBOT_COLOUR

# What each colour of the scene is, in the order a key lists them (`mark_replay` writes it
# into a 2-D replay: Meshcat has no text to draw one in the scene).
LEGEND = (("start", START_COLOUR), ("goal", GOAL_COLOUR), ("obstacle", OBSTACLE_COLOUR),
          ("demonstration", DEMONSTRATION_COLOUR), ("robot and its executed path", ROBOT_COLOUR),
          ("operator acting", OPERATOR_HALO), ("DMP predicted paths", PATH_COLOUR))

ROBOT_RADIUS = 0.03
GOAL_RADIUS = 0.025
# The start is a flat disc under everything, wider than the robot that stands on it at first.
START_RADIUS = 0.05
PATH_DOTS = 40
PATH_DOT_RADIUS = 0.006
# The executed path: dots closer than their diameter read as a line, thinner than the DMPs'
# dots; `PathTrail` doubles their spacing after 1.6 m (a toy run's path is about 1.3 m).
EXECUTED_DOT_RADIUS = 0.003
EXECUTED_SPACING = 0.004
# Heights seen from above: the start under the obstacles (top at 0.005), the executed path
# over them, under the predicted paths.
START_Z, EXECUTED_Z, PATH_Z = -0.01, 0.006, 0.008


class PointSceneVisualizer(PortGetters, LeafSystem):
    """Publishes the robot and the DMPs' predicted paths to Meshcat; a planar scene is seen
    from above, framed on the whole scene.

    .. pydrake_system::

        name: PointSceneVisualizer
        input_ports:
        - robot_state
        - operator_active (optional)
        - predicted_paths (optional)

    At each initialisation the static scene is drawn under `/pbp` (after deleting it), and a
    planar scene's view is framed once on what is known then (`core.scene_framing`). Each
    publish moves the robot, shows an orange halo while the operator acts and extends the
    executed path (`PathTrail`, `/pbp/executed`) and moves every DMP's predicted path
    (`PathDots`). All with `time_in_recording`, so that a recording replays them. Call from
    the thread that made `meshcat`.
    """

    def __init__(self, meshcat, start, goals, obstacles, demonstration=None,
                 prediction_steps=0, publish_period=1.0 / 30.0):
        super().__init__()
        self._meshcat = meshcat
        goals = np.atleast_2d(np.asarray(goals, dtype=float))
        if goals.ndim != 2 or goals.size == 0 or not np.isfinite(goals).all():
            raise ValueError(f"goals must be a non-empty finite (K, D) array, got "
                             f"{goals.tolist()}")
        checked_period(publish_period, "publish_period")
        self._goal_count, self._dimension = goals.shape
        self._prediction_steps = int(prediction_steps)
        d, k = self._dimension, self._goal_count
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", 2 * d)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._predicted_paths_port = self.DeclareVectorInputPort(
            "predicted_paths", max(1, k * (self._prediction_steps + 1) * d))
        self._start = np.asarray(start, float)
        self._goals = goals
        self._obstacles = list(obstacles)
        self._demonstration = demonstration
        self._path_dots = [PathDots(f"/pbp/predictions/{index}", PATH_DOTS, PATH_DOT_RADIUS,
                                    PATH_COLOUR) for index in range(k)]
        self._executed = PathTrail("/pbp/executed", EXECUTED_DOT_RADIUS, EXECUTED_COLOUR,
                                   EXECUTED_SPACING)
        self._operator_halo = Visibility("/pbp/robot/operator")
        self.DeclarePeriodicPublishEvent(publish_period, 0.0, self._publish)
        if self._prediction_steps:
            self.DeclarePeriodicPublishEvent(publish_period, 0.0, self._publish_paths)
        self.DeclareInitializationPublishEvent(self._draw_scene)

    def _to_3d(self, points, z=0.0):
        points = np.atleast_2d(points)
        padded = np.full((points.shape[0], 3), float(z))
        padded[:, :min(3, self._dimension)] = points[:, :3]
        return padded

    def _paths(self, context):
        """The predicted paths `(K, steps + 1, D)`, or None when there are none."""
        if not (self._prediction_steps and self._predicted_paths_port.HasValue(context)):
            return None
        return self._predicted_paths_port.Eval(context).reshape(
            self._goal_count, self._prediction_steps + 1, self._dimension)

    def _draw_scene(self, context):
        meshcat = self._meshcat
        start, goals = self._start, self._goals
        obstacles, demonstration = self._obstacles, self._demonstration
        meshcat.Delete("/pbp")
        for index, obstacle in enumerate(obstacles):
            path = f"/pbp/obstacles/{index}"
            centre = self._to_3d(obstacle.center)[0]
            if self._dimension == 2:
                meshcat.SetObject(path, Cylinder(obstacle.radius, 0.01), OBSTACLE_COLOUR)
            else:
                meshcat.SetObject(path, Sphere(obstacle.radius), OBSTACLE_COLOUR)
            meshcat.SetTransform(path, RigidTransform(centre))
        meshcat.SetObject("/pbp/start", Cylinder(START_RADIUS, 0.002), START_COLOUR)
        meshcat.SetTransform("/pbp/start", RigidTransform(self._to_3d(start, START_Z)[0]))
        for index, goal in enumerate(goals):
            meshcat.SetObject(f"/pbp/goals/{index}", Sphere(GOAL_RADIUS), GOAL_COLOUR)
            meshcat.SetTransform(f"/pbp/goals/{index}", RigidTransform(self._to_3d(goal)[0]))
        if demonstration is not None:
            meshcat.SetLine("/pbp/demonstration", self._to_3d(demonstration).T, 2.0,
                            DEMONSTRATION_COLOUR)
        self._executed.draw(meshcat, context.get_time())
        for dots in self._path_dots if self._prediction_steps else []:
            dots.draw(meshcat)
        meshcat.SetObject("/pbp/robot", Sphere(ROBOT_RADIUS), ROBOT_COLOUR)
        meshcat.SetObject("/pbp/robot/operator", Sphere(0.045), OPERATOR_HALO)
        meshcat.SetProperty("/pbp/robot/operator", "visible", False)
        self._operator_halo.forget()
        meshcat.SetTransform("/pbp/robot", RigidTransform(self._to_3d(start)[0]))
        if self._dimension == 2:
            # Framed once, on what is known at the start.
            points = [start[None, :], goals]
            if demonstration is not None:
                points.append(np.asarray(demonstration, float))
            paths = self._paths(context)
            if paths is not None:
                points.append(paths.reshape(-1, 2))
            low, high = scene_bounds(np.concatenate(points),
                                     [(o.center, o.radius) for o in obstacles])
            frame_top_down(meshcat, page_view(low, high))

    def _publish(self, context):
        time = context.get_time()
        d = self._dimension
        position = self._robot_state_port.Eval(context)[:d]
        self._meshcat.SetTransform(
            "/pbp/robot", RigidTransform(self._to_3d(position)[0]), time)
        self._executed.extend(self._meshcat, self._to_3d(position, EXECUTED_Z)[0], time)
        if self._operator_active_port.HasValue(context):
            active = bool(self._operator_active_port.Eval(context)[0] > 0.5)
            self._operator_halo.show(self._meshcat, active, time)

    def _publish_paths(self, context):
        paths = self._paths(context)
        if paths is None:
            return
        for dots, path in zip(self._path_dots, paths):
            dots.show(self._meshcat, path, context.get_time(),
                      lift=PATH_Z if self._dimension == 2 else 0.0)
