"""What `pbp-drake run` tells a person about their task: each robot's own controls, why a
run failed, and a gamepad run whose page has no pad."""

import dataclasses

import msgpack
import numpy as np
import pytest

from pbp_drake.builder import TaskResult, build_diagram, simulate
from pbp_drake.commands.task_runs import controls_line, why_failed
from pbp_drake.console import Console, LiveRun, result_text
from pbp_drake.console.live import GAMEPAD_FOUND, NO_GAMEPAD
from pbp_drake.console.text import failure_text
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.scenarios.overrides import ScenarioOverrides
from pbp_drake.studies.trial_files import time_series_csv


# A gamepad as the page reports it, sticks at rest.
PAD = {"index": 0, "button_values": [0.0] * 17, "axes": [0.0] * 4}


def scenario(repo, name, *settings):
    return load_scenario_file(repo / "diagrams" / name, ScenarioOverrides(settings)).scenario


@pytest.mark.parametrize("name, operator, method, expected, absent", [
    # The arm's objects stand at heights of their own: its page has Up (R) and Down (F).
    ("arm_reach.yaml", "!Keyboard {}", "pbp_alternated",
     "Keys: arrows move the hand (not forward: the primitive drives it), Q and E turn it, "
     "R raises it and F lowers it.", "PageUp"),
    ("hsr_reach.yaml", "!Keyboard {}", "teleop",
     "Keys: arrows move the hand, Q and E turn it.", "raises"),
    ("hsr_reach.yaml", "!Gamepad {}", "pbp_alternated",
     "Gamepad: left stick moves the hand (not forward: the primitive drives it), right "
     "stick turns it.", "Keys"),
    ("hsr_grasp.yaml", "!Keyboard {}", "teleop",
     "Keys: arrows move the hand, PageUp/PageDown raise and lower it; R switches to turning",
     "Q and E"),
])
def test_each_task_prints_its_own_controls(repo, name, operator, method, expected, absent):
    line = controls_line(scenario(repo, name, f"operator={operator}", f"method={method}"))
    assert expected in line and absent not in line, line


def result(success, ee_position, target, objects):
    ticks = np.zeros(3)
    return TaskResult(
        success=success, task_time=40.0, intervention_ratio=0.5, switches=1, times=ticks,
        ee_positions=np.array([[0.0, 0.0, 0.7]] * 2 + [ee_position]), headings=ticks,
        commands=np.zeros((3, 7)), operator_active=np.zeros(3, bool),
        operator_commands=np.zeros((3, 4)), selected_goals=np.zeros(3, int),
        targets=np.array([0, target, target]), objects=np.array(objects))


def test_a_failed_run_says_which_target_and_how_far(repo):
    reach = scenario(repo, "hsr_reach.yaml")
    # The hand 0.3 m short of object 2 (index 1) of 3, in x: 0.3 m from it.
    failed = result(False, [1.2, 0.5, 0.7], 1, [[2.0, 0.0, 0.7], [1.5, 0.5, 0.7],
                                                [2.2, -0.5, 0.7]])
    why = why_failed(failed, reach)
    assert why == ("the target was object 2 of 3, the hand 0.300 m from it (success within "
                   "0.050 m)")
    assert result_text(False, 40.0, why=why) == f"failed: time limit; {why}"
    assert failure_text(0, 4, 1.25) == "the target was object 1 of 4, the hand 1.250 m from it"
    # With many grasps an object the targets are grasps: 2 objects of 3 grasps are 6.
    grasps = scenario(repo, "hsr_grasp.yaml", "task.grasps_per_object=3")
    failed_grasp = result(False, [1.2, 0.5, 0.7], 4, [[1.5, 0.5, 0.7]] * 6)
    assert why_failed(failed_grasp, grasps) == ("the target was grasp 5 of 6, the hand "
                                                "0.300 m from it")
    # A robot whose joints stand at a limit says which: the hand may be held there.
    held = dataclasses.replace(failed, joints_at_limits=["wrist_flex_joint", "arm_lift_joint"])
    assert why_failed(held, reach) == f"{why}; at a joint limit: wrist_flex_joint, arm_lift_joint"



def test_a_failed_run_streamed_to_its_log_says_why_from_the_log(repo, tmp_path):
    reach = scenario(repo, "hsr_reach.yaml")
    objects = [[2.0, 0.0, 0.7], [1.5, 0.5, 0.7], [2.2, -0.5, 0.7]]
    whole = result(False, [1.2, 0.5, 0.7], 1, objects)
    # A streamed run's result holds no series (`run_task_streamed`): its rows are in the log.
    streamed = dataclasses.replace(whole, times=np.zeros(0), ee_positions=np.zeros((0, 3)),
                                   targets=np.zeros(0, int))
    log = tmp_path / "run.csv"
    log.write_text(time_series_csv(whole))
    assert why_failed(streamed, reach, str(log)) == why_failed(whole, reach)
    assert why_failed(streamed, reach) is None
    # A log that is not a file (--force allows a device) is not read: /dev/zero never ends.
    assert why_failed(streamed, reach, "/dev/zero") is None
    header_only = tmp_path / "header.csv"
    header_only.write_text(time_series_csv(whole).splitlines(keepends=True)[0])
    assert why_failed(streamed, reach, str(header_only)) is None

@pytest.mark.slow
def test_a_gamepad_run_without_a_pad_says_so_until_one_comes(repo, meshcat, capsys):
    toy = load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").resolved
    console = Console(meshcat, choices=("stop",))
    diagram = build_diagram(toy, meshcat)
    live = LiveRun(diagram, 0.2, console, gamepad=True)
    simulate(toy, diagram=diagram, advance=live.advance, realtime_rate=0.0)
    assert NO_GAMEPAD in console.lines()
    assert capsys.readouterr().err.count(NO_GAMEPAD) == 1  # said once, not every slice
    meshcat._InjectWebsocketMessage(msgpack.packb({"type": "gamepad", "name": "",
                                                   "gamepad": PAD}))
    diagram = build_diagram(toy, meshcat)
    live = LiveRun(diagram, 0.2, console, gamepad=True)
    simulate(toy, diagram=diagram, advance=live.advance, realtime_rate=0.0)
    assert NO_GAMEPAD not in console.lines()
    assert capsys.readouterr().err == ""  # a pad there at the start is no news


@pytest.mark.slow
def test_a_pad_that_comes_during_the_run_is_greeted(repo, meshcat, capsys):
    toy = load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").resolved
    console = Console(meshcat, choices=("stop",))
    diagram = build_diagram(toy, meshcat)
    live = LiveRun(diagram, 0.2, console, gamepad=True)

    def advance(simulator, end_time):
        ended = live.advance(simulator, 0.1)  # no pad yet
        meshcat._InjectWebsocketMessage(msgpack.packb({"type": "gamepad", "name": "",
                                                       "gamepad": PAD}))
        return ended or live.advance(simulator, end_time)

    simulate(toy, diagram=diagram, advance=advance, realtime_rate=0.0)
    assert capsys.readouterr().err == f"{NO_GAMEPAD}\n{GAMEPAD_FOUND}\n"
    assert NO_GAMEPAD not in console.lines()
