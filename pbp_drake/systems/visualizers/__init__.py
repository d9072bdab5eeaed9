"""Meshcat drawing: each task's scene, the DMPs' predicted paths, replays
(`ReachSceneVisualizer`, `GraspSceneVisualizer`, `PointSceneVisualizer`; `scene_drawing`
holds what they share)."""

from pbp_drake.systems.visualizers.grasp_scene_visualizer import GraspSceneVisualizer
from pbp_drake.systems.visualizers.point_scene_visualizer import PointSceneVisualizer
from pbp_drake.systems.visualizers.reach_scene_visualizer import ReachSceneVisualizer

__all__ = ["GraspSceneVisualizer", "PointSceneVisualizer", "ReachSceneVisualizer"]
