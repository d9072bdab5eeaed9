"""The console's Start gate and its panel, against a real Meshcat: a run whose task waits
for Start has simulated nothing until the press (however long the person takes), Stop,
Restart or Next scene at the gate end it at once with that choice, a key pressed at the
gate drives nothing once the run goes, the lines go to a panel (the page front's) with the
simulated time of the status, the choice buttons can be swapped for the ones after a run,
and the page kept after it has no keys and outlives a reload."""

import dataclasses
import threading
import time
import types

import msgpack
import pytest
from foreign_page import ForeignPage
from test_page_gone import keyboard_run

from pbp_drake.builder import build_diagram, simulate
from pbp_drake.commands import run_page, task_runs
from pbp_drake.commands.run_page import keep_page
from pbp_drake.commands.task_runs import run_task_loop
from pbp_drake.console import Console, LiveRun
from pbp_drake.scenarios import Keyboard, load_scenario_file, resolve
from pbp_drake.systems.operators.keyboard_operator import KEY_BUTTONS, LEFT_BUTTON


def click(meshcat, name):
    meshcat._InjectWebsocketMessage(msgpack.packb({"type": "button", "name": name}))


class Panel:
    """What a page front keeps: the latest of each line."""

    def __init__(self):
        self.state = {}

    def show(self, **lines):
        self.state.update(lines)


