"""The paper's 2-D experiments from the command line, checked against the issue's bar."""

import base64
import json
import re

import msgpack
import numpy as np
import pytest

from pbp_drake.cli import main

# Whole tasks, studies, notebooks, browsers or pip: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def alpha_study(tmp_path_factory):
    repo = __import__("pathlib").Path(__file__).resolve().parents[2]
    output = tmp_path_factory.mktemp("alpha_study")
    assert main(["study", str(repo / "diagrams/toy_alpha_study.yaml"), "--output",
                 str(output)]) == 0
    return output


def test_alpha_study_shows_no_alpha_transfers(alpha_study):
    summary = json.loads((alpha_study / "summary.json").read_text())
    scenes = {scene["name"]: scene["by_operator_speed"] for scene in summary["scenes"]}
    assert list(scenes) == ["scene_1", "scene_2", "scene_3", "scene_4"]
    assert summary["operator_speeds"] == [1.0, 2.0]
    for by_speed in scenes.values():
        assert list(by_speed) == ["1", "2"]
        for results in by_speed.values():
            fixed = results["fixed_alpha"]
            assert len(fixed) == 11
            # Alpha 1 ignores the operator: the demonstration runs into the moved obstacle.
            assert fixed["1.00"]["collision_ratio"] > 0
            # The ideal alpha is the highest collision-free one (reaching is not judged).
            safe = [float(a) for a, outcome in fixed.items() if outcome["collision_ratio"] == 0]
            assert results["ideal_alpha"] == max(safe)
            # PBP-Alt never collides: while the operator acts the DMP's phase stands still.
            assert results["pbp_alternated"]["collision_ratio"] == 0.0
    assert abs(scenes["scene_1"]["2"]["ideal_alpha"] - scenes["scene_2"]["2"]["ideal_alpha"]
               ) >= 0.3 - 1e-9
    # The paper's two scenes at our speed 2: PBP-Cont passes untouched too.
    for name in ("scene_1", "scene_2"):
        assert scenes[name]["2"]["pbp_continuous"]["collision_ratio"] == 0.0


def test_alpha_study_reports_where_pbp_ends_short_of_the_goal(alpha_study):
    summary = json.loads((alpha_study / "summary.json").read_text())
    tolerance = summary["goal_tolerance"]
    for scene in summary["scenes"]:
        for results in scene["by_operator_speed"].values():
            for outcome in [results["pbp_alternated"], results["pbp_continuous"],
                            *results["fixed_alpha"].values()]:
                assert outcome["reached"] == (outcome["final_distance"] <= tolerance)
            assert results["measured_operator_speed"] == results["operator_speed"]
    goal_near = summary["scenes"][3]["by_operator_speed"]
    for results in goal_near.values():
        # The goal lies within the operator's reach of the obstacle: it keeps pushing away.
        for method in ("pbp_alternated", "pbp_continuous"):
            assert not results[method]["reached"]
            assert results[method]["final_distance"] > 0.1
        # Only alpha 1, which ignores the operator (and collides), reaches it.
        assert [a for a, o in results["fixed_alpha"].items() if o["reached"]] == ["1.00"]


def test_alpha_study_gets_its_summary_as_a_markdown_table(alpha_study, tmp_path):
    markdown = tmp_path / "alpha_study.md"
    assert main(["report", str(alpha_study), "--markdown", str(markdown)]) == 0
    lines = markdown.read_text().splitlines()
    assert lines[0].startswith("`pbp-drake study ") and "toy_alpha_study.yaml`" in lines[0]
    assert "4 scenes at operator speeds 1, 2" in lines[0]
    rows = [line for line in lines if line.startswith("| ")]
    assert rows[0].startswith("| scene | operator speed | ideal alpha | alpha 0.00 |")
    assert rows[0].endswith("| alpha 1.00 | PBP-Alt | PBP-Cont |")
    assert len(rows) == 1 + 4 * 2
    # A row is the summary's: scene_1 at speed 1, its ideal alpha, then PBP-Alt's cell.
    summary = json.loads((alpha_study / "summary.json").read_text())
    first = summary["scenes"][0]["by_operator_speed"]["1"]
    alternated = first["pbp_alternated"]
    cells = rows[1].strip("| ").split(" | ")
    assert cells[:3] == ["scene_1", "1", f"{first['ideal_alpha']:g}"]
    assert cells[-2] == (f"{alternated['collision_ratio']:.3f} / "
                         f"{'yes' if alternated['reached'] else 'no'}")
    assert lines[-1] == f"Figure: `{alpha_study / 'fig2_alpha_study.png'}`."


