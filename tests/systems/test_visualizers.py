"""The scene visualizers draw their static scene on initialisation, so it comes back after a
`meshcat.Delete` of their tree or in a second run; checked with `Meshcat.HasPath`. Their
recordings replay the DMPs' paths as they were at each moment, from where the robot was.

(`meshcat.Delete()` without a path deletes `/drake` only; the visualizers draw under their own
roots, `/task` and `/pbp`.)"""

import numpy as np
import pytest
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial
from replay_tracks import recorded, value_at

from pbp_drake.builder import build_diagram
from pbp_drake.scenarios import load_scenario_file

from pbp_drake.scenarios import Obstacle
from pbp_drake.systems.ports import Target
from pbp_drake.systems.visualizers.point_scene_visualizer import PointSceneVisualizer
from pbp_drake.systems.visualizers.reach_scene_visualizer import ReachSceneVisualizer

OBJECTS = np.array([[1.5, -0.4, 0.7], [1.5, 0.4, 0.7]])
ROOTS = ["/task", "/pbp"]
REACH_PATHS = ["/task/tables/0", "/task/tables/1", "/task/objects/0", "/task/objects/1",
               "/task/target", "/task/estimated_goal", "/task/operator"]
POINT_PATHS = ["/pbp/obstacles/0", "/pbp/start", "/pbp/goals/0", "/pbp/goals/1",
               "/pbp/demonstration", "/pbp/robot", "/pbp/robot/operator"]


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
    meshcat.DeleteRecording()


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



def test_a_2d_replay_shows_the_dmp_path_from_where_the_robot_is_at_each_time(repo, meshcat):
    # Fig. 4's scene: pushed sideways from 0.2 s to 0.6 s, the DMP's path bends; then it
    # comes back straight to the goal.
    resolved = load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").resolved
    tracks = recorded(meshcat, build_diagram(resolved, meshcat), 1.0)
    dots = [f"/pbp/predictions/0/{index}" for index in range(40)]

    def path_at(time):
        return np.array([value_at(tracks, dot, ".position", time) for dot in dots])

    for time in [0.0, 0.5, 0.9]:
        robot = value_at(tracks, "/pbp/robot", ".position", time)
        path = path_at(time)
        np.testing.assert_allclose(path[0, :2], robot[:2], atol=0.02)  # starts at the robot
        np.testing.assert_allclose(path[-1, :2], resolved.goals[0], atol=0.02)  # ends at the goal
    assert np.max(np.abs(path_at(0.5) - path_at(0.0))) > 0.1  # the path is not frozen
    assert np.max(np.abs(path_at(0.5)[:, 1])) > 0.05  # bent sideways by the push


def test_an_hsr_replay_shows_each_dmp_path_and_the_selected_one_as_they_were(meshcat):
    # Paths of 3 points each that slide 0.5 m along y over a second; the estimate is object 1.
    steps, count = 2, len(OBJECTS)
    start = np.array([[[0.5, 0.0, 0.7], *OBJECTS]] * count).reshape(count, steps + 1, 3)
    start[:, -1] = OBJECTS  # each path ends at its object
    end = start + [0.0, 0.5, 0.0]
    paths = PiecewisePolynomial.FirstOrderHold(
        [0.0, 1.0], np.column_stack([start.ravel(), end.ravel()]))
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(ReachSceneVisualizer(meshcat, OBJECTS, steps))
    add_source(builder, np.zeros(Target.size), visualizer.get_target_input_port())
    add_source(builder, [1.0], visualizer.get_selected_goal_input_port())
    source = builder.AddSystem(TrajectorySource(paths))
    builder.Connect(source.get_output_port(), visualizer.get_predicted_paths_input_port())
    tracks = recorded(meshcat, builder.Build(), 1.0)
    for time in [0.0, 0.5, 1.0]:
        shift = [0.0, 0.5 * time, 0.0]
        for root, index in [("/task/predictions/0", 0), ("/task/predictions/1", 1),
                            ("/task/predictions/selected", 1)]:
            first = value_at(tracks, f"{root}/0", ".position", time)
            last = value_at(tracks, f"{root}/23", ".position", time)
            np.testing.assert_allclose(first, start[index, 0] + shift, atol=1e-9)
            np.testing.assert_allclose(last, OBJECTS[index] + shift, atol=1e-9)