@pytest.fixture
def scene(repo):
    return resolve(load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").scenario)


def press_later(port, origin, name, delay, stop):
    """A page that presses `name` every 20 ms from `delay` seconds on, until `stop` is set
    (the button only counts once the console has added it)."""
    page = ForeignPage(port, origin=origin)
    time.sleep(delay)
    while not stop.is_set():
        page.press(name)
        time.sleep(0.02)
    page.close()


@pytest.mark.slow
def test_the_clock_starts_at_the_start_press(scene, meshcat):
    diagram = build_diagram(scene)
    panel = Panel()
    console = Console(meshcat, choices=("stop",), panel=panel)
    live = LiveRun(diagram, scene.scenario.duration, console, start_label="Start")
    stop = threading.Event()
    presser = threading.Thread(target=press_later, daemon=True, args=(
        meshcat.port(), meshcat.web_url(), "Start", 1.0, stop))
    started = time.monotonic()
    presser.start()
    try:
        trajectory = simulate(scene, realtime_rate=0.0, diagram=diagram, advance=live.advance)
    finally:
        stop.set()
        presser.join(timeout=5)
    waited = time.monotonic() - started
    assert waited >= 1.0
    # The whole scene ran after the press: nothing was simulated while the page waited.
    assert live.choice is None
    assert trajectory.times[-1] == pytest.approx(scene.scenario.duration, abs=0.05)
    assert "Start" not in meshcat.GetButtonNames()  # gone once pressed
    assert panel.state["status"] == "time left 0 s"
    assert panel.state["time"] == pytest.approx(trajectory.times[-1], abs=0.05)


def test_stop_at_the_start_gate_ends_the_run_at_once(scene, meshcat):
    diagram = build_diagram(scene)
    console = Console(meshcat, choices=("stop",), panel=Panel())
    live = LiveRun(diagram, scene.scenario.duration, console, start_label="Start")
    click(meshcat, "Stop")  # pressed while the page waits for Start
    trajectory = simulate(scene, realtime_rate=0.0, diagram=diagram, advance=live.advance)
    assert live.choice == "stop"
    assert trajectory.times[-1] < 0.1  # one slice of 0.05 s, not the 3 s of the scene


@pytest.mark.timeout(60)  # the gate ignored these: it waited for Start for ever
@pytest.mark.parametrize("label, choice", [("Next scene", "next"), ("Restart", "restart")])
def test_a_choice_at_the_start_gate_ends_the_run_with_it(scene, meshcat, label, choice):
    diagram = build_diagram(scene)
    console = Console(meshcat, panel=Panel())  # Stop, Restart and Next scene
    live = LiveRun(diagram, scene.scenario.duration, console, start_label="Start")
    click(meshcat, label)  # pressed while the page waits for Start
    trajectory = simulate(scene, realtime_rate=0.0, diagram=diagram, advance=live.advance)
    assert live.choice == choice
    assert trajectory.times[-1] < 0.1
    assert "Start" not in meshcat.GetButtonNames()


class KeyBeforeStart(Console):
    """A page where ← is pressed while it waits for Start, then Start."""

    def wait_for_start(self, label, poll_period=0.05, stdin=None):
        click(self.meshcat, LEFT_BUTTON)
        return "start"


def test_a_key_pressed_before_start_does_not_move_the_robot_after_it(meshcat):
    diagram, simulator, active = keyboard_run(meshcat)
    live = LiveRun(diagram, 2.0, KeyBeforeStart(meshcat, panel=Panel()), start_label="Start")
    live.advance(simulator, 1.0)
    log = active.FindLog(simulator.get_context())
    assert len(log.sample_times()) > 10 and not log.data().any()  # it was held 0.6 s
    click(meshcat, LEFT_BUTTON)  # pressed once the run goes: read
    live.advance(simulator, 1.5)
    assert log.data().any()


def test_the_lines_go_to_the_panel_not_to_buttons(meshcat):
    panel = Panel()
    console = Console(meshcat, panel=panel)
    console.show_title("PBP-Alt, seed 0")
    console.show_status("time left 41 s", time=19.0)
    console.show_result("success in 14.2 s")
    assert panel.state == {"title": "PBP-Alt, seed 0", "status": "time left 41 s",
                           "time": 19.0, "result": "Result: success in 14.2 s"}
    assert sorted(meshcat.GetButtonNames()) == ["Next scene", "Restart", "Stop"]
    console.clear_result()
    assert panel.state["result"] is None


class ReloadedPage:
    """A page front whose one page is reloaded after the run: gone for a few looks, then
    back, where Close is clicked; with `back=False` it stays gone (closed)."""

    def __init__(self, meshcat, back=True):
        self._meshcat, self._looks = meshcat, [1, 0, 0] if back else [1]
        self._back = back

    def pages(self):
        if self._looks:
            return self._looks.pop(0)
        if self._back:
            click(self._meshcat, "Close")
            self._back = False
            return 1
        return 0


def test_a_page_reloaded_after_the_run_keeps_it_and_a_closed_one_ends_it(meshcat,
                                                                           monkeypatch):
    args = types.SimpleNamespace(keep_page=60.0)
    console = Console(meshcat, panel=Panel())
    assert keep_page(args, ReloadedPage(meshcat), console, ("close",)) == "close"
    monkeypatch.setattr(run_page, "RELOAD_SECONDS", 0.05)
    assert keep_page(args, ReloadedPage(meshcat, back=False), console, ("close",)) is None


def test_the_choices_after_a_run_replace_the_run_s(meshcat):
    console = Console(meshcat)
    click(meshcat, "Restart")
    console.set_choices(("restart", "next", "close"))
    assert sorted(meshcat.GetButtonNames()) == ["Close", "Next scene", "Restart"]
    assert console.choice() is None  # the click before does not count
    click(meshcat, "Close")
    assert console.wait_for_choice(poll_period=0.01) == "close"
    # Bounded: a page that is closed (or a timeout) ends the wait with no choice.
    assert console.wait_for_choice(poll_period=0.01, until=lambda: True) is None
    started = time.monotonic()
    assert console.wait_for_choice(poll_period=0.01, timeout=0.2) is None
    assert 0.2 <= time.monotonic() - started < 2.0


class KeptPage(Panel):
    """A page front with one browser on it, for the whole command."""

    url = "http://localhost/?token=test"

    def pages(self):
        return 1

    pages_present = pages  # in view and heard

    def end(self, text=None):
        self.state["ended"] = text


def test_the_page_kept_after_a_run_has_no_keys(repo, meshcat, monkeypatch):
    scenario = dataclasses.replace(
        load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario,
        method="teleop", operator=Keyboard(), duration=0.2)
    args = types.SimpleNamespace(
        hand_trail=False, start_on_connect=True, wait_for_browser=1.0, camera="overview",
        record=None, headless=False, realtime_rate=50.0, log=None, keep_page=60.0)
    kept = []

    def keep_page(args, page, console, choices):
        kept.append(set(meshcat.GetButtonNames()))
        return "close"

    monkeypatch.setattr(task_runs, "keep_page", keep_page)
    run_task_loop(args, resolve(scenario), meshcat, KeptPage())
    # No key is offered for a robot whose run is over (the choices are keep_page's).
    assert len(kept) == 1 and not kept[0] & set(KEY_BUTTONS), kept
