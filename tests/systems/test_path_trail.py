"""The executed path in a 2-D replay (and a teaching run's hand path) is drawn as the robot
goes: at each time of the replay the robot's trail (`/pbp/executed`, `PathTrail`) runs from
the start to where the robot is then, never further, and nothing of it shows before the
robot moves. The trail is a few objects however long (its dots gathered into meshes, their
spacing doubling), still runs from the start, and its dots jump, not slide, when reused.

Checked on Meshcat's recordings (`StaticHtml`, decoded by `replay_tracks`).
"""

import numpy as np
import pytest
from pydrake.geometry import Rgba
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.analysis import Simulator
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial
from replay_tracks import animation_tracks, commands, held_at, recorded_page

from pbp_drake.systems.visualizers.point_scene_visualizer import (
    EXECUTED_SPACING, EXECUTED_Z, PointSceneVisualizer)
from pbp_drake.systems.ports import EeState, Target
from pbp_drake.systems.visualizers.reach_scene_visualizer import (
    TRAIL_SPACING, ReachSceneVisualizer)
from pbp_drake.systems.visualizers.scene_drawing import (
    DOT_FACES, DOT_VERTICES, PathTrail, spheres_mesh)

FPS = 30.0  # replay_tracks.recorded_page's frames per second
DURATION = 1.0


def robot_path(time):
    """Where the robot is at `time` (s): along +x at 1 m/s, bowed sideways."""
    time = np.asarray(time, float)
    return np.stack([time, 0.3 * np.sin(np.pi * time)], axis=-1)


def trail_objects(html, root):
    """`{path: centres (N, 3)}` of the trail's objects in the page: each piece's dots (the
    centres of its mesh's spheres) and each single dot (its centre at the origin)."""
    objects = {}
    for command in commands(html):
        path = command.get("path", "")
        if command.get("type") != "set_object" or not path.startswith(f"{root}/"):
            continue
        if "/pieces/" in path:
            geometry = command["object"]["geometries"][0]["data"]
            position = geometry["attributes"]["position"]
            vertices = np.frombuffer(position["array"].data, np.float32).reshape(
                -1, len(DOT_VERTICES), 3)
            objects[path] = vertices.mean(axis=1)
        else:
            objects[path] = np.zeros((1, 3))
    return objects


def shown_trail(html, root, time):
    """The trail's dots shown at `time` of the replay, in order along the path: the shown
    pieces' in the order they were made, then the shown single dots'."""
    tracks = animation_tracks(html)
    objects = trail_objects(html, root)
    pieces = sorted((path for path in objects if "/pieces/" in path),
                    key=lambda path: int(path.rsplit("/", 1)[1]))
    dots = sorted((path for path in objects if "/dots/" in path),
                  key=lambda path: int(path.rsplit("/", 1)[1]))
    shown = [objects[path] for path in pieces if held_at(tracks, path, ".visible", time)]
    shown += [held_at(tracks, path, ".position", time)[None] for path in dots
              if (path, ".visible") in tracks and held_at(tracks, path, ".visible", time)]
    return np.concatenate(shown) if shown else np.zeros((0, 3))


# Piece meshes hold float32 vertices: their dots' centres are this close.
MESH_TOLERANCE = 1e-6


def simulated(meshcat, diagram):
    return recorded_page(meshcat, lambda: Simulator(diagram).AdvanceTo(DURATION))


@pytest.fixture
def replay(meshcat):
    times = np.linspace(0.0, DURATION, 101)
    positions = robot_path(times)
    velocities = np.gradient(positions, times, axis=0)
    state = PiecewisePolynomial.FirstOrderHold(times, np.hstack([positions, velocities]).T)
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(PointSceneVisualizer(
        meshcat, start=[0.0, 0.0], goals=[[1.0, 0.0]], obstacles=[]))
    source = builder.AddSystem(TrajectorySource(state))
    builder.Connect(source.get_output_port(), visualizer.get_robot_state_input_port())
    return simulated(meshcat, builder.Build())


