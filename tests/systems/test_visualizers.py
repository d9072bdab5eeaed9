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
from replay_tracks import held_at, recorded, value_at

from pbp_drake.builder import build_diagram
from pbp_drake.scenarios import load_scenario_file

from pbp_drake.scenarios import Obstacle
from pbp_drake.systems.ports import EeState, Target
from pbp_drake.systems.visualizers.point_scene_visualizer import PointSceneVisualizer
from pbp_drake.systems.visualizers.reach_scene_visualizer import (
    ReachSceneVisualizer, draw_table_object)
from pbp_drake.systems.visualizers.scene_drawing import LIKELY_RGB, UNLIKELY_RGB, GoalCloud

OBJECTS = np.array([[1.5, -0.4, 0.7], [1.5, 0.4, 0.7]])
ROOTS = ["/task", "/pbp"]
REACH_PATHS = ["/task/tables/0", "/task/tables/1", "/task/objects/0", "/task/objects/1",
               "/task/goal_cloud", "/task/target", "/task/estimated_goal", "/task/operator"]
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


def test_a_3d_scene_draws_spheres_and_runs_without_its_predicted_paths(meshcat):
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(PointSceneVisualizer(
        meshcat, start=[0.0, 0.0, 0.7], goals=[[1.0, 0.5, 0.7], [1.0, -0.5, 0.7]],
        obstacles=[Obstacle(center=[0.5, 0.0, 0.7], radius=0.1)], prediction_steps=4))
    add_source(builder, [0.2, 0.1, 0.7, 0.0, 0.0, 0.0], visualizer.get_robot_state_input_port())
    Simulator(builder.Build()).AdvanceTo(0.1)  # predicted_paths unconnected: none shown
    obstacle = meshcat._GetPackedObject("/pbp/obstacles/0")
    assert b"Sphere" in obstacle and b"Cylinder" not in obstacle


def test_more_paths_than_objects_are_refused(meshcat):
    with pytest.raises(ValueError, match=r"path_count must be in \[1, 2\] \(the object "
                                         r"count\), got 3"):
        ReachSceneVisualizer(meshcat, OBJECTS, prediction_steps=5, path_count=3)



@pytest.mark.slow
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


def test_an_hsr_replay_shows_the_selected_path_bold_and_the_likely_ones_as_they_were(meshcat):
    # Three objects, two paths on the port (the controller's order: the selected goal's,
    # then the likeliest other's), of 3 points each, sliding 0.5 m along y over a second.
    objects = np.vstack([OBJECTS, [[2.0, 0.0, 0.7]]])
    steps, count = 2, 2
    start = np.array([[[0.5, 0.0, 0.7], objects[2], objects[2]],
                      [[0.5, 0.0, 0.7], objects[0], objects[0]]])
    end = start + [0.0, 0.5, 0.0]
    paths = PiecewisePolynomial.FirstOrderHold(
        [0.0, 1.0], np.column_stack([start.ravel(), end.ravel()]))
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(ReachSceneVisualizer(meshcat, objects, steps, count))
    add_source(builder, np.zeros(Target.size), visualizer.get_target_input_port())
    add_source(builder, [2.0], visualizer.get_selected_goal_input_port())
    source = builder.AddSystem(TrajectorySource(paths))
    builder.Connect(source.get_output_port(), visualizer.get_predicted_paths_input_port())
    tracks = recorded(meshcat, builder.Build(), 1.0)
    for time in [0.0, 0.5, 1.0]:
        shift = [0.0, 0.5 * time, 0.0]
        for root, index in [("/task/predictions/selected", 0),
                            ("/task/predictions/likely/1", 1)]:
            first = value_at(tracks, f"{root}/0", ".position", time)
            last = value_at(tracks, f"{root}/23", ".position", time)
            np.testing.assert_allclose(first, start[index, 0] + shift, atol=1e-9)
            np.testing.assert_allclose(last, start[index, -1] + shift, atol=1e-9)
    assert not meshcat.HasPath("/task/predictions/likely/2")  # two paths, no more


def test_the_hand_marker_is_keyed_only_when_the_operator_starts_or_stops(meshcat):
    # The operator acts from 0.5 s to 1 s; the visualizer publishes at 30 Hz for 1.5 s.
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(ReachSceneVisualizer(meshcat, OBJECTS))
    add_source(builder, np.zeros(Target.size), visualizer.get_target_input_port())
    add_source(builder, [0.0], visualizer.get_selected_goal_input_port())
    add_source(builder, np.zeros(EeState.size), visualizer.get_ee_state_input_port())
    acting = builder.AddSystem(TrajectorySource(PiecewisePolynomial.ZeroOrderHold(
        [0.0, 0.5, 1.0, 2.0], [[0.0, 1.0, 0.0, 0.0]])))
    builder.Connect(acting.get_output_port(), visualizer.get_operator_active_input_port())
    tracks = recorded(meshcat, builder.Build(), 1.5)
    times, shown = tracks["/task/operator", ".visible"]
    # A key at the start and one at each change, not one at each of the 46 publishes.
    np.testing.assert_allclose(times, [0.0, 0.5, 1.0], atol=1.0 / 30.0)
    assert shown.tolist() == [False, True, False]
    assert [bool(held_at(tracks, "/task/operator", ".visible", time))
            for time in (0.25, 0.75, 1.25)] == [False, True, False]


