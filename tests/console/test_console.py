"""The operator's console: what the page and the terminal say about a run, and
the controls a person uses, against a real Meshcat (clicks and slider moves injected as the
page sends them)."""

import io
import os

import msgpack
import numpy as np
import pytest

from pbp_drake.builder import build_diagram, find_system, run_task, simulate
from pbp_drake.console import (
    ALPHA_SLIDER, CHOICE_BUTTONS, RATE_SLIDER, Console, LiveRun, Progress, behind_head_view,
    method_name, progress_text, result_text, status_text, time_left)
from pbp_drake.console.questionnaire import start_label
from pbp_drake.scenarios import METHOD_NAMES, METHODS, load_scenario_file, resolve, with_method


def click(meshcat, name):
    meshcat._InjectWebsocketMessage(msgpack.packb({"type": "button", "name": name}))


def slide(meshcat, name, value):
    meshcat._InjectWebsocketMessage(msgpack.packb({"type": "slider", "name": name,
                                                   "value": value}))


def test_status_words():
    assert status_text(60.0, 18.3, 2, 0.31) == ("time left 42 s · 2 target switches · "
                                                "intervention 31 %")
    assert status_text(60.0, 59.2, 1, 0.0).startswith("time left 1 s · 1 target switch ·")
    assert status_text(3.0, 3.02) == "time left 0 s"  # a 2-D scene: no targets
    assert time_left(41.0, 0.0) == "time left 41 s"
    assert result_text(True, 14.23) == "success in 14.2 s"
    assert result_text(False, 60.0) == "failed: time limit"
    assert result_text(False, 9.0, stopped=True) == "stopped at 9.0 s"
    assert method_name("pbp_alternated") == "PBP-Alt"
    assert method_name("pbp_continuous") == "PBP-Cont"
    assert method_name("teleop") == "Teleop"
    assert method_name("fixed_alpha", 0.5) == "Fixed alpha 0.50"
    assert progress_text(12.34, 60.0, 1.0) == "t = 12.3 s of 60 s, 1.00x real time"


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_terminal_s_progress_line_is_rewritten_in_place_then_cleared():
    terminal = Terminal()
    progress = Progress(60.0, terminal)
    progress.show(12.34, 1.0, force=True)
    progress.show(2.0, 1.0, force=True)  # shorter: padded over the longer line
    progress.finish()
    first, second = progress_text(12.34, 60.0, 1.0), progress_text(2.0, 60.0, 1.0)
    assert len(second) < len(first)
    assert terminal.getvalue() == ("\r" + first + "\r" + second.ljust(len(first))
                                   + "\r" + " " * len(second) + "\r")


# The names the results tables in docs/results/generated/ print.
NAMES = {"pbp_alternated": "PBP-Alt", "pbp_continuous": "PBP-Cont", "teleop": "Teleop",
         "pbp_no_user": "PBP-NoUser", "fixed_alpha": "Fixed alpha",
         "confidence_alpha": "confidence_alpha", "hop": "HOP",
         "predict_then_assist": "Predict-then-assist"}


@pytest.mark.parametrize("method", METHODS)
def test_a_method_has_one_name_in_the_title_the_start_button_and_the_results(method):
    assert method_name(method) == METHOD_NAMES[method] == NAMES[method]
    assert start_label(method, 1, 3) == f"Start method 1 of 3: {NAMES[method]}"
    assert start_label(method, 2, 3, practice=True) == (
        f"Start practice 2 of 3: {NAMES[method]} (not recorded)")


def test_the_page_shows_the_buttons_and_the_lines_in_order(meshcat):
    console = Console(meshcat, alpha=0.4, realtime_rate=1.0)
    console.show_title("PBP-Alt, seed 0")
    console.show_status("time left 41 s")
    console.show_result("success in 14.2 s")
    console.show_status("time left 40 s")
    # The old status is gone, and the changed one is still above the result (Meshcat lists
    # its buttons by name; the page, in the order they were added: lines() is that order).
    lines = ["PBP-Alt, seed 0", "time left 40 s", "Result: success in 14.2 s"]
    assert console.lines() == lines
    assert sorted(meshcat.GetButtonNames()) == sorted(["Stop", "Restart", "Next scene",
                                                       *lines])
    assert meshcat.GetSliderValue(ALPHA_SLIDER) == pytest.approx(0.4)
    assert meshcat.GetSliderValue(RATE_SLIDER) == pytest.approx(1.0)
    console.close()
    assert meshcat.GetButtonNames() == [] and meshcat.GetSliderNames() == []


