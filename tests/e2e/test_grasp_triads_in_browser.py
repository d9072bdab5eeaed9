"""The grasp scene as a person sees it: headless Chromium opens the Meshcat page of a
`GraspSceneVisualizer` and finds each grasp's triad in the page's scene tree (three.js):
red, green and blue cylinders, at the grasp, the blue one along the approach.

Needs Debian's `chromium` and Playwright from PyPI (skipped where either is missing)."""

import numpy as np
from browser_page import NEEDS_BROWSER, open_page
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.core.grasp_task import approach_direction, sample_grasp_scene
from pbp_drake.systems.visualizers.grasp_scene_visualizer import (
    PATH_TRIADS, TRIAD_LENGTH, GraspSceneVisualizer)

pytestmark = NEEDS_BROWSER

# Every drawn shape in the page: its scene path, colour and world position (three.js keeps
# Meshcat's objects as `<object>` children of the nodes named by the path).
SHAPES_JS = """() => {
  const shapes = {};
  const walk = (node, path) => {
    for (const [name, child] of Object.entries(node.children)) {
      if (name === "<object>" && child.object.material) {
        child.object.updateWorldMatrix(true, false);
        const m = child.object.matrixWorld.elements;
        shapes[path] = {colour: child.object.material.color.getHexString(),
                        position: [m[12], m[13], m[14]]};
      }
      walk(child, path + "/" + name);
    }
  };
  walk(viewer.scene_tree, "");
  return shapes;
}"""
COLOURS = {"x": "ff0000", "y": "00ff00", "z": "0000ff"}
# three.js's world is y-up: the page turns Drake's z-up world -90 degrees about x.
PAGE_TO_WORLD = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
SCENE = sample_grasp_scene(3)  # four objects, one grasped from above
STEPS = 10


def grasp_diagram(meshcat):
    """The visualizer showing target 1, estimate 0 and a predicted path of STEPS + 1 poses
    from the hand's start to grasp 0."""
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(GraspSceneVisualizer(meshcat, SCENE, STEPS))
    poses = np.linspace(np.array([0.6, 0.0, 0.8, 1.0, 0, 0, 0]),
                        np.concatenate([SCENE.grasp_positions[0],
                                        SCENE.grasp_orientations[0]]), STEPS + 1)
    for value, port in [([*SCENE.objects[1], 1], visualizer.get_target_input_port()),
                        ([0.0], visualizer.get_selected_goal_input_port()),
                        (poses.ravel(), visualizer.get_predicted_poses_input_port())]:
        source = builder.AddSystem(ConstantVectorSource(np.asarray(value, float)))
        builder.Connect(source.get_output_port(), port)
    return builder.Build()


def test_the_page_shows_a_triad_at_every_grasp():
    meshcat = Meshcat(MeshcatParams(host="localhost", port=0))  # this thread only
    Simulator(grasp_diagram(meshcat)).Initialize()
    count = len(SCENE.objects)
    with open_page(meshcat.web_url()) as page:
        last = f"/task/grasps/{count - 1}/z"
        page.wait_for_function(
            f"() => Object.keys(({SHAPES_JS})()).some(p => p.endsWith('{last}'))")
        shapes = page.evaluate(SHAPES_JS)
    by_suffix = {path[path.index("/task/"):]: shape for path, shape in shapes.items()
                 if "/task/" in path}
    for k in range(count):
        approach = approach_direction(SCENE.grasp_orientations[k])
        for axis, colour in COLOURS.items():
            shape = by_suffix[f"/task/grasps/{k}/{axis}"]
            assert shape["colour"] == colour, (k, axis, shape)
        # The blue cylinder's centre: half the triad's length out along the approach.
        np.testing.assert_allclose(PAGE_TO_WORLD @ by_suffix[f"/task/grasps/{k}/z"]["position"],
                                   SCENE.grasp_positions[k] + TRIAD_LENGTH / 2 * approach,
                                   atol=1e-6)
    assert f"/task/prediction/{PATH_TRIADS - 1}/z" in by_suffix
