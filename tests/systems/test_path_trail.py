"""The executed path in a 2-D replay (and a teaching run's hand path) is drawn as the robot
goes: at each time of the replay the robot's trail (`/pbp/executed`, `PathTrail`) runs from
the start to where the robot is then, never further, and nothing of it shows before the
robot moves. A trail longer than
its dots thins and still runs from the start, and its dots jump, not slide, when it does.

Checked on Meshcat's recordings (`StaticHtml`, decoded by `replay_tracks`).
"""

import numpy as np
import pytest
from pydrake.geometry import Rgba
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial
from replay_tracks import animation_tracks, held_at, recorded

from pbp_drake.systems.visualizers.point_scene_visualizer import (
    EXECUTED_DOTS, EXECUTED_SPACING, EXECUTED_Z, PointSceneVisualizer)
from pbp_drake.systems.ports import EeState, Target
from pbp_drake.systems.visualizers.reach_scene_visualizer import (
    TRAIL_DOTS, TRAIL_SPACING, ReachSceneVisualizer)
from pbp_drake.systems.visualizers.scene_drawing import PathTrail

FPS = 30.0  # replay_tracks.recorded's frames per second
DURATION = 1.0


def robot_path(time):
    """Where the robot is at `time` (s): along +x at 1 m/s, bowed sideways."""
    time = np.asarray(time, float)
    return np.stack([time, 0.3 * np.sin(np.pi * time)], axis=-1)


def shown_dots(tracks, root, count, time):
    """The positions of the trail's dots shown at `time` of the replay, in pool order."""
    return np.array([held_at(tracks, f"{root}/{index}", ".position", time)
                     for index in range(count)
                     if held_at(tracks, f"{root}/{index}", ".visible", time)]).reshape(-1, 3)


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
    return recorded(meshcat, builder.Build(), DURATION)


@pytest.mark.slow
def test_a_2d_replay_shows_no_executed_path_before_the_robot_moves(replay):
    dots = shown_dots(replay, "/pbp/executed", EXECUTED_DOTS, 0.0)
    assert len(dots) <= 1  # at most one, on the start, under the robot
    np.testing.assert_allclose(dots[:, :2], np.zeros((len(dots), 2)), atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("time", [0.3, 0.6, 1.0])
def test_a_2d_replay_shows_the_executed_path_from_the_start_up_to_the_robot(replay, time):
    dots = shown_dots(replay, "/pbp/executed", EXECUTED_DOTS, time)
    travelled = robot_path(np.linspace(0.0, time, 2001))
    # On the path the robot has travelled (within a spacing: a dot lies on the chord
    # between two publishes), never beyond it.
    nearest = np.min(np.linalg.norm(dots[:, None, :2] - travelled[None], axis=2), axis=1)
    assert nearest.max() < EXECUTED_SPACING, f"a dot {nearest.max():.4f} m off the path"
    np.testing.assert_allclose(dots[:, 2], EXECUTED_Z)
    # From the start to the robot, a spacing apart all along.
    np.testing.assert_allclose(dots[0, :2], [0.0, 0.0], atol=1e-9)
    steps = np.linalg.norm(np.diff(dots[:, :2], axis=0), axis=1)
    np.testing.assert_allclose(steps, EXECUTED_SPACING, rtol=1e-6)
    robot = held_at(replay, "/pbp/robot", ".position", time)[:2]
    assert np.linalg.norm(dots[-1, :2] - robot) < EXECUTED_SPACING + 1e-9


def record_trail(meshcat, trail, points_and_times):
    meshcat.StartRecording(frames_per_second=FPS)
    trail.draw(meshcat, 0.0)
    for point, time in points_and_times:
        trail.extend(meshcat, point, time)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    return animation_tracks(meshcat.StaticHtml())


def test_a_trail_longer_than_its_dots_thins_and_still_runs_from_the_start(meshcat):
    # 3 m at 1 m/s, one extend a frame, for 10 dots 0.1 m apart: thinned twice, at 0.9 m
    # (spacing 0.2) and 1.8 m (spacing 0.4).
    count, spacing = 10, 0.1
    trail = PathTrail("/trail", count, 0.01, Rgba(0.1, 0.3, 0.9, 1.0), spacing)
    frames = np.arange(0, 91)
    tracks = record_trail(meshcat, trail, [([frame / FPS, 0.0, 0.0], frame / FPS)
                                           for frame in frames])
    early = shown_dots(tracks, "/trail", count, 0.55)
    np.testing.assert_allclose(early[:, 0], np.arange(6) * spacing, atol=1e-9)
    last = shown_dots(tracks, "/trail", count, 3.0)
    np.testing.assert_allclose(last[:, 0], np.arange(len(last)) * 4 * spacing, atol=1e-9)
    assert 3.0 - 4 * spacing <= last[-1, 0] <= 3.0
    # A replay interpolates positions between keys: a dot that moved when the trail thinned
    # holds its place up to the frame before, so that it jumps rather than slides there.
    for index in range(count):
        times, positions = tracks[f"/trail/{index}", ".position"]
        moves = np.any(np.diff(positions, axis=0) != 0.0, axis=1)
        assert np.all(np.diff(times)[moves] <= 1.0 / FPS + 1e-9), (
            f"dot {index} slides from {times[:-1][moves]} s to {times[1:][moves]} s")


def test_drawing_the_trail_again_starts_it_again(meshcat):
    trail = PathTrail("/trail", 20, 0.01, Rgba(0.1, 0.3, 0.9, 1.0), 0.1)
    meshcat.StartRecording(frames_per_second=FPS)
    trail.draw(meshcat, 0.0)
    trail.extend(meshcat, [0.0, 0.0, 0.0], 0.0)
    trail.extend(meshcat, [1.0, 0.0, 0.0], 1.0)  # 11 dots
    trail.draw(meshcat, 2.0)  # a second run in the same page
    trail.extend(meshcat, [5.0, 0.0, 0.0], 2.0)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    tracks = animation_tracks(meshcat.StaticHtml())
    assert len(shown_dots(tracks, "/trail", 20, 1.5)) == 11
    np.testing.assert_allclose(shown_dots(tracks, "/trail", 20, 2.0), [[5.0, 0.0, 0.0]])


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
    replay = recorded(meshcat, builder.Build(), DURATION)
    for time in (0.3, 1.0):
        dots = shown_dots(replay, "/task/hand_trail", TRAIL_DOTS, time)
        travelled = robot_path(np.linspace(0.0, time, 2001))
        nearest = np.min(np.linalg.norm(dots[:, None, :2] - travelled[None], axis=2), axis=1)
        assert nearest.max() < TRAIL_SPACING and len(dots) > 5
        reached = np.linalg.norm(dots[-1, :2] - travelled[-1])
        assert reached < 2 * TRAIL_SPACING, f"the trail ends {reached:.3f} m short"
        np.testing.assert_allclose(dots[:, 2], 0.7)