def test_each_click_is_one_choice(meshcat):
    click(meshcat, "Stop")  # before the console: not a choice of its
    console = Console(meshcat, choices=("stop", "next"))
    assert console.choice() is None
    click(meshcat, CHOICE_BUTTONS["next"])
    assert console.choice() == "next"
    assert console.choice() is None
    click(meshcat, "Stop")
    assert console.wait_for_choice(poll_period=0.01) == "stop"
    assert "Restart" not in meshcat.GetButtonNames()


def test_a_choice_without_a_button_is_refused(meshcat):
    with pytest.raises(ValueError, match=r"unknown choices \['pause'\]; choose from"):
        Console(meshcat, choices=("stop", "pause"))


def test_enter_in_the_terminal_is_stop(meshcat, tmp_path):
    console = Console(meshcat)
    with open(tmp_path / "typed", "w+") as stdin:
        stdin.write("\n")
        stdin.seek(0)
        assert console.wait_for_choice(poll_period=0.01, stdin=stdin) == "stop"
    # A terminal where nothing is typed: the wait ends at its timeout, with no choice.
    read, write = os.pipe()
    with open(read) as stdin, open(write, "w"):
        assert console.wait_for_choice(poll_period=0.01, stdin=stdin, timeout=0.05) is None


def test_the_sliders_read_what_the_person_set(meshcat):
    console = Console(meshcat, alpha=0.5, realtime_rate=1.0)
    slide(meshcat, ALPHA_SLIDER, 0.8)
    slide(meshcat, RATE_SLIDER, 0.5)
    assert console.alpha() == pytest.approx(0.8)
    assert console.realtime_rate() == pytest.approx(0.5)
    assert Console(meshcat, choices=()).alpha() is None
    console.close()
    # A rate asked for on the command line is not clipped by the slider's range.
    assert Console(meshcat, realtime_rate=5.0).realtime_rate() == pytest.approx(5.0)


def test_stop_ends_a_run_where_it_stands(repo, meshcat):
    resolved = resolve(load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").scenario)
    diagram = build_diagram(resolved)
    console = Console(meshcat)
    stream = io.StringIO()
    live = LiveRun(diagram, resolved.scenario.duration, console, Progress(3.0, stream))
    click(meshcat, "Stop")
    trajectory = simulate(resolved, realtime_rate=0.0, diagram=diagram, advance=live.advance)
    assert live.choice == "stop"
    assert trajectory.times[-1] < 0.1  # one slice of 0.05 s, not the 3 s of the scene
    assert console.lines() == ["time left 3 s"]
    # Not a terminal: one progress line, where the run ended.
    assert stream.getvalue().startswith("t = 0.") and stream.getvalue().count("\n") == 1


@pytest.mark.slow
def test_the_alpha_slider_changes_the_blend_during_the_run(repo, meshcat):
    scenario = with_method(load_scenario_file(repo / "diagrams" / "toy_alpha_study.yaml")
                           .scenario, "fixed_alpha=0.2")
    resolved = resolve(scenario)
    commands = {}
    for alpha in (0.2, 0.9):
        diagram = build_diagram(resolved)
        console = Console(meshcat, choices=(), alpha=0.2)
        slide(meshcat, ALPHA_SLIDER, alpha)
        live = LiveRun(diagram, scenario.duration, console)
        commands[alpha] = simulate(resolved, realtime_rate=0.0, diagram=diagram,
                                   advance=live.advance).command
        console.close()
    # The run with alpha 0.2 from the slider is the run the scenario describes.
    assert np.array_equal(commands[0.2], simulate(resolved, realtime_rate=0.0).command)
    assert not np.allclose(commands[0.2], commands[0.9])


@pytest.mark.slow
def test_the_hsr_status_counts_what_the_task_monitor_counts(repo, meshcat):
    resolved = resolve(load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario)
    diagram = build_diagram(resolved)
    console = Console(meshcat)
    live = LiveRun(diagram, 2.0, console)
    result = run_task(resolved, realtime_rate=0.0, diagram=diagram,
                      advance=lambda simulator, end: live.advance(simulator, 2.0))
    assert console.lines() == [status_text(2.0, 2.0, result.switches,
                                           result.intervention_ratio)]
    assert find_system(diagram, "blender") is not None


def test_the_robot_camera_looks_over_the_head_where_the_base_faces():
    camera, target = behind_head_view([1.0, 2.0, 1.2], np.pi / 2)  # facing world +y
    assert camera[1] < 2.0 and camera[2] > 1.2 and camera[0] == pytest.approx(1.0)
    assert target[1] > 2.0 and target[2] < 1.2
