"""The grasping task's Meshcat drawing: a triad at every grasp pose, drawn on
initialisation, and a recording in which the predicted path's triads move and turn as the
path did. (The page itself is checked in tests/e2e/test_grasp_triads_in_browser.py.)"""

import dataclasses

import msgpack
import numpy as np
import pytest
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial
from replay_tracks import commands, held_at, recorded, value_at

from pbp_drake.core.grasp_task import (
    approach_direction, sample_grasp_scene, side_grasp_orientation)
from pbp_drake.core.quaternion import angle_between
from pbp_drake.systems.visualizers.grasp_scene_visualizer import (
    PATH_TRIADS, TRIAD_LENGTH, GraspSceneVisualizer)
from pbp_drake.systems.ports import Target

SCENE = sample_grasp_scene(3)  # four objects, one grasped from above
STEPS = 10
START = np.array([0.6, 0.0, 0.8])


def add_source(builder, value, port):
    source = builder.AddSystem(ConstantVectorSource(np.asarray(value, float)))
    builder.Connect(source.get_output_port(), port)


def grasp_diagram(meshcat, predicted=None, hand=None, selected=0):
    """The visualizer with the target object 1, the estimate `selected`, and optionally a
    source of predicted poses (a trajectory) and a hand pose."""
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(GraspSceneVisualizer(meshcat, SCENE, STEPS))
    target = np.zeros(Target.size)
    target[:3], target[3] = SCENE.objects[1], 1
    add_source(builder, target, visualizer.get_target_input_port())
    add_source(builder, [float(selected)], visualizer.get_selected_goal_input_port())
    if predicted is not None:
        source = builder.AddSystem(TrajectorySource(predicted))
        builder.Connect(source.get_output_port(), visualizer.get_predicted_poses_input_port())
    if hand is not None:
        add_source(builder, hand, visualizer.get_hand_state_input_port())
    return builder.Build()


def straight_path(goal, orientation_from, orientation_to):
    """STEPS + 1 poses from START to `goal`, turning linearly (renormalised by the drawing)."""
    fractions = np.linspace(0.0, 1.0, STEPS + 1)[:, None]
    positions = START + fractions * (goal - START)
    orientations = (1 - fractions) * orientation_from + fractions * orientation_to
    orientations /= np.linalg.norm(orientations, axis=1, keepdims=True)
    return np.hstack([positions, orientations])


@pytest.fixture
def meshcat():
    return Meshcat(MeshcatParams(host="localhost", port=0))  # any free port; this thread only


def test_every_grasp_pose_is_drawn_as_a_triad_on_initialisation(meshcat):
    diagram = grasp_diagram(meshcat)
    triads = [f"/task/grasps/{k}/{axis}" for k in range(len(SCENE.objects))
              for axis in "xyz"]
    assert not any(meshcat.HasPath(path) for path in triads)
    Simulator(diagram).Initialize()
    assert all(meshcat.HasPath(path) for path in triads)


def test_the_estimate_ball_is_hidden_while_the_robot_shows_no_grasp(meshcat):
    def ball_visible(selected):
        simulator = Simulator(grasp_diagram(meshcat, selected=selected))
        simulator.AdvanceTo(0.1)
        packed = meshcat._GetPackedProperty("/task/estimated_goal", "visible")
        return msgpack.unpackb(packed, raw=False)["value"] if packed else True

    assert not ball_visible(-1)  # teleop, or a robot following a group of grasps
    assert ball_visible(2)