@pytest.mark.slow
def test_a_2d_replay_shows_no_executed_path_before_the_robot_moves(replay):
    dots = shown_trail(replay, "/pbp/executed", 0.0)
    assert len(dots) <= 1  # at most one, on the start, under the robot
    np.testing.assert_allclose(dots[:, :2], np.zeros((len(dots), 2)), atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("time", [0.3, 0.6, 1.0])
def test_a_2d_replay_shows_the_executed_path_from_the_start_up_to_the_robot(replay, time):
    dots = shown_trail(replay, "/pbp/executed", time)
    travelled = robot_path(np.linspace(0.0, time, 2001))
    # On the path the robot has travelled (within a spacing: a dot lies on the chord
    # between two publishes), never beyond it.
    nearest = np.min(np.linalg.norm(dots[:, None, :2] - travelled[None], axis=2), axis=1)
    assert nearest.max() < EXECUTED_SPACING, f"a dot {nearest.max():.4f} m off the path"
    np.testing.assert_allclose(dots[:, 2], EXECUTED_Z, atol=MESH_TOLERANCE)
    # From the start to the robot, a spacing apart all along.
    np.testing.assert_allclose(dots[0, :2], [0.0, 0.0], atol=MESH_TOLERANCE)
    steps = np.linalg.norm(np.diff(dots[:, :2], axis=0), axis=1)
    np.testing.assert_allclose(steps, EXECUTED_SPACING, atol=2 * MESH_TOLERANCE)
    robot = held_at(animation_tracks(replay), "/pbp/robot", ".position", time)[:2]
    assert np.linalg.norm(dots[-1, :2] - robot) < EXECUTED_SPACING + 1e-9


def test_a_2d_run_s_trail_is_a_few_objects(replay):
    # About 1.2 m of path, 0.004 m apart: some 300 dots in 14 meshes and 20 spheres.
    assert len(shown_trail(replay, "/pbp/executed", DURATION)) > 290
    assert len(trail_objects(replay, "/pbp/executed")) <= 35


def record_trail(meshcat, trail, points_and_times):
    def run():
        trail.draw(meshcat, 0.0)
        for point, time in points_and_times:
            trail.extend(meshcat, point, time)
    return recorded_page(meshcat, run)


def test_a_long_trail_doubles_its_spacing_and_still_runs_from_the_start(meshcat):
    # 3.1 m at 1 m/s, one extend a frame, in pieces of 5 dots, 2 pieces a spacing, 0.1 m
    # apart at first: 1 m at 0.1 m, 2 m at 0.2 m, then 0.4 m (none more before 3.1 m).
    spacing = 0.1
    trail = PathTrail("/trail", 0.01, Rgba(0.1, 0.3, 0.9, 1.0), spacing, piece=5, pieces=2)
    frames = np.arange(0, 94)
    html = record_trail(meshcat, trail, [([frame / FPS, 0.0, 0.0], frame / FPS)
                                         for frame in frames])
    early = shown_trail(html, "/trail", 0.55)
    np.testing.assert_allclose(early[:, 0], np.arange(6) * spacing, atol=MESH_TOLERANCE)
    last = shown_trail(html, "/trail", 3.1)[:, 0]
    expected = np.concatenate([np.arange(10) * spacing, 1.0 + np.arange(10) * 2 * spacing])
    np.testing.assert_allclose(last[:20], expected, atol=MESH_TOLERANCE)
    assert len(last) == 21 and abs(last[20] - 3.0) < MESH_TOLERANCE
    assert len(trail_objects(html, "/trail")) == 5 + 4  # the spheres and four pieces
    # A replay interpolates positions between keys: a sphere used again holds its place up
    # to the frame before, so that it jumps rather than slides there.
    tracks = animation_tracks(html)
    for index in range(5):
        times, positions = tracks[f"/trail/dots/{index}", ".position"]
        moves = np.any(np.diff(positions, axis=0) != 0.0, axis=1)
        assert np.all(np.diff(times)[moves] <= 1.0 / FPS + 1e-9), (
            f"dot {index} slides from {times[:-1][moves]} s to {times[1:][moves]} s")


def test_drawing_the_trail_again_starts_it_again(meshcat):
    trail = PathTrail("/trail", 0.01, Rgba(0.1, 0.3, 0.9, 1.0), 0.1, piece=4)

    def run():
        trail.draw(meshcat, 0.0)
        trail.extend(meshcat, [0.0, 0.0, 0.0], 0.0)
        trail.extend(meshcat, [1.0, 0.0, 0.0], 1.0)  # 11 dots: 2 pieces and 3 spheres
        trail.draw(meshcat, 2.0)  # a second run in the same page
        trail.extend(meshcat, [5.0, 0.0, 0.0], 2.0)
    html = recorded_page(meshcat, run)
    np.testing.assert_allclose(shown_trail(html, "/trail", 1.5)[:, 0], np.arange(11) * 0.1,
                               atol=MESH_TOLERANCE)
    np.testing.assert_allclose(shown_trail(html, "/trail", 2.0), [[5.0, 0.0, 0.0]])


@pytest.mark.slow
def test_a_teaching_run_s_page_shows_the_hand_s_path_as_it_grows(meshcat):
    # `pbp-drake teach` draws the demonstration being recorded (`hand_trail`).
    times = np.linspace(0.0, DURATION, 101)
    hand = np.zeros((len(times), EeState.size))
    hand[:, :2], hand[:, 2] = robot_path(times), 0.7
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(ReachSceneVisualizer(meshcat, [[1.0, 0.0, 0.7]],
                                                        hand_trail=True))
    source = builder.AddSystem(TrajectorySource(PiecewisePolynomial.FirstOrderHold(
        times, hand.T)))
    builder.Connect(source.get_output_port(), visualizer.get_ee_state_input_port())
    for port, value in ((visualizer.get_target_input_port(), np.zeros(Target.size)),
                        (visualizer.get_selected_goal_input_port(), [-1.0])):
        builder.Connect(builder.AddSystem(ConstantVectorSource(value)).get_output_port(),
                        port)
    replay = simulated(meshcat, builder.Build())
    for time in (0.3, 1.0):
        dots = shown_trail(replay, "/task/hand_trail", time)
        travelled = robot_path(np.linspace(0.0, time, 2001))
        nearest = np.min(np.linalg.norm(dots[:, None, :2] - travelled[None], axis=2), axis=1)
        assert nearest.max() < TRAIL_SPACING and len(dots) > 5
        reached = np.linalg.norm(dots[-1, :2] - travelled[-1])
        assert reached < 2 * TRAIL_SPACING, f"the trail ends {reached:.3f} m short"
        np.testing.assert_allclose(dots[:, 2], 0.7, atol=MESH_TOLERANCE)


def test_a_dot_is_a_closed_sphere_of_80_triangles_facing_out():
    np.testing.assert_allclose(np.linalg.norm(DOT_VERTICES, axis=1), 1.0)
    assert DOT_FACES.shape == (80, 3)
    # Every edge is shared by exactly two triangles, in opposite directions: no hole.
    edges = [(a, b) for face in DOT_FACES for a, b in zip(face, np.roll(face, -1))]
    assert len(set(edges)) == len(edges)
    assert all((b, a) in set(edges) for a, b in edges)
    # Its triangles face out: the volume they enclose is positive, near a unit ball's.
    a, b, c = (DOT_VERTICES[DOT_FACES[:, i]] for i in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    assert 0.7 * 4.0 / 3.0 * np.pi < volume < 4.0 / 3.0 * np.pi
    vertices, faces = spheres_mesh([[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]], 0.5)
    assert vertices.shape == (3, 2 * len(DOT_VERTICES)) and faces.shape == (3, 160)
    np.testing.assert_allclose(vertices[:, :len(DOT_VERTICES)].mean(axis=1), [1.0, 2.0, 3.0])
