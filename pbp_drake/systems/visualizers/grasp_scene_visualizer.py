"""Draws the grasping task in Meshcat: the scene, grasp poses as triads, the goal cloud,
the markers, the hand and the selected DMP's predicted poses."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.pbp.likely_goals import likely_goal_indices
from pbp_drake.systems.ports import GoalPose, PortGetters, PoseState, Target, goal_index
from pbp_drake.systems.visualizers.reach_scene_visualizer import (
    CLOUD_POINT_SIZE, SOLID_OBJECTS, TaskMarkers, behind_the_robot, draw_table_object)
from pbp_drake.systems.visualizers.scene_drawing import (
    GoalCloud, PathTriads, Visibility, draw_triad, pose_transform)

# Triads: the grasp poses' and the hand's full size, the predicted path's smaller and a
# little transparent, so that the grasp they lead to stands out.
TRIAD_LENGTH, TRIAD_RADIUS = 0.1, 0.005
PATH_TRIADS, PATH_TRIAD_LENGTH, PATH_TRIAD_OPACITY = 5, 0.06, 0.7


class GraspSceneVisualizer(PortGetters, LeafSystem):
    """Publishes the grasping task's drawing to Meshcat under `/task`.

    .. pydrake_system::

        name: GraspSceneVisualizer
        input_ports:
        - target
        - selected_goal
        - predicted_poses (optional)
        - hand_state (optional)
        - goal_probabilities (optional)

    The ports, the triads and the predicted path: docs/concepts/six-dof.md, "Drawing the
    grasp scene". `grasps` is the task's `GraspScene` (`layout.grasps`); the scene, cloud
    and markers are drawn as `ReachSceneVisualizer`'s. Up to `SOLID_OBJECTS` grasps, every
    table and object is drawn with a triad at its grasp pose; with more, `likely_triads`
    triads `/task/likely_grasps/{i}` that each path period moves to the selected grasp and
    the likeliest others. Call from the thread that made `meshcat`.
    """

    def __init__(self, meshcat, grasps, prediction_steps=0, table_size=(0.3, 0.3),
                 object_radius=0.03, object_height=0.15, publish_period=1.0 / 30.0,
                 path_period=0.1, cloud_period=0.25, likely_triads=4):
        super().__init__()
        self._meshcat = meshcat
        self._grasps = grasps
        self._table_size = tuple(float(size) for size in table_size)
        self._object_shape = (float(object_radius), float(object_height))
        self._prediction_steps = int(prediction_steps)
        self._target_port = self.DeclareVectorInputPort("target", Target.size)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._predicted_poses_port = self.DeclareVectorInputPort(
            "predicted_poses", (self._prediction_steps + 1) * GoalPose.size)
        self._hand_state_port = self.DeclareVectorInputPort("hand_state", PoseState.size)
        count = len(grasps.grasp_positions)
        self._probabilities_port = self.DeclareVectorInputPort("goal_probabilities", count)
        self._path = PathTriads("/task/prediction", PATH_TRIADS, PATH_TRIAD_LENGTH,
                                TRIAD_RADIUS, PATH_TRIAD_OPACITY)
        self._solid = count <= SOLID_OBJECTS
        self._likely_triads = min(int(likely_triads), count)
        self._cloud = GoalCloud("/task/goal_cloud", grasps.grasp_positions, CLOUD_POINT_SIZE)
        self._markers = TaskMarkers()
        self._hand = Visibility("/task/hand")
        self._likely = [Visibility(f"/task/likely_grasps/{index}")
                        for index in range(self._likely_triads)]
        self.DeclarePeriodicPublishEvent(publish_period, 0.0, self._publish)
        if self._prediction_steps:
            self.DeclarePeriodicPublishEvent(path_period, 0.0, self._publish_path)
        if not self._solid:
            self.DeclarePeriodicPublishEvent(path_period, 0.0, self._publish_likely_grasps)
        self.DeclarePeriodicPublishEvent(self._cloud.period(cloud_period), 0.0,
                                         self._publish_cloud)
        self.DeclareInitializationPublishEvent(self._initialise)

    def _initialise(self, context):
        self._draw_scene()
        self._publish(context)
        if self._prediction_steps:
            self._publish_path(context)
        if not self._solid:
            self._publish_likely_grasps(context)
        self._publish_cloud(context)

    def _draw_scene(self):
        meshcat, grasps = self._meshcat, self._grasps
        meshcat.Delete("/task")
        self._cloud.restart()  # drawn by the `_publish_cloud` that follows
        for visibility in [self._hand, *self._likely]:
            visibility.forget()
        for index in range(0 if self._solid else self._likely_triads):
            draw_triad(meshcat, f"/task/likely_grasps/{index}", None, TRIAD_LENGTH,
                       TRIAD_RADIUS, opacity=1.0 if index == 0 else 0.5)
        solid = zip(grasps.tables, grasps.objects) if self._solid else ()
        for index, (table, centre) in enumerate(solid):
            # `tables` holds each top face's centre.
            draw_table_object(meshcat, index, table, self._table_size, centre,
                              self._object_shape)
            draw_triad(meshcat, f"/task/grasps/{index}", self._grasp_pose(index),
                       TRIAD_LENGTH, TRIAD_RADIUS)
        self._markers.draw(meshcat)
        draw_triad(meshcat, "/task/hand", None, TRIAD_LENGTH, TRIAD_RADIUS)
        meshcat.SetProperty("/task/hand", "visible", False)  # until a hand_state is seen
        if self._prediction_steps:
            self._path.draw(meshcat)
        meshcat.SetCameraPose(*behind_the_robot(grasps.objects))

    def _grasp_pose(self, index):
        return np.concatenate([self._grasps.grasp_positions[index],
                               self._grasps.grasp_orientations[index]])

    def _publish(self, context):
        time = context.get_time()
        meshcat, objects = self._meshcat, self._grasps.objects
        count = len(objects)
        target = int(Target(self._target_port.Eval(context)).index)
        if not 0 <= target < count:
            raise ValueError(f"target index {target} is not one of the {count} objects")
        selected = self._shown_goal(context)
        self._markers.show(meshcat, objects[target],
                           None if selected is None else objects[selected], time)
        if self._hand_state_port.HasValue(context):
            hand = self._hand_state_port.Eval(context)[:GoalPose.size]
            meshcat.SetTransform("/task/hand", pose_transform(hand), time)
            self._hand.show(meshcat, True, time)

    def _publish_path(self, context):
        if not self._predicted_poses_port.HasValue(context):
            return
        poses = self._predicted_poses_port.Eval(context).reshape(-1, GoalPose.size)
        self._path.show(self._meshcat, poses, context.get_time())

    def _shown_goal(self, context):
        """The selected grasp's index, or None while the robot shows none (-1)."""
        if self._selected_goal_port.Eval(context)[0] < 0:
            return None
        return goal_index(self._selected_goal_port, context, len(self._grasps.objects))

    def _likeliest(self, context):
        """The selected grasp (while one is shown) and the likeliest others, `likely_triads`
        at most."""
        selected = self._shown_goal(context) if self._selected_goal_port.HasValue(
            context) else 0
        if not self._probabilities_port.HasValue(context):
            return [] if selected is None else [selected]
        probabilities = self._probabilities_port.Eval(context)
        if selected is None:
            selected = int(np.argmax(probabilities))
        return likely_goal_indices(selected, probabilities, self._likely_triads)

    def _publish_likely_grasps(self, context):
        time, likeliest = context.get_time(), self._likeliest(context)
        for index, visibility in enumerate(self._likely):
            shown = index < len(likeliest)
            if shown:
                self._meshcat.SetTransform(
                    visibility.path, pose_transform(self._grasp_pose(likeliest[index])), time)
            visibility.show(self._meshcat, shown, time)

    def _publish_cloud(self, context):
        port = self._probabilities_port
        self._cloud.show(self._meshcat, port.Eval(context) if port.HasValue(context) else None)