def test_a_replay_moves_and_turns_the_predicted_paths_triads(meshcat):
    # Over a second the path swings from the side grasp of object 0 to the top grasp of
    # object 1: the triads along it move, and the last one turns from one grasp to the other.
    ready = side_grasp_orientation(0.0)
    first = straight_path(SCENE.grasp_positions[0], ready, SCENE.grasp_orientations[0])
    second = straight_path(SCENE.grasp_positions[1], ready, SCENE.grasp_orientations[1])
    predicted = PiecewisePolynomial.FirstOrderHold(
        [0.0, 1.0], np.column_stack([first.ravel(), second.ravel()]))
    hand = np.concatenate([START, ready, np.zeros(6)])
    tracks = recorded(meshcat, grasp_diagram(meshcat, predicted, hand), 1.0)
    last = f"/task/prediction/{PATH_TRIADS - 1}"

    def pose_at(path, time):
        return (value_at(tracks, path, ".position", time),
                value_at(tracks, path, ".quaternion", time))

    for time, path in [(0.0, first), (1.0, second)]:
        position, quaternion = pose_at(last, time)
        np.testing.assert_allclose(position, path[-1, :3], atol=1e-9)
        # Meshcat (three.js) keeps quaternions as (x, y, z, w).
        assert angle_between(np.roll(quaternion, 1), path[-1, 3:]) < 1e-6
        start, _ = pose_at("/task/prediction/0", time)
        np.testing.assert_allclose(start, START, atol=1e-9)  # the path starts at the hand
    middle = [pose_at(f"/task/prediction/{PATH_TRIADS // 2}", t)[0] for t in (0.0, 1.0)]
    assert np.linalg.norm(middle[1] - middle[0]) > 0.2  # the triads along it moved too
    position, quaternion = pose_at("/task/hand", 0.5)
    np.testing.assert_allclose(position, START)
    assert angle_between(np.roll(quaternion, 1), ready) < 1e-9


def test_a_path_that_only_turns_spreads_its_triads_over_its_turn(meshcat):
    # The hand stays at START and turns to object 1's grasp: no arc length to spread the
    # triads along, so they are spread along the samples, from the first to the last turn.
    ready = side_grasp_orientation(0.0)
    turning = straight_path(START, ready, SCENE.grasp_orientations[1])
    predicted = PiecewisePolynomial.ZeroOrderHold([0.0, 1.0],
                                                  np.column_stack([turning.ravel()] * 2))
    tracks = recorded(meshcat, grasp_diagram(meshcat, predicted), 0.3)
    turns = [np.roll(value_at(tracks, f"/task/prediction/{index}", ".quaternion", 0.2), 1)
             for index in range(PATH_TRIADS)]
    assert angle_between(turns[0], ready) < 1e-6
    assert angle_between(turns[-1], SCENE.grasp_orientations[1]) < 1e-6
    angles = [angle_between(turn, ready) for turn in turns]
    assert all(np.diff(angles) > 0.0)  # each triad turned further than the one before


def transforms(html):
    """The last 4x4 transform the page was sent for each path."""
    return {command["path"]: np.array(command["matrix"]).reshape(4, 4).T
            for command in commands(html) if command.get("type") == "set_transform"}


def test_each_grasp_triad_stands_at_its_grasp_with_blue_along_the_approach(meshcat):
    Simulator(grasp_diagram(meshcat)).Initialize()
    sent = transforms(meshcat.StaticHtml())
    for k, (position, orientation) in enumerate(zip(SCENE.grasp_positions,
                                                    SCENE.grasp_orientations)):
        triad = sent[f"/task/grasps/{k}"]
        np.testing.assert_allclose(triad[:3, 3], position, atol=1e-12)
        # Each cylinder's centre, in the world: half the triad's length along its axis.
        for axis, direction in zip("xyz", np.eye(3)):
            centre = (triad @ sent[f"/task/grasps/{k}/{axis}"])[:3, 3]
            world_axis = triad[:3, :3] @ direction
            np.testing.assert_allclose(centre, position + TRIAD_LENGTH / 2 * world_axis,
                                       atol=1e-12)
        z_axis = triad[:3, :3] @ [0, 0, 1.0]
        np.testing.assert_allclose(z_axis, approach_direction(orientation), atol=1e-12)
    # A top grasp's blue axis points straight down at its object.
    top = SCENE.approaches.index("top")
    np.testing.assert_allclose(sent[f"/task/grasps/{top}"][:3, 2], [0, 0, -1], atol=1e-9)


