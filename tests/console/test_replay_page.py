"""What `mark_replay` makes of Meshcat's StaticHtml for `pbp-drake run --record`: the
replay's marker, a script that pauses the recording at 0 s once it loads (put before any
of the page's commands is decoded), a line saying how to play it and, for a 2-D scene only,
a key of its colours; the recording itself unchanged. (tests/e2e/test_replay_screenshots.py
opens such pages in a browser.)"""

import numpy as np
import pytest
from pydrake.geometry import Rgba, Sphere
from pydrake.math import RigidTransform
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource
from replay_tracks import commands

from pbp_drake.output_paths import (
    LEGEND_ID, PAUSED_AT_START, REPLAY_HINT_ID, REPLAY_MARKER, is_replay, mark_replay)
from pbp_drake.scenarios import Obstacle
from pbp_drake.systems.visualizers.point_scene_visualizer import LEGEND, PointSceneVisualizer


def static_html(meshcat, draw):
    """StaticHtml of a short recording of what `draw(meshcat)` records."""
    meshcat.StartRecording(frames_per_second=30.0)
    draw(meshcat)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    return meshcat.StaticHtml()


def run_a_2d_scene(meshcat):
    """0.2 s of a 2-D scene with all it draws: an obstacle, the demonstration, the robot
    with the operator acting, its executed path and a DMP's predicted path."""
    steps = 2
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(PointSceneVisualizer(
        meshcat, start=[0.0, 0.0], goals=[[1.0, 0.0]],
        obstacles=[Obstacle(center=[0.5, 0.2], radius=0.1)],
        demonstration=np.array([[0.0, 0.0], [0.5, 0.1], [1.0, 0.0]]),
        prediction_steps=steps))
    for value, port in [([0.3, 0.0, 0.0, 0.0], visualizer.get_robot_state_input_port()),
                        ([1.0], visualizer.get_operator_active_input_port()),
                        (np.linspace([0.3, 0.0], [1.0, 0.0], steps + 1).ravel(),
                         visualizer.get_predicted_paths_input_port())]:
        source = builder.AddSystem(ConstantVectorSource(np.asarray(value, float)))
        builder.Connect(source.get_output_port(), port)
    Simulator(builder.Build()).AdvanceTo(0.2)


def draw_a_task_target(meshcat):
    # What an HSR task draws: its markers under /task, none under /pbp.
    meshcat.SetObject("/task/target", Sphere(0.06), Rgba(1.0, 0.9, 0.0, 1.0))
    for time in [0.0, 0.5]:
        meshcat.SetTransform("/task/target", RigidTransform([time, 0.0, 0.8]), time)


@pytest.mark.slow
def test_a_2d_replay_opens_paused_with_a_key_of_the_scene_colours(meshcat, tmp_path):
    html = static_html(meshcat, run_a_2d_scene)
    replay = mark_replay(html)
    assert replay.startswith(f"<!DOCTYPE html>\n{REPLAY_MARKER}\n")
    # The pause goes in once, after the viewer is made and before any command is decoded.
    assert replay.count(PAUSED_AT_START) == 1
    pause = replay.index(PAUSED_AT_START)
    first_command = replay.index('fetch("data:application/octet-binary;base64,')
    assert replay.index("var viewer = new MeshCat.Viewer(") < pause < first_command
    key = replay[replay.index(f'<div id="{LEGEND_ID}"'):]
    key = key[:key.index("</div></div>")]
    for name, colour in LEGEND:
        assert name in key
        assert (f"rgba({round(255 * colour.r())}, {round(255 * colour.g())}, "
                f"{round(255 * colour.b())}, {colour.a():g})") in key
    assert replay.index(f'id="{REPLAY_HINT_ID}"') < replay.rindex("</body>")
    assert commands(replay) == commands(html)  # the recording is untouched
    (tmp_path / "replay.html").write_text(replay)
    assert is_replay(tmp_path / "replay.html")


@pytest.mark.slow
def test_a_task_replay_opens_paused_without_the_2d_key(meshcat):
    html = static_html(meshcat, draw_a_task_target)
    replay = mark_replay(html)
    assert replay.count(PAUSED_AT_START) == 1 and f'id="{REPLAY_HINT_ID}"' in replay
    assert LEGEND_ID not in replay
    assert commands(replay) == commands(html)


def test_a_page_without_meshcat_s_viewer_gets_the_marker_alone():
    page = "<!DOCTYPE html>\n<html><body><p>not a replay</p></body></html>"
    assert mark_replay(page) == page.replace("\n", f"\n{REPLAY_MARKER}\n", 1)


def colour_bytes(colour):
    """`(r, g, b)` 0..255 and the opacity of an Rgba, as Meshcat's materials hold them."""
    return np.array([colour.r(), colour.g(), colour.b()]) * 255, colour.a()


@pytest.mark.slow
def test_the_key_lists_every_colour_the_2d_scene_draws_and_no_other(meshcat):
    drawn = []
    for command in commands(static_html(meshcat, run_a_2d_scene)):
        if command["type"] == "set_object" and command["path"].startswith("/pbp/"):
            for material in command["object"].get("materials", []):
                rgb = [(material["color"] >> shift) & 0xFF for shift in (16, 8, 0)]
                drawn.append((command["path"], np.array(rgb), material.get("opacity", 1.0)))
    listed = [(name, *colour_bytes(colour)) for name, colour in LEGEND]

    def matches(rgb, opacity, key_rgb, key_opacity):
        # Drake writes a channel as int(255 * value): within one of 255 * value.
        return np.all(np.abs(rgb - key_rgb) <= 1.0) and abs(opacity - key_opacity) < 1e-6

    unlisted = [path for path, rgb, opacity in drawn
                if not any(matches(rgb, opacity, *key[1:]) for key in listed)]
    assert unlisted == [], f"drawn in colours the key does not list: {unlisted}"
    undrawn = [name for name, *key in listed
               if not any(matches(rgb, opacity, *key) for _, rgb, opacity in drawn)]
    assert undrawn == [], f"the key lists colours the scene does not draw: {undrawn}"
