"""An arm's task is framed by the default camera: its workspace (the base, the tool's start
and the objects) spans `WORKSPACE_FILL` of the view's height, where the HSR's view, a room
seen from behind the robot, showed it as a small patch."""

import pathlib

import numpy as np
import pytest
from pydrake.geometry import Meshcat, MeshcatParams

from pbp_drake.builder import build_diagram
from pbp_drake.core.scene_framing import MESHCAT_FIELD_OF_VIEW, WORKSPACE_FILL, workspace_view
from pbp_drake.scenarios import load_scenario_file, resolve

REPO = pathlib.Path(__file__).resolve().parents[2]


def angles_from_the_view_axis(camera, target, points):
    """Each point's angle (rad) from the line of sight camera -> target."""
    axis = (target - camera) / np.linalg.norm(target - camera)
    rays = points - camera
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    return np.arccos(np.clip(rays @ axis, -1.0, 1.0))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_ball_around_the_points_spans_the_stated_share_of_the_view(seed):
    points = np.random.default_rng(seed).uniform(-0.4, 0.6, (6, 3))
    camera, target = workspace_view(points, fill=0.5)
    centre = (points.min(axis=0) + points.max(axis=0)) / 2.0
    radius = np.max(np.linalg.norm(points - centre, axis=1))
    np.testing.assert_allclose(target, centre)
    # From the definition: a ball of radius r seen from d away spans 2 asin(r / d).
    spanned = 2.0 * np.arcsin(radius / np.linalg.norm(camera - target))
    assert spanned == pytest.approx(0.5 * MESHCAT_FIELD_OF_VIEW)
    assert angles_from_the_view_axis(camera, target, points).max() <= spanned / 2 + 1e-12
    assert camera[2] > target[2]  # from above


def test_the_arms_default_camera_frames_its_workspace():
    resolved = resolve(load_scenario_file(REPO / "diagrams" / "arm_reach.yaml").scenario)
    meshcat = Meshcat(MeshcatParams(host="localhost", port=0))
    visualizer = build_diagram(resolved, meshcat).GetSubsystemByName("task_visualizer")
    camera, target = visualizer.camera
    workspace = np.vstack([resolved.station.base_pose[:3], resolved.scene.objects,
                           resolved.start])
    # Every point of the workspace in view, the farthest from the line of sight at the
    # edge of the stated share: the workspace spans it.
    half_share = angles_from_the_view_axis(camera, target, workspace).max() / (
        MESHCAT_FIELD_OF_VIEW / 2.0)
    assert 0.8 * WORKSPACE_FILL <= half_share <= WORKSPACE_FILL + 1e-9
    # The HSR's view of the same workspace: a fifth of the view or less.
    hsr_camera, hsr_target = np.array([-1.6, -1.2, 2.6]), np.array([0.3, 0.0, 0.4])
    hsr_share = angles_from_the_view_axis(hsr_camera, hsr_target, workspace).max() / (
        MESHCAT_FIELD_OF_VIEW / 2.0)
    assert hsr_share < 0.5 * half_share
