"""The scene visualizers draw their static scene on initialisation, so it comes back after a
`meshcat.Delete` of their tree or in a second run; checked with `Meshcat.HasPath`.

(`meshcat.Delete()` without a path deletes `/drake` only; the visualizers draw under their own
roots, `/task` and `/pbp`.)"""

import numpy as np
import pytest
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.scenarios import Obstacle
from pbp_drake.systems.layouts import Target
from pbp_drake.systems.point_scene_visualizer import PointSceneVisualizer
from pbp_drake.systems.reach_scene_visualizer import ReachSceneVisualizer

OBJECTS = np.array([[1.5, -0.4, 0.7], [1.5, 0.4, 0.7]])
ROOTS = ["/task", "/pbp"]
REACH_PATHS = ["/task/tables/0", "/task/tables/1", "/task/objects/0", "/task/objects/1",
               "/task/target", "/task/estimated_goal", "/task/operator"]
POINT_PATHS = ["/pbp/obstacles/0", "/pbp/goals/0", "/pbp/goals/1", "/pbp/demonstration",
               "/pbp/robot", "/pbp/robot/operator"]


@pytest.fixture(scope="module")
def meshcat():
    # Port 0: any free port. Used only from this (the creating) thread.
    return Meshcat(MeshcatParams(host="localhost", port=0))


@pytest.fixture(autouse=True)
def empty_scene(meshcat):
    delete_scenes(meshcat)
    yield
    delete_scenes(meshcat)


def delete_scenes(meshcat):
    for root in ROOTS:
        meshcat.Delete(root)


def add_source(builder, value, port):
    source = builder.AddSystem(ConstantVectorSource(np.asarray(value, float)))
    builder.Connect(source.get_output_port(), port)


def reach_diagram(meshcat):
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(ReachSceneVisualizer(meshcat, OBJECTS))
    target = Target(np.zeros(Target.size))
    target.x, target.y, target.z = OBJECTS[1]
    target.index = 1
    add_source(builder, target[:], visualizer.get_target_input_port())
    add_source(builder, [0.0], visualizer.get_selected_goal_input_port())
    return builder.Build()


def point_diagram(meshcat):
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(PointSceneVisualizer(
        meshcat, start=[0.0, 0.0], goals=[[1.0, 0.5], [1.0, -0.5]],
        obstacles=[Obstacle(center=[0.5, 0.0], radius=0.1)],
        demonstration=np.array([[0.0, 0.0], [0.5, 0.25], [1.0, 0.5]])))
    add_source(builder, [0.2, 0.1, 0.0, 0.0], visualizer.get_robot_state_input_port())
    return builder.Build()


def drawn(meshcat, paths):
    return [path for path in paths if meshcat.HasPath(path)]


@pytest.mark.parametrize("make, paths", [(reach_diagram, REACH_PATHS),
                                         (point_diagram, POINT_PATHS)])
def test_the_scene_is_drawn_on_initialisation_not_at_construction(meshcat, make, paths):
    diagram = make(meshcat)
    assert drawn(meshcat, paths) == []
    Simulator(diagram).Initialize()
    assert drawn(meshcat, paths) == paths


@pytest.mark.parametrize("make, paths", [(reach_diagram, REACH_PATHS),
                                         (point_diagram, POINT_PATHS)])
def test_the_scene_comes_back_after_a_delete_and_in_a_second_run(meshcat, make, paths):
    diagram = make(meshcat)
    simulator = Simulator(diagram)
    simulator.AdvanceTo(0.1)
    delete_scenes(meshcat)
    assert drawn(meshcat, paths) == []
    simulator.Initialize()  # the same simulator, initialised again
    assert drawn(meshcat, paths) == paths
    delete_scenes(meshcat)
    Simulator(diagram).AdvanceTo(0.1)  # a second simulator on the same diagram
    assert drawn(meshcat, paths) == paths