def many_grasps():
    """120 grasps (the 4 of SCENE, 30 times, shifted along y): past SOLID_OBJECTS."""
    shifts = np.repeat(np.arange(30) * 0.01, 4)[:, None] * [0.0, 1.0, 0.0]
    return dataclasses.replace(
        SCENE, objects=np.tile(SCENE.objects, (30, 1)) + shifts,
        tables=np.tile(SCENE.tables, (30, 1)) + shifts,
        approaches=SCENE.approaches * 30,
        approach_angles=np.tile(SCENE.approach_angles, 30),
        grasp_positions=np.tile(SCENE.grasp_positions, (30, 1)) + shifts,
        grasp_orientations=np.tile(SCENE.grasp_orientations, (30, 1)))


def test_many_grasps_are_a_cloud_and_the_likeliest_grasps_triads_that_a_replay_keeps(meshcat):
    # Past SOLID_OBJECTS: no table, object or triad per grasp, but the goal cloud and three
    # triads moved to the selected grasp (0) and the likeliest others (7 at first, then 42
    # from 0.5 s).
    many = many_grasps()
    count = len(many.grasp_positions)
    before, after = np.full(count, 1e-3), np.full(count, 1e-3)
    before[7], after[42] = 0.5, 0.5
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(GraspSceneVisualizer(meshcat, many, STEPS,
                                                        likely_triads=3))
    target = np.zeros(Target.size)
    target[:3], target[3] = many.objects[1], 1
    add_source(builder, target, visualizer.get_target_input_port())
    add_source(builder, [0.0], visualizer.get_selected_goal_input_port())
    source = builder.AddSystem(TrajectorySource(PiecewisePolynomial.ZeroOrderHold(
        [0.0, 0.5, 1.0], np.column_stack([before, after, after]))))
    builder.Connect(source.get_output_port(), visualizer.get_goal_probabilities_input_port())
    tracks = recorded(meshcat, builder.Build(), 1.0)
    assert meshcat.HasPath("/task/goal_cloud")
    assert not any(meshcat.HasPath(f"/task/{kind}/0") for kind in ("grasps", "tables", "objects"))
    assert all(meshcat.HasPath(f"/task/likely_grasps/{i}") for i in range(3))
    assert not meshcat.HasPath("/task/likely_grasps/3")
    for time, likeliest in [(0.2, 7), (0.9, 42)]:
        np.testing.assert_allclose(
            value_at(tracks, "/task/likely_grasps/0", ".position", time),
            many.grasp_positions[0], atol=1e-9)
        np.testing.assert_allclose(
            value_at(tracks, "/task/likely_grasps/1", ".position", time),
            many.grasp_positions[likeliest], atol=1e-9)


@pytest.mark.parametrize("selected, probabilities, shown", [
    (-1, True, 42),  # no grasp shown: the likeliest leads
    (5, False, 5),  # no probabilities: the grasp shown alone
])
def test_the_likely_triads_follow_what_is_known(meshcat, selected, probabilities, shown):
    many = many_grasps()
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(GraspSceneVisualizer(meshcat, many, likely_triads=3))
    target = np.zeros(Target.size)
    target[:3], target[3] = many.objects[1], 1
    add_source(builder, target, visualizer.get_target_input_port())
    add_source(builder, [float(selected)], visualizer.get_selected_goal_input_port())
    if probabilities:
        likely = np.full(len(many.grasp_positions), 1e-3)
        likely[42] = 0.5
        add_source(builder, likely, visualizer.get_goal_probabilities_input_port())
    tracks = recorded(meshcat, builder.Build(), 0.3)
    np.testing.assert_allclose(value_at(tracks, "/task/likely_grasps/0", ".position", 0.2),
                               many.grasp_positions[shown], atol=1e-9)
    assert held_at(tracks, "/task/likely_grasps/1", ".visible", 0.2) == probabilities


def test_a_target_that_is_no_object_is_refused(meshcat):
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(GraspSceneVisualizer(meshcat, SCENE))
    target = np.zeros(Target.size)
    target[3] = 9
    add_source(builder, target, visualizer.get_target_input_port())
    add_source(builder, [0.0], visualizer.get_selected_goal_input_port())
    with pytest.raises(ValueError, match="target index 9 is not one of the 4 objects"):
        Simulator(builder.Build()).Initialize()
