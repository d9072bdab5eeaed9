"""A whole HSR run at real time with a person at the keyboard: a page with a foreign origin
connects mid-run and presses ← for a second. The robot does not move, the run says why, and
it takes the pause in its stride (no rush to catch up afterwards). And behind the page
front, pages without the run's token or from another origin are refused (HTTP 403) and never
reach Meshcat. The acceptance tests of exclusive control."""

import dataclasses
import threading
import time

import numpy as np
import pytest
from foreign_page import ForeignPage

from pbp_drake.builder import build_diagram, run_task
from pbp_drake.console import PageFront
from pbp_drake.scenarios import Keyboard, load_scenario_file
from pbp_drake.systems.operators.keyboard_operator import LEFT_BUTTON

# Real-time runs a browser's clicks race against: `make test` runs them on their own.
pytestmark = [pytest.mark.slow, pytest.mark.browser]

DURATION = 3.0


def test_a_foreign_page_cannot_move_the_robot(repo, meshcat, capsys):
    scenario = dataclasses.replace(
        load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario,
        method="teleop", operator=Keyboard(), duration=DURATION)
    diagram = build_diagram(scenario, meshcat)
    port = meshcat.port()  # read here: Meshcat is used from this thread alone
    person = ForeignPage(port, origin=meshcat.web_url())
    attack_times = []

    def attack():
        time.sleep(0.8)
        page = ForeignPage(port)
        attack_times.append(time.monotonic())
        for _ in range(40):
            page.press(LEFT_BUTTON)
            time.sleep(0.025)
        page.close()
        attack_times.append(time.monotonic())

    attacker = threading.Thread(target=attack, daemon=True)
    start = time.monotonic()
    attacker.start()
    try:
        result = run_task(scenario, realtime_rate=1.0, diagram=diagram)
    finally:
        person.close()
    wall = time.monotonic() - start
    attacker.join(timeout=5.0)
    assert len(attack_times) == 2, "the attack did not run"

    # Teleop with no input of the person's: the hand stays where it started.
    drift = np.linalg.norm(result.ee_positions - result.ee_positions[0], axis=1).max()
    assert drift < 0.005, drift
    assert not result.operator_active.any()
    assert "Paused: 2 browsers are connected" in capsys.readouterr().err
    # Simulated time stood still during the pause, and the real-time pacing restarted
    # after it: the run lasted its duration plus the pause, rather than catching up.
    pause = attack_times[1] - attack_times[0]
    assert wall > DURATION + pause - 0.3, (wall, pause)


def test_behind_the_front_no_page_without_the_token_and_origin_reaches_the_robot(repo,
                                                                                  meshcat):
    scenario = dataclasses.replace(
        load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario,
        method="teleop", operator=Keyboard(), duration=DURATION)
    diagram = build_diagram(scenario, meshcat)
    front = PageFront(meshcat.port())
    port, own = front.port, f"http://localhost:{front.port}"
    attempts = {"a foreign origin": (f"/?token={front.token}", "http://evil.example"),
                "no token": ("/", own), "a wrong token": ("/?token=" + "x" * 32, own)}
    refusals = {}

    def attack():
        # Each tries, over and over while the run goes, to connect and press the left key.
        deadline = time.monotonic() + DURATION - 0.5
        while time.monotonic() < deadline:
            for name, (path, origin) in attempts.items():
                try:
                    page = ForeignPage(port, origin=origin, path=path)
                except ConnectionError as error:
                    refusals[name] = str(error)
                    continue
                page.press(LEFT_BUTTON)
                page.close()
                refusals[name] = "let in"
            time.sleep(0.05)

    attacker = threading.Thread(target=attack, daemon=True)
    attacker.start()
    try:
        result = run_task(scenario, realtime_rate=1.0, diagram=diagram)
    finally:
        attacker.join(timeout=10.0)
        front.close()
    assert set(refusals) == set(attempts)
    assert all(" 403 " in refusal for refusal in refusals.values()), refusals
    # Nothing reached Meshcat: no connection, no key, and the hand stayed where it started.
    assert meshcat.GetNumActiveConnections() == 0
    assert not result.operator_active.any()
    drift = np.linalg.norm(result.ee_positions - result.ee_positions[0], axis=1).max()
    assert drift < 0.005, drift