def _cloud_scene(meshcat, objects, probabilities):
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(ReachSceneVisualizer(meshcat, objects))
    add_source(builder, np.zeros(Target.size), visualizer.get_target_input_port())
    add_source(builder, [0.0], visualizer.get_selected_goal_input_port())
    source = builder.AddSystem(TrajectorySource(probabilities))
    builder.Connect(source.get_output_port(), visualizer.get_goal_probabilities_input_port())
    return builder.Build()


def test_many_goals_are_one_cloud_coloured_by_probability_sent_only_when_it_changes(meshcat):
    # 1,000 goals: no tables, one cloud; the probabilities change once, at 1 s.
    rng = np.random.default_rng(0)
    objects = np.column_stack([rng.uniform(1.2, 2.5, 1000), rng.uniform(-1, 1, 1000),
                               np.full(1000, 0.7)])
    first, second = np.full(1000, 1e-3), np.full(1000, 1e-3)
    first[0], second[7] = 0.5, 0.5
    probabilities = PiecewisePolynomial.ZeroOrderHold(
        [0.0, 1.0, 2.0], np.column_stack([first, second, second]))
    sent = []
    original = GoalCloud.show

    def spy(cloud, meshcat_, values):
        before = cloud._sent
        original(cloud, meshcat_, values)
        if cloud._sent is not before:
            sent.append(np.array(values))

    GoalCloud.show = spy
    try:
        Simulator(_cloud_scene(meshcat, objects, probabilities)).AdvanceTo(2.0)
    finally:
        GoalCloud.show = original
    assert meshcat.HasPath("/task/goal_cloud") and not meshcat.HasPath("/task/tables/0")
    # Drawn in its colours at initialisation, and again once at 1 s: two sends in 2 s,
    # whatever the 0.25 s period would allow (nine).
    assert len(sent) == 2
    assert np.argmax(sent[0]) == 0 and np.argmax(sent[1]) == 7


def test_an_object_standing_on_the_floor_is_drawn_without_a_table(meshcat):
    # Its centre half its height up (0.05 m): a table there would have no height.
    draw_table_object(meshcat, 0, [0.55, 0.0, 0.0], (0.3, 0.3), [0.55, 0.0, 0.05], (0.04, 0.1))
    draw_table_object(meshcat, 1, [0.5, 0.3, 0.25], (0.3, 0.3), [0.5, 0.3, 0.3], (0.04, 0.1))
    assert meshcat.HasPath("/task/objects/0") and not meshcat.HasPath("/task/tables/0")
    assert meshcat.HasPath("/task/objects/1") and meshcat.HasPath("/task/tables/1")


def test_the_cloud_colours_the_most_probable_goal_blue_and_the_unlikely_grey():
    class Recorder:
        def SetObject(self, path, cloud, point_size):
            self.colours = np.array(cloud.rgbs())

    recorder = Recorder()
    cloud = GoalCloud("/cloud", np.zeros((3, 3)), 0.05)
    cloud.show(recorder, [0.0, 0.25, 0.5])
    np.testing.assert_array_equal(recorder.colours[:, 2], LIKELY_RGB)
    np.testing.assert_array_equal(recorder.colours[:, 0], UNLIKELY_RGB)
    halfway = recorder.colours[:, 1].astype(float)
    assert (np.minimum(UNLIKELY_RGB, LIKELY_RGB) < halfway).all()
    assert (halfway < np.maximum(UNLIKELY_RGB, LIKELY_RGB)).all()


@pytest.mark.parametrize("build, message", [
    (lambda meshcat: ReachSceneVisualizer(meshcat, []),
     r"objects must be a non-empty finite \(M, 3\) array, got shape \(0,\)"),
    (lambda meshcat: ReachSceneVisualizer(meshcat, [[np.nan, 0.0, 0.4]]),
     r"objects must be a non-empty finite \(M, 3\) array"),
    (lambda meshcat: ReachSceneVisualizer(meshcat, [[0.5, 0.0, 0.4]], publish_period=0.0),
     "publish_period must be positive, got 0.0"),
    (lambda meshcat: PointSceneVisualizer(meshcat, [0.0, 0.0], [[np.nan, 0.0]], []),
     r"goals must be a non-empty finite \(K, D\) array, got \[\[nan, 0.0\]\]"),
    (lambda meshcat: PointSceneVisualizer(meshcat, [0.0, 0.0], [[1.0, 0.0]], [],
                                          publish_period=-1.0),
     "publish_period must be positive, got -1.0"),
])
def test_a_visualizer_names_what_it_cannot_draw(meshcat, build, message):
    with pytest.raises(ValueError, match=message):
        build(meshcat)
