"""Exclusive control: a second page connected to Meshcat pauses a person's operator, and
nothing it sends moves the robot. The second page is a raw websocket with a
foreign Origin (`foreign_page.ForeignPage`), driven from a thread of its own; Meshcat is
used only from the test's thread."""

import threading
import time

import pytest

from foreign_page import ForeignPage
from test_browser_operators import PERIOD, Rig, gamepad_rig, set_gamepad

from pbp_drake.systems.operators.keyboard_operator import LEFT_BUTTON, KeyboardOperator


def port_of(meshcat):
    return meshcat.port()


class Attack(threading.Thread):
    """Opens a page with a foreign origin, sends `messages` (or presses ← `presses`
    times), stays `linger` seconds, then closes."""

    def __init__(self, meshcat, presses=20, messages=(), linger=0.3):
        super().__init__(daemon=True)
        self._port = port_of(meshcat)
        self._presses, self._messages, self._linger = presses, messages, linger

    def run(self):
        page = ForeignPage(self._port)
        for _ in range(self._presses):
            page.press(LEFT_BUTTON)
            time.sleep(0.02)
        for message in self._messages:
            page.send(message)
        time.sleep(self._linger)
        page.close()


def drive_through(rig, attack, after=0.3):
    """Advances `rig` tick by tick while `attack` runs, then `after` seconds more; returns
    whether the operator was ever active."""
    active = False
    attack.start()
    while attack.is_alive():
        rig.advance(PERIOD)
        active |= rig.active()
        time.sleep(0.005)
    for _ in range(int(round(after / PERIOD))):
        rig.advance(PERIOD)
        active |= rig.active()
    return active


def keyboard(meshcat, exclusive):
    return Rig(KeyboardOperator(meshcat, PERIOD, allow_forward=False, nominal_speed=0.2,
                                exclusive=exclusive))


@pytest.mark.slow
def test_a_second_page_pauses_the_keyboard_and_its_presses_are_dropped(meshcat, capsys):
    person = ForeignPage(port_of(meshcat), origin=meshcat.web_url())
    rig = keyboard(meshcat, exclusive=True)
    try:
        assert not drive_through(rig, Attack(meshcat))
    finally:
        person.close()
    assert rig.operator.browser_guard.pauses >= 1
    err = capsys.readouterr().err
    assert "Paused: 2 browsers are connected" in err
    assert "the robot goes on" in err


@pytest.mark.slow
def test_without_exclusive_control_the_second_page_drives(meshcat):
    person = ForeignPage(port_of(meshcat), origin=meshcat.web_url())
    rig = keyboard(meshcat, exclusive=False)
    try:
        assert drive_through(rig, Attack(meshcat))
    finally:
        person.close()


@pytest.mark.slow
def test_the_pause_is_shown_in_the_page(meshcat):
    person = ForeignPage(port_of(meshcat), origin=meshcat.web_url())
    rig = keyboard(meshcat, exclusive=True)
    try:
        drive_through(rig, Attack(meshcat, presses=0))
        time.sleep(0.2)
    finally:
        person.close()
    # Meshcat sends a page its controls: the notice came, and left with the pause.
    notice = b"Paused: 2 browsers are connected"
    assert notice in person.received()
    assert not any(name.startswith("Paused") for name in meshcat.GetButtonNames())


@pytest.mark.slow
def test_a_gamepad_state_left_by_a_second_page_is_ignored_until_the_sticks_move(meshcat):
    person = ForeignPage(port_of(meshcat), origin=meshcat.web_url())
    rig = gamepad_rig(meshcat, allow_forward=True)
    full_left = {"type": "gamepad", "name": "", "gamepad": {
        "index": 0, "button_values": [0.0] * 17, "axes": [-1.0, 0.0, 0.0, 0.0]}}
    try:
        assert not drive_through(rig, Attack(meshcat, presses=0, messages=[full_left]))
        # Meshcat still holds the stick the other page left: ignored.
        assert list(meshcat.GetGamepad().axes)[:1] == [-1.0]
        assert not rig.active()
        # The person's own gamepad moves: read again.
        set_gamepad(meshcat, [0.0, 1.0, 0.0, 0.0])
        rig.advance(PERIOD)
        assert rig.active()
    finally:
        person.close()
