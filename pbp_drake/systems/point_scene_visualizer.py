"""Draws a point-robot scene in Meshcat: obstacles, goals, demonstration, robot, DMP paths."""

import numpy as np
from pydrake.geometry import Cylinder, Rgba, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.systems.framework import LeafSystem

ROBOT_COLOUR = Rgba(0.1, 0.3, 0.9, 1.0)
OPERATOR_HALO = Rgba(1.0, 0.55, 0.0, 0.5)
GOAL_COLOUR = Rgba(0.1, 0.7, 0.2, 1.0)
OBSTACLE_COLOUR = Rgba(0.85, 0.15, 0.15, 0.8)
PATH_COLOUR = Rgba(0.2, 0.2, 0.8, 1.0)


class PointSceneVisualizer(LeafSystem):
    """Publishes the robot and the DMPs' predicted paths to Meshcat, in 2-D render mode for
    planar scenes.

    .. pydrake_system::

        name: PointSceneVisualizer
        input_ports:
        - robot_state
        - operator_active (optional)
        - predicted_paths (optional)

    The static scene (obstacles, goals, the demonstration, the robot at `start`) is drawn
    under `/pbp`, after deleting it, at each initialisation (`Simulator.Initialize`), so a
    second run or a run after `meshcat.Delete()` draws it again. Each publish moves the robot
    (with `time_in_recording`, so `Meshcat.StartRecording` captures a replay), shows an
    orange halo while the operator acts, and redraws the predicted path of every DMP (live
    only: Meshcat replays transforms and visibility, not lines). Call from the thread that
    made `meshcat`.
    """

    def __init__(self, meshcat, start, goals, obstacles, demonstration=None,
                 prediction_steps=0, publish_period=1.0 / 30.0):
        super().__init__()
        self._meshcat = meshcat
        goals = np.atleast_2d(np.asarray(goals, dtype=float))
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
        self.DeclarePeriodicPublishEvent(publish_period, 0.0, self._publish)
        self.DeclareInitializationPublishEvent(self._draw_scene)

    def get_robot_state_input_port(self):
        return self._robot_state_port

    def get_operator_active_input_port(self):
        return self._operator_active_port

    def get_predicted_paths_input_port(self):
        return self._predicted_paths_port

    def _to_3d(self, points):
        points = np.atleast_2d(points)
        padded = np.zeros((points.shape[0], 3))
        padded[:, :min(3, self._dimension)] = points[:, :3]
        return padded

    def _draw_scene(self, context):
        meshcat = self._meshcat
        start, goals = self._start, self._goals
        obstacles, demonstration = self._obstacles, self._demonstration
        meshcat.Delete("/pbp")
        everything = [start, *goals]
        for index, obstacle in enumerate(obstacles):
            path = f"/pbp/obstacles/{index}"
            centre = self._to_3d(obstacle.center)[0]
            if self._dimension == 2:
                meshcat.SetObject(path, Cylinder(obstacle.radius, 0.01), OBSTACLE_COLOUR)
            else:
                meshcat.SetObject(path, Sphere(obstacle.radius), OBSTACLE_COLOUR)
            meshcat.SetTransform(path, RigidTransform(centre))
            everything += [np.asarray(obstacle.center) + obstacle.radius,
                           np.asarray(obstacle.center) - obstacle.radius]
        for index, goal in enumerate(goals):
            meshcat.SetObject(f"/pbp/goals/{index}", Sphere(0.025), GOAL_COLOUR)
            meshcat.SetTransform(f"/pbp/goals/{index}", RigidTransform(self._to_3d(goal)[0]))
        if demonstration is not None:
            meshcat.SetLine("/pbp/demonstration", self._to_3d(demonstration).T, 2.0,
                            Rgba(0.3, 0.3, 0.3, 1.0))
            everything += list(demonstration)
        meshcat.SetObject("/pbp/robot", Sphere(0.03), ROBOT_COLOUR)
        meshcat.SetObject("/pbp/robot/operator", Sphere(0.045), OPERATOR_HALO)
        meshcat.SetProperty("/pbp/robot/operator", "visible", False)
        meshcat.SetTransform("/pbp/robot", RigidTransform(self._to_3d(start)[0]))
        if self._dimension == 2:
            low = np.min(everything, axis=0) - 0.2
            high = np.max(everything, axis=0) + 0.2
            centre = (low + high) / 2
            half = max(high - low) / 2
            # Camera above the plane looking down -z, screen up = +y.
            camera = RigidTransform(RotationMatrix.MakeXRotation(-np.pi / 2),
                                    [centre[0], centre[1], 1.0])
            meshcat.Set2dRenderMode(camera, -half, half, -half, half)

    def _publish(self, context):
        time = context.get_time()
        d = self._dimension
        position = self._robot_state_port.Eval(context)[:d]
        self._meshcat.SetTransform(
            "/pbp/robot", RigidTransform(self._to_3d(position)[0]), time)
        if self._operator_active_port.HasValue(context):
            active = bool(self._operator_active_port.Eval(context)[0] > 0.5)
            self._meshcat.SetProperty("/pbp/robot/operator", "visible", active, time)
        if self._prediction_steps and self._predicted_paths_port.HasValue(context):
            paths = self._predicted_paths_port.Eval(context).reshape(
                self._goal_count, self._prediction_steps + 1, d)
            for index, path in enumerate(paths):
                self._meshcat.SetLine(f"/pbp/predictions/{index}", self._to_3d(path).T, 2.0,
                                      PATH_COLOUR)
