"""`pbp-drake teach`: a primitive taught by the virtual operator, named by a scenario beside
it and run headless; taught again from the drive's CSV; bad primitives and recordings
refused in one line naming the file (exit 2)."""

import csv
import errno
import json
import os
import pathlib
import shutil

import numpy as np
import pytest

from pbp_drake.cli import main
from pbp_drake.commands import teach
from pbp_drake.core.dmp.primitive import FORMAT_VERSION
from pbp_drake.output_paths import REPLAY_MARKER

REPO = pathlib.Path(__file__).resolve().parents[2]
REACH = REPO / "diagrams" / "hsr_reach.yaml"


def run(*argv, capsys):
    code = main([str(arg) for arg in argv])
    return code, capsys.readouterr()


@pytest.fixture(scope="module")
def taught(tmp_path_factory):
    """A folder with the reaching scenario and a primitive taught in it, and what teach
    printed."""
    folder = tmp_path_factory.mktemp("teach")
    shutil.copy(REACH, folder / "scene.yaml")
    code = main(["teach", str(folder / "scene.yaml"), "--output", str(folder / "P.json")])
    assert code == 0
    return folder


@pytest.mark.slow
def test_a_taught_primitive_runs_from_a_scenario_beside_it(taught, capsys):
    document = json.loads((taught / "P.json").read_text())
    assert document["format"] == "pbp_drake.primitive" and document["dimension"] == 3
    assert document["fit_error"] < 0.01
    # Relative to the scenario file's folder, not the working folder.
    code, out = run("run", taught / "scene.yaml", "--headless", "--operator", "virtual",
                    "--set", "dmp.primitive=P.json", capsys=capsys)
    assert code == 0, out.err
    assert "hsr_reach [pbp_alternated, seed 0]: success" in out.out


@pytest.mark.slow
def test_the_obstacle_task_teaches_a_primitive_it_then_runs(tmp_path, capsys):
    # Its one target never switches: the drive keeps the task as it is.
    obstacles = REACH.with_name("hsr_obstacles.yaml")
    code, out = run("teach", obstacles, "--output", tmp_path / "P.json", capsys=capsys)
    assert code == 0, out.err
    code, out = run("run", obstacles, "--headless", "--set",
                    f"dmp.primitive={tmp_path / 'P.json'}", capsys=capsys)
    assert code == 0, out.err
    assert "hsr_obstacles [pbp_alternated, seed 0]: success" in out.out


def test_the_drive_takes_the_command_line_s_seed_and_settings(tmp_path, capsys):
    code, out = run("teach", REACH, "--output", tmp_path / "P.json", "--seed", "3", "--set",
                    "duration=1", "--scenario-text", "{control_period: 0.03}", capsys=capsys)
    assert code == 0, out.err
    assert "hsr_reach [teleop, seed 3]:" in out.out
    with open(tmp_path / "P.csv") as rows:
        times = [float(row["time"]) for row in csv.DictReader(rows)]
    assert times[-1] == pytest.approx(1.0, abs=0.03)
    assert np.diff(times) == pytest.approx(0.03)


@pytest.mark.slow
def test_a_drive_s_recording_teaches_the_same_primitive(taught, tmp_path, capsys):
    code, out = run("teach", REACH, "--from", taught / "P.csv", "--output",
                    tmp_path / "again.json", "--figure", tmp_path / "again.png",
                    capsys=capsys)
    assert code == 0, out.err
    assert "reproduces it within" in out.out
    assert (tmp_path / "again.png").read_bytes().startswith(b"\x89PNG")
    first, again = (json.loads(path.read_text())
                    for path in (taught / "P.json", tmp_path / "again.json"))
    assert first["weights"] == again["weights"]


