"""A person's run without its page: while no page is present (closed, hidden or silent: see
test_front.py) the run stands still (its clock stopped), says so once, and goes on when a
page is back, what the gone page held forgotten; Ctrl-C meanwhile stops it; a short
absence (a reload) is not announced; and a run nobody drives (a virtual participant's, a
scene's) does not wait for a page."""

import msgpack
import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

from pbp_drake.builder import build_diagram, simulate
from pbp_drake.console import Console, LiveRun, live
from pbp_drake.scenarios import load_scenario_file, resolve
from pbp_drake.systems.operators.keyboard_operator import LEFT_BUTTON, KeyboardOperator
from pbp_drake.systems.ports import EeState


class Panel:
    def show(self, **lines):
        pass


class Page:
    """A page front whose count of present pages follows `counts`, one per call of
    `pages_present()` (then 1), the run's simulated time (`clock()`) noted at each call."""

    url = "http://localhost:1/?token=t"

    def __init__(self, counts, clock, interrupt_at=None):
        self._counts = list(counts)
        self._clock = clock
        self._interrupt_at = interrupt_at
        self.seen = []  # (count, simulated time) at each call

    def pages_present(self):
        if len(self.seen) == self._interrupt_at:
            raise KeyboardInterrupt  # Ctrl-C, as it comes during the pause's sleep
        count = self._counts.pop(0) if self._counts else 1
        self.seen.append((count, self._clock()))
        return count


def keyboard_run(meshcat):
    """A person's diagram (the keyboard operator alone), its simulator and its activity log."""
    builder = DiagramBuilder()
    operator = builder.AddNamedSystem("operator", KeyboardOperator(
        meshcat, 0.05, allow_forward=False, nominal_speed=0.2))
    source = builder.AddSystem(ConstantVectorSource(np.zeros(EeState.size)))
    builder.Connect(source.get_output_port(), operator.get_ee_state_input_port())
    active = LogVectorOutput(operator.get_operator_active_output_port(), builder)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.Initialize()
    return diagram, simulator, active


def test_a_person_s_run_stands_still_while_no_page_is_open(meshcat, monkeypatch, capsys):
    monkeypatch.setattr(live, "NO_PAGE_QUIET", 0.0)
    diagram, simulator, active = keyboard_run(meshcat)
    page = Page([1] * 5 + [0] * 4, lambda: simulator.get_context().get_time())
    run = LiveRun(diagram, 1.0, Console(meshcat, choices=("stop",), panel=Panel()), page=page)
    # ← pressed as the run starts: held 0.6 s, past the moment the page goes.
    meshcat._InjectWebsocketMessage(msgpack.packb({"type": "button", "name": LEFT_BUTTON}))
    assert not run.advance(simulator, 1.0)
    assert simulator.get_context().get_time() == pytest.approx(1.0)
    # The page went after five slices (0.25 s): the clock stood there until it came back.
    gone = [time for count, time in page.seen if count == 0]
    assert len(gone) == 4 and gone == pytest.approx([0.25] * 4)
    assert [time for count, time in page.seen[9:]] == pytest.approx(
        [0.25 + 0.05 * k for k in range(15)])
    err = capsys.readouterr().err
    assert err == (f"pbp-drake: {live.NO_PAGE.format(time=0.25, url=Page.url)}\n"
                   f"pbp-drake: {live.PAGE_BACK}\n")
    # The key the closed page held drives nothing once the run goes on.
    log = active.FindLog(simulator.get_context())
    times, data = log.sample_times(), log.data()[0]
    assert data[times < 0.2].any() and not data[times > 0.26].any()


def test_a_reload_holds_the_run_without_a_word(meshcat, monkeypatch, capsys):
    monkeypatch.setattr(live, "NO_PAGE_QUIET", 1e9)
    diagram, simulator, _ = keyboard_run(meshcat)
    page = Page([1, 1, 0, 0], lambda: simulator.get_context().get_time())
    run = LiveRun(diagram, 0.3, Console(meshcat, choices=("stop",), panel=Panel()), page=page)
    assert not run.advance(simulator, 0.3)
    assert [time for count, time in page.seen if count == 0] == pytest.approx([0.1, 0.1])
    assert capsys.readouterr().err == ""


def test_ctrl_c_stops_a_run_that_waits_for_its_page(meshcat, monkeypatch):
    monkeypatch.setattr(live, "NO_PAGE_QUIET", 0.0)
    diagram, simulator, _ = keyboard_run(meshcat)
    page = Page([1, 0, 0], lambda: simulator.get_context().get_time(), interrupt_at=3)
    run = LiveRun(diagram, 1.0, Console(meshcat, choices=("stop",), panel=Panel()), page=page)
    with pytest.raises(KeyboardInterrupt):
        run.advance(simulator, 1.0)
    assert simulator.get_context().get_time() == pytest.approx(0.05)


def test_a_run_nobody_drives_needs_no_page(repo, meshcat, capsys):
    scene = resolve(load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").scenario)
    diagram = build_diagram(scene)
    page = Page([0] * 1000, lambda: 0.0)
    run = LiveRun(diagram, scene.scenario.duration, Console(meshcat, panel=Panel()),
                  page=page)
    trajectory = simulate(scene, realtime_rate=0.0, diagram=diagram, advance=run.advance)
    assert trajectory.times[-1] == pytest.approx(scene.scenario.duration)
    assert page.seen == [] and capsys.readouterr().err == ""
