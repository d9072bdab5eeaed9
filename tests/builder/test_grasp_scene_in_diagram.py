"""The grasping task drawn in Meshcat by its own diagram: a recording of a PBP-Alt
run with the virtual participant shows the selected DMP's predicted path ending at the
estimated goal's grasp pose and starting at the hand, and the hand's triad where the hand
is; without Meshcat nothing is predicted at all."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from replay_tracks import animation_tracks, value_at

from pbp_drake.builder import build_diagram
from pbp_drake.builder.grasp import GRASP_PREDICTION_SAMPLES
from pbp_drake.core.quaternion import angle_between
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.systems.visualizers.grasp_scene_visualizer import PATH_TRIADS

DURATION = 1.5


@pytest.fixture(scope="module")
def grasp(repo):
    return load_scenario_file(repo / "diagrams" / "hsr_grasp.yaml").resolved


@pytest.mark.slow
def test_the_replay_shows_the_selected_dmps_path_to_its_grasp(grasp, meshcat):
    diagram = build_diagram(grasp, meshcat)
    meshcat.StartRecording(frames_per_second=30.0)
    simulator = Simulator(diagram)
    simulator.AdvanceTo(DURATION)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    tracks = animation_tracks(meshcat.StaticHtml())
    context = simulator.get_context()
    grasps = grasp.scene.grasps
    # The path's last triad, at the last path publish (every 0.1 s): the DMP's rollout over
    # its duration ends at (nearly) its goal, the estimated goal's grasp pose. The estimate
    # may change from tick to tick: the one drawn is that of the tick the publish fell in,
    # logged (one sample late, as every decision) within a tick of it.
    shown = 1.4
    log = diagram.GetSubsystemByName("selected_goal_log").FindLog(context)
    near = np.abs(log.sample_times() - shown) <= grasp.scenario.control_period
    last = f"/task/prediction/{PATH_TRIADS - 1}"
    position = value_at(tracks, last, ".position", shown)
    reached = np.linalg.norm(grasps.grasp_positions - position, axis=1)
    selected = int(np.argmin(reached))
    assert reached[selected] < 0.01
    assert selected in log.data()[0, near].astype(int), "the path ends at no estimated grasp"
    # Meshcat (three.js) keeps quaternions as (x, y, z, w).
    turn = np.roll(value_at(tracks, last, ".quaternion", shown), 1)
    assert np.degrees(angle_between(turn, grasps.grasp_orientations[selected])) < 2.0
    # The path starts at the hand, and the hand's triad is drawn where the hand is.
    hand = value_at(tracks, "/task/hand", ".position", shown)
    start = value_at(tracks, "/task/prediction/0", ".position", shown)
    assert np.linalg.norm(start - hand) < 0.05
    station = diagram.GetSubsystemByName("hsr_station")
    now = np.asarray(station.GetOutputPort("hand_pose").Eval(
        station.GetMyContextFromRoot(context)))[:3]
    # The hand moves at most 0.12 m/s: within 0.1 s of its last drawing it is near it.
    assert np.linalg.norm(value_at(tracks, "/task/hand", ".position", DURATION) - now) < 0.02


def test_without_meshcat_the_pose_bank_predicts_nothing(grasp):
    bank = build_diagram(grasp).GetSubsystemByName("dmp_bank")
    assert not bank.HasOutputPort("predicted_poses")
    assert GRASP_PREDICTION_SAMPLES > 0


@pytest.mark.slow
def test_the_grasp_dmps_last_the_duration_the_scenario_was_checked_for(grasp):
    # resolve checks the DMPs' duration (at least a control tick); the bank must run that one,
    # derived from the palm's start and the grasps, not a second one of its own.
    bank = build_diagram(grasp).GetSubsystemByName("dmp_bank")
    assert bank.position_bank.duration == grasp.controller.dmp_duration
    assert grasp.controller.dmp_duration > grasp.scenario.control_period