@pytest.mark.slow
def test_a_run_s_replay_teaches_the_path_it_shows(tmp_path, capsys):
    replay = tmp_path / "run.html"
    code, out = run("run", REACH, "--method", "teleop", "--headless", "--record", replay,
                    "--set", "task.switch_schedule=[0.0]", capsys=capsys)
    assert code == 0, out.err
    code, out = run("teach", REACH, "--from", replay, "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 0, out.err
    document = json.loads((tmp_path / "P.json").read_text())
    assert document["fit_error"] < 0.01
    positions = document["demonstration"]["positions"]
    assert positions[0] == pytest.approx([0.531, 0.078, 0.7], abs=0.002)
    assert positions[-1][0] - positions[0][0] > 1.0  # the hand went to the far objects


def test_a_replay_without_a_hand_path_is_refused(tmp_path, capsys):
    replay = tmp_path / "empty.html"
    replay.write_text(f"<!DOCTYPE html>\n{REPLAY_MARKER}\n<html></html>\n")
    code, out = run("teach", REACH, "--from", replay, "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 2 and f"{replay}: no hand path in this replay" in out.err


def _primitive_file(taught, tmp_path, change):
    document = json.loads((taught / "P.json").read_text())
    text = change(document)
    path = tmp_path / "bad.json"
    path.write_text(text if isinstance(text, str) else json.dumps(document))
    return path


@pytest.mark.slow
@pytest.mark.parametrize("change, message", [
    (lambda d: json.dumps(d)[:200], "is not a primitive file (truncated or corrupt"),
    (lambda d: "\x00\x01 garbage", "is not a primitive file (truncated or corrupt"),
    (lambda d: d.update(version=FORMAT_VERSION + 1), "is newer than this pbp_drake reads"),
    (lambda d: d["settings"].update(formulation="pastor"),
     "scenario.dmp.formulation is 'ijspeert'; the primitive"),
    (lambda d: d.update(dimension=2, amplitude_scaling=[True, True],
                        weights=[row[:2] for row in d["weights"]],
                        demonstration={"times": d["demonstration"]["times"],
                                       "positions": [p[:2] for p in
                                                     d["demonstration"]["positions"]]}),
     "teaches 2-D paths; the task's DMPs move the hand in 3-D"),
])
def test_a_bad_primitive_is_refused_in_one_line_naming_the_file(taught, tmp_path, change,
                                                                 message, capsys):
    path = _primitive_file(taught, tmp_path, change)
    code, out = run("run", REACH, "--headless", "--set", f"dmp.primitive={path}",
                    capsys=capsys)
    assert code == 2
    assert message in out.err and str(path) in out.err
    assert len(out.err.strip().splitlines()) == 1, out.err


def test_a_missing_primitive_is_refused(tmp_path, capsys):
    code, out = run("run", REACH, "--headless", "--set",
                    f"dmp.primitive={tmp_path / 'none.json'}", capsys=capsys)
    assert code == 2 and "none.json cannot be read" in out.err


@pytest.mark.slow
def test_the_grasping_task_teaches_a_pose_and_refuses_a_position_primitive(taught, tmp_path,
                                                                           capsys):
    grasp = REACH.with_name("hsr_grasp.yaml")
    code, out = run("teach", grasp, "--output", tmp_path / "pose.json", capsys=capsys)
    assert code == 0, out.err
    assert "its turn within" in out.out
    document = json.loads((tmp_path / "pose.json").read_text())
    assert len(document["orientation"]["quaternions"][0]) == 4
    code, out = run("run", grasp, "--headless", "--set",
                    f"dmp.primitive={tmp_path / 'pose.json'}", capsys=capsys)
    assert code == 0, out.err
    assert "hsr_grasp [pbp_alternated, seed 0]: success" in out.out
    # The reaching task's primitive has no turn to give the hand's orientation.
    code, out = run("run", grasp, "--headless", "--set",
                    f"dmp.primitive={taught / 'P.json'}", capsys=capsys)
    assert code == 2 and "teaches positions alone" in out.err
    # Nor does the reaching task's recording teach a grasp.
    code, out = run("teach", grasp, "--from", taught / "P.csv", "--output",
                    tmp_path / "again.json", capsys=capsys)
    assert code == 2 and "the grasping task teaches a pose" in out.err


@pytest.mark.parametrize("rows, message", [
    ("time,ee_x,ee_y,ee_z\n" + "".join(f"{t / 10},0.5,0.0,0.7\n" for t in range(30)),
     "ends 0.000 m from where it starts"),
    ("time,ee_x,ee_y,ee_z\n" + "".join(f"{t / 10},{0.5 + t / 20},nan,0.7\n"
                                        for t in range(30)), "NaN or infinite at sample 0"),
    ("time,x\n0,1\n", "not a run's path: it needs the columns time, ee_x, ee_y, ee_z"),
    ("time,ee_x,ee_y,ee_z\n0,0.5,x,0.7\n", "a value of time, ee_x, ee_y, ee_z is not a number"),
    ("time,ee_x,ee_y,ee_z\n0,0.5,0.0\n", "a value of time, ee_x, ee_y, ee_z is not a number"),
])
def test_a_bad_recording_is_refused_in_one_line_naming_it(tmp_path, rows, message, capsys):
    recording = tmp_path / "run.csv"
    recording.write_text(rows)
    code, out = run("teach", REACH, "--from", recording, "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 2
    assert message in out.err and str(recording) in out.err
    assert not (tmp_path / "P.json").exists()


def test_a_trial_s_json_points_to_its_csv(tmp_path, capsys):
    trial = tmp_path / "seed_3.json"
    trial.write_text('{"success": true}\n')
    code, out = run("teach", REACH, "--from", trial, "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 2 and "not a run's path" in out.err and "its CSV" not in out.err
    trial.with_suffix(".csv").write_text("time,ee_x,ee_y,ee_z\n")
    code, out = run("teach", REACH, "--from", trial, "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 2
    assert f"; a trial's path is in its CSV, {trial.with_suffix('.csv')}" in out.err

def test_a_recording_that_cannot_be_read_is_refused(tmp_path, capsys):
    code, out = run("teach", REACH, "--from", tmp_path, "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 2 and f"{tmp_path}: cannot be read as a CSV" in out.err
    assert list(tmp_path.iterdir()) == []


def test_a_recording_too_large_is_refused_without_reading_it(tmp_path, capsys, monkeypatch):
    # A 2 GB file was read whole (a MemoryError): the limit, made small here.
    monkeypatch.setattr(teach, "MOST_HAND_PATH_BYTES", 1000)
    recording = tmp_path / "run.csv"
    recording.write_text("time,ee_x,ee_y,ee_z\n" + "0.0,0.5,0.0,0.7\n" * 100)
    code, out = run("teach", REACH, "--from", recording, "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 2 and out.err == (f"pbp-drake: {recording}: holds 1,620 bytes; a run's CSV "
                                     "or replay to teach from is at most 1,000\n")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes")
@pytest.mark.timeout(60)
def test_a_recording_that_is_a_pipe_is_refused_without_reading_it(tmp_path, capsys):
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    code, out = run("teach", REACH, "--from", pipe, "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 2 and f"{pipe}: not a regular file; give a run's CSV" in out.err
    assert sorted(tmp_path.iterdir()) == [pipe]


@pytest.mark.parametrize("flags, message", [
    (["--from", "run.csv", "--operator", "keyboard"],
     "--from teaches from a recording; --operator keyboard drives the task instead: give one "
     "of them"),
    (["--from", "run.csv", "--port", "8123"], "--port is the page's port of a keyboard or "
     "gamepad drive (--operator keyboard or gamepad, without --from)"),
    (["--port", "8123"], "--port is the page's port of a keyboard or gamepad drive"),
])
def test_flags_that_would_do_nothing_are_refused(tmp_path, capsys, flags, message):
    code, out = run("teach", REACH, "--output", tmp_path / "P.json", *flags, capsys=capsys)
    assert code == 2 and out.err.startswith(f"pbp-drake: {message}")
    assert list(tmp_path.iterdir()) == []


def test_a_2d_scene_is_refused(repo, tmp_path, capsys):
    code, out = run("teach", repo / "diagrams" / "toy_alt_vs_cont.yaml", "--output",
                    tmp_path / "P.json", capsys=capsys)
    assert code == 2 and "teach drives a robot task's hand; this scenario is a 2-D" in out.err
    assert list(tmp_path.iterdir()) == []


def test_the_grasping_task_is_driven_in_the_page_without_a_hand_trail(tmp_path, capsys,
                                                                      monkeypatch):
    # The grasping task's page draws no trail: `run --hand-trail` refuses it there.
    def the_page(*_):
        raise teach.ScenarioError("the page would open here")
    monkeypatch.setattr("pbp_drake.commands.run.open_page", the_page)
    code, out = run("teach", REPO / "diagrams" / "hsr_grasp.yaml", "--operator", "keyboard",
                    "--output", tmp_path / "P.json", capsys=capsys)
    assert (code, out.err) == (2, "pbp-drake: the page would open here\n")


def test_a_figure_that_is_not_an_image_file_is_refused_before_anything_runs(tmp_path,
                                                                             capsys):
    code, out = run("teach", REACH, "--output", tmp_path / "P.json", "--figure",
                    tmp_path / "P.txt", capsys=capsys)
    assert code == 2 and "a figure is a .png, .svg or .pdf file" in out.err
    assert list(tmp_path.iterdir()) == []


def test_teach_does_not_overwrite_a_file_that_is_not_a_primitive(tmp_path, capsys):
    notes = tmp_path / "notes.json"
    notes.write_text("{}")
    code, out = run("teach", REACH, "--output", notes, capsys=capsys)
    assert code == 2 and "is not a primitive written by pbp-drake" in out.err
    assert notes.read_text() == "{}"


@pytest.mark.parametrize("argv, message", [
    # The drive's rows went to P.csv, then the primitive over them.
    (["--output", "{tmp}/P.csv"], "--output {tmp}/P.csv: the drive's rows are saved beside "
     "the primitive as a .csv; give the primitive a .json file"),
    (["--output", "{tmp}/P.png", "--figure", "{tmp}/P.png"],
     "--figure and --output both name {tmp}/P.png; give each its own file"),
    (["--output", ""], "--output: the path is empty; give a file, e.g. primitive.json"),
])
def test_outputs_that_would_overwrite_each_other_are_refused(tmp_path, capsys, monkeypatch,
                                                             argv, message):
    monkeypatch.chdir(tmp_path)
    code, out = run("teach", REACH, *[arg.replace("{tmp}", str(tmp_path)) for arg in argv],
                    capsys=capsys)
    assert code == 2 and out.err == f"pbp-drake: {message.replace('{tmp}', str(tmp_path))}\n"
    assert list(tmp_path.iterdir()) == []


def test_teach_names_the_primitive_as_the_scenario_reads_it(tmp_path, capsys, monkeypatch):
    # A relative dmp.primitive is read from the scenario's folder: the working folder's
    # path it printed named another file there, or none.
    recording = tmp_path / "run.csv"
    recording.write_text("time,ee_x,ee_y,ee_z\n" + "".join(
        f"{t / 10},{0.5 + t / 20},0.0,0.7\n" for t in range(30)))
    (tmp_path / "scene").mkdir()
    shutil.copy(REACH, tmp_path / "scene" / "reach.yaml")
    monkeypatch.chdir(tmp_path)
    code, out = run("teach", "scene/reach.yaml", "--from", recording, "--output",
                    "primitives/mine.json", capsys=capsys)
    assert code == 0, out.err
    assert out.out.rstrip().endswith("Saved to primitives/mine.json: name it in "
                                     "scene/reach.yaml as dmp: {primitive: "
                                     "../primitives/mine.json}")


def test_a_primitive_that_cannot_be_written_says_how_to_teach_from_what_is_kept(
        tmp_path, capsys, monkeypatch):
    # A full disk was an OSError traceback, the drive kept beside it unsaid.
    def full_disk(path, text):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))
    monkeypatch.setattr(teach, "write_atomically", full_disk)
    recording = tmp_path / "P.csv"
    recording.write_text("time,ee_x,ee_y,ee_z\n" + "".join(
        f"{t / 10},{0.5 + t / 20},0.0,0.7\n" for t in range(30)))
    code, out = run("teach", REACH, "--from", recording, "--output", tmp_path / "P.json",
                    "--set", "dmp.basis_count=20", capsys=capsys)
    assert code == 4
    assert out.err == (f"pbp-drake: cannot write {tmp_path / 'P.json'}: no space left on "
                       "device; nothing is left half-written: free some space, then "
                       f"pbp-drake teach {REACH} --from {recording} --output "
                       f"{tmp_path / 'P.json'} --set dmp.basis_count=20 teaches from "
                       f"{recording}.\n")


def test_a_drive_ended_by_ctrl_c_says_where_it_is_kept(tmp_path, capsys, monkeypatch):
    # It said "interrupted" alone; the next drive wrote over the rows kept.
    def driven_then_interrupted(args, log, **_):
        pathlib.Path(log).write_text("time,ee_x,ee_y,ee_z\n0.0,0.5,0.0,0.7\n")
        raise KeyboardInterrupt
    monkeypatch.setattr(teach, "_drive", driven_then_interrupted)
    code, out = run("teach", REACH, "--operator", "keyboard", "--output", tmp_path / "P.json",
                    capsys=capsys)
    assert code == 130
    assert out.err == (f"\npbp-drake: interrupted; the drive so far is kept in "
                       f"{tmp_path / 'P.csv'}: pbp-drake teach {REACH} --from "
                       f"{tmp_path / 'P.csv'} --output {tmp_path / 'P.json'} teaches from it\n")