def test_alpha_study_draws_the_four_panel_figure(alpha_study):
    import matplotlib.image

    image = matplotlib.image.imread(alpha_study / "fig2_alpha_study.png")
    assert image.shape[0] > 600 and image.shape[1] > 900
    # Not a blank canvas: many distinct colours.
    assert len(np.unique(image.reshape(-1, image.shape[-1])[::50], axis=0)) > 100


def test_alt_vs_cont_locks_the_phase_only_in_alternated_mode(tmp_path, repo):
    assert main(["study", str(repo / "diagrams/toy_alt_vs_cont.yaml"), "--output",
                 str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    alternated = summary["modes"]["pbp_alternated"]
    continuous = summary["modes"]["pbp_continuous"]
    for mode in (alternated, continuous):
        phase = np.asarray(mode["phase"])
        acting = np.asarray(mode["operator_active"], bool)
        assert acting.sum() >= 30, "the input must act for a while"
        assert mode["final_error"] <= 0.01
        assert len(phase) == len(mode["times"])
    phase = np.asarray(alternated["phase"])
    acting = np.asarray(alternated["operator_active"], bool)[:-1]
    assert np.all(np.diff(phase)[acting] == 0.0)
    assert np.all(np.diff(phase)[~acting] > 0.0)
    assert np.all(np.diff(continuous["phase"]) > 0.0)
    assert alternated["phase_constant_while_operator_acts"]
    assert continuous["phase_strictly_increasing"]
    assert summary["both_reach_goal"]
    # Same input, strikingly different paths.
    difference = np.abs(np.asarray(alternated["positions"]) - continuous["positions"]).max()
    assert difference > 0.05
    assert (tmp_path / "fig4_alt_vs_cont.png").stat().st_size > 20_000


def test_run_saves_a_self_contained_replay(tmp_path, repo, capsys):
    replay = tmp_path / "replay.html"
    assert main(["run", str(repo / "diagrams/toy_alpha_study.yaml"), "--scene", "scene_2",
                 "--method", "pbp_continuous", "--headless", "--record", str(replay)]) == 0
    out = capsys.readouterr().out
    assert "http://" not in out  # a headless run has no page to open
    assert "collision ratio 0.000" in out
    html = replay.read_text()
    # Self-contained: the viewer is inlined, no script loaded from elsewhere.
    assert "<script src=" not in html
    # The recorded animation moves the robot: decode the embedded Meshcat commands.
    blobs = re.findall(r'fetch\("data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"\)',
                       html)
    commands = [msgpack.unpackb(base64.b64decode(blob), strict_map_key=False)
                for blob in blobs]
    animations = [c for c in commands if c.get("type") == "set_animation"]
    assert len(animations) == 1
    clips = {clip["path"]: clip["clip"] for clip in animations[0]["animations"]}
    track = [t for t in clips["/pbp/robot"]["tracks"] if t["name"] == ".position"][0]
    positions = np.array([key["value"] for key in track["keys"]])
    assert len(positions) >= 55  # 2 s at 30 frames per second
    np.testing.assert_allclose(positions[-1, :2], [1.0, 0.0], atol=0.01)  # at the goal
    # Every frame stays outside scene_2's obstacle, which sits on the demonstrated path.
    assert np.linalg.norm(positions[:, :2] - [0.5, 0.4], axis=1).min() > 0.12
