"""The six-DoF browser operators driven through Meshcat's websocket, as a page drives them:
`foreign_page.ForeignPage` sends the gamepad states and button clicks a Meshcat page sends
(here it is the one connected page, so `BrowserGuard` lets it drive). Meshcat is used only
from the test's thread; each message is awaited there before the simulator steps on."""

import time

import numpy as np
import pytest
from foreign_page import ForeignPage
from test_browser_guard import Attack
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.core.grasp_task import side_grasp_orientation, top_grasp_orientation
from pbp_drake.systems.operators.pose_gamepad_operator import PoseGamepadOperator, PoseGamepadParams
from pbp_drake.systems.operators.pose_keyboard_operator import (
    BACK_KEY, FORWARD_KEY, LEFT_KEY, MODE_LABELS, ROTATE, TRANSLATE, UP_KEY,
    PoseKeyboardOperator, PoseKeyboardParams)

PERIOD = 0.05
SPEED, ROTATION_SPEED, DEAD_ZONE, HOLD_TIME = 0.2, 0.6, 0.15, 0.25
# A side grasp's hand turned to face world +y: its approach z_H and forward are +y, its
# left is world -x, up is +z. A frame mistake shows up as a wrong world axis.
FACING_Y = side_grasp_orientation(np.pi / 2)
FORWARD, LEFT, UP = np.array([0, 1.0, 0]), np.array([-1.0, 0, 0]), np.array([0, 0, 1.0])


def twist(linear=(0, 0, 0), angular=(0, 0, 0)):
    return np.concatenate([linear, angular]).astype(float)


class Rig:
    """An operator fed a fixed hand pose, a simulator, and a page on Meshcat's websocket."""

    def __init__(self, meshcat, operator, orientation=FACING_Y):
        hand = np.zeros(13)
        hand[:3] = [1.0, 0.0, 0.8]
        hand[3:7] = orientation
        builder = DiagramBuilder()
        builder.AddSystem(operator)
        source = builder.AddSystem(ConstantVectorSource(hand))
        builder.Connect(source.get_output_port(), operator.get_hand_state_input_port())
        self.meshcat, self.operator = meshcat, operator
        self.simulator = Simulator(builder.Build())
        self.simulator.Initialize()
        self.context = operator.GetMyContextFromRoot(self.simulator.get_context())
        self.page = ForeignPage(meshcat.port(), origin=meshcat.web_url())

    def close(self):
        self.page.close()

    def step(self, ticks=1):
        now = self.simulator.get_context().get_time()
        self.simulator.AdvanceTo(now + ticks * PERIOD)

    def twist(self):
        return np.array(self.operator.get_operator_twist_output_port().Eval(self.context))

    def active(self):
        return bool(self.operator.get_operator_active_output_port().Eval(self.context)[0])

    def gamepad(self, axes=(0, 0, 0, 0), buttons=()):
        """Sends a gamepad state as the page does, waits for Meshcat to hold it, steps."""
        values = [0.0] * 17
        for index, value in dict(buttons).items():
            values[index] = value
        self.page.send({"type": "gamepad", "name": "",
                        "gamepad": {"index": 0, "button_values": values, "axes": list(axes)}})
        wait_for(lambda: list(self.meshcat.GetGamepad().axes) == list(axes)
                 and list(self.meshcat.GetGamepad().button_values) == values)
        self.step()

    def press(self, name):
        """Clicks a button as the page does on a keydown, waits for Meshcat, steps."""
        before = self.meshcat.GetButtonClicks(name)
        self.page.press(name)
        wait_for(lambda: self.meshcat.GetButtonClicks(name) > before)
        self.step()


def wait_for(condition, timeout=5.0):
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "Meshcat did not receive the page's message"
        time.sleep(0.002)


@pytest.fixture
def rigs(meshcat):
    made = []

    def make(operator, orientation=FACING_Y):
        made.append(Rig(meshcat, operator, orientation))
        return made[-1]

    yield make
    for rig in made:
        rig.close()


def gamepad(meshcat, allow_forward):
    return PoseGamepadOperator(meshcat, PERIOD, allow_forward, PoseGamepadParams(
        speed=SPEED, rotation_speed=ROTATION_SPEED, dead_zone=DEAD_ZONE))


def keyboard(meshcat, allow_forward):
    return PoseKeyboardOperator(meshcat, PERIOD, allow_forward, PoseKeyboardParams(
        speed=SPEED, rotation_speed=ROTATION_SPEED, hold_time=HOLD_TIME))


# Standard mapping: axes [LX, LY, RX, RY] (y down); buttons 4 LB, 5 RB, 6 LT, 7 RT.
GAMEPAD_AXES = [
    ("left stick left", dict(axes=(-1, 0, 0, 0)), twist(SPEED * LEFT)),
    ("left stick up", dict(axes=(0, -1, 0, 0)), twist(SPEED * FORWARD)),
    ("left stick down", dict(axes=(0, 1, 0, 0)), twist(-SPEED * FORWARD)),
    ("right trigger", dict(buttons={7: 1.0}), twist(SPEED * UP)),
    ("left trigger", dict(buttons={6: 1.0}), twist(-SPEED * UP)),
    ("right stick left", dict(axes=(0, 0, -1, 0)), twist(angular=ROTATION_SPEED * UP)),
    # Pushed up, the right stick tips the approach axis down: about the hand's left.
    ("right stick up", dict(axes=(0, 0, 0, -1)), twist(angular=ROTATION_SPEED * LEFT)),
    # Shoulders roll about the approach axis z_H (world +y here): RB right-handed.
    ("right shoulder", dict(buttons={5: 1.0}), twist(angular=ROTATION_SPEED * FORWARD)),
    ("left shoulder", dict(buttons={4: 1.0}), twist(angular=-ROTATION_SPEED * FORWARD)),
]


def test_each_gamepad_axis_moves_the_hand_along_its_own_world_axis(meshcat, rigs):
    rig = rigs(gamepad(meshcat, allow_forward=True))
    rig.step(2)
    assert not rig.active()  # no gamepad yet
    for name, controls, expected in GAMEPAD_AXES:
        rig.gamepad(**controls)
        assert rig.active(), name
        np.testing.assert_allclose(rig.twist(), expected, atol=1e-12, err_msg=name)
        rig.gamepad()  # back to rest
        assert not rig.active(), name
        np.testing.assert_array_equal(rig.twist(), np.zeros(6))


def test_gamepad_dead_zone(meshcat, rigs):
    rig = rigs(gamepad(meshcat, allow_forward=True))
    rig.gamepad(axes=(-0.1, 0.05, 0.1, -0.1), buttons={6: 0.1, 7: 0.12})  # resting drift
    assert not rig.active()
    np.testing.assert_array_equal(rig.twist(), np.zeros(6))
    rig.gamepad(axes=(0, -0.16, 0, 0))  # just past the dead zone: barely moves
    assert rig.active()
    np.testing.assert_allclose(rig.twist(), twist(
        SPEED * (0.16 - DEAD_ZONE) / (1 - DEAD_ZONE) * FORWARD), atol=1e-12)
    # Two full pushes together go no faster than one.
    rig.gamepad(axes=(-1, -1, 0, 0), buttons={7: 1.0})
    np.testing.assert_allclose(np.linalg.norm(rig.twist()[:3]), SPEED)


def test_pbp_drops_the_gamepads_push_along_the_approach_axis(meshcat, rigs):
    rig = rigs(gamepad(meshcat, allow_forward=False))
    rig.gamepad(axes=(0, -1, 0, 0))  # forward, along z_H: dropped
    assert not rig.active()
    np.testing.assert_array_equal(rig.twist(), np.zeros(6))
    rig.gamepad(axes=(0, 1, 0, 0))  # back: allowed
    np.testing.assert_allclose(rig.twist(), twist(-SPEED * FORWARD), atol=1e-12)
    rig.gamepad(axes=(-1, -1, 0, 0))  # forward-left: only the left part is left
    np.testing.assert_allclose(rig.twist(), twist(SPEED / np.sqrt(2) * LEFT), atol=1e-12)


def test_pbp_drops_the_push_down_of_a_hand_grasping_from_above(meshcat, rigs):
    rig = rigs(gamepad(meshcat, allow_forward=False), top_grasp_orientation(0.0))
    rig.gamepad(buttons={6: 1.0})  # down is along the approach: dropped
    assert not rig.active()
    rig.gamepad(buttons={7: 1.0})  # up: allowed
    np.testing.assert_allclose(rig.twist(), twist(SPEED * UP), atol=1e-12)
    rig.gamepad(axes=(0, -1, 0, 0))  # forward over the table (+x here): allowed
    np.testing.assert_allclose(rig.twist(), twist([SPEED, 0, 0]), atol=1e-12)


def test_the_mode_key_turns_the_arrows_from_translation_to_rotation(meshcat, rigs):
    rig = rigs(keyboard(meshcat, allow_forward=True))
    assert MODE_LABELS[TRANSLATE] in meshcat.GetButtonNames()
    rig.press(FORWARD_KEY)
    np.testing.assert_allclose(rig.twist(), twist(SPEED * FORWARD), atol=1e-12)
    rig.press(LEFT_KEY)
    rig.step(round(HOLD_TIME / PERIOD))  # both released
    assert not rig.active()

    rig.press(MODE_LABELS[TRANSLATE])
    assert rig.operator.mode(rig.context) == ROTATE
    # The page shows the mode: the button now carries the rotate label.
    assert MODE_LABELS[ROTATE] in meshcat.GetButtonNames()
    assert MODE_LABELS[TRANSLATE] not in meshcat.GetButtonNames()
    wait_for(lambda: MODE_LABELS[ROTATE].encode() in rig.page.received())  # sent to the page
    rig.press(FORWARD_KEY)  # ↑ now tips the approach axis down (about the hand's left)
    np.testing.assert_allclose(rig.twist(), twist(angular=ROTATION_SPEED * LEFT), atol=1e-12)
    rig.step(round(HOLD_TIME / PERIOD))
    rig.press(LEFT_KEY)  # ← yaws left
    np.testing.assert_allclose(rig.twist(), twist(angular=ROTATION_SPEED * UP), atol=1e-12)
    rig.step(round(HOLD_TIME / PERIOD))
    rig.press(UP_KEY)  # PageUp rolls right-handed about z_H
    np.testing.assert_allclose(rig.twist(), twist(angular=ROTATION_SPEED * FORWARD),
                               atol=1e-12)

    # A held R repeats its keydown: it toggles once, back to translation.
    rig.step(round(HOLD_TIME / PERIOD))
    for _ in range(4):
        rig.press(rig.operator.button_names()[-1])
    assert rig.operator.mode(rig.context) == TRANSLATE
    assert MODE_LABELS[TRANSLATE] in meshcat.GetButtonNames()
    rig.step(round(HOLD_TIME / PERIOD))
    rig.press(BACK_KEY)
    np.testing.assert_allclose(rig.twist(), twist(-SPEED * FORWARD), atol=1e-12)


def test_pbp_drops_the_forward_key_but_not_the_tip_down(meshcat, rigs):
    rig = rigs(keyboard(meshcat, allow_forward=False))
    rig.press(FORWARD_KEY)
    assert not rig.active()
    np.testing.assert_array_equal(rig.twist(), np.zeros(6))
    rig.step(round(HOLD_TIME / PERIOD))
    rig.press(MODE_LABELS[TRANSLATE])
    rig.press(FORWARD_KEY)
    assert rig.active()
    np.testing.assert_allclose(rig.twist(), twist(angular=ROTATION_SPEED * LEFT), atol=1e-12)


def drive_through(rig, attack, after=0.3):
    """Steps `rig` while `attack` (a second page) runs, then `after` seconds more; returns
    whether the operator was ever active."""
    active = False
    attack.start()
    while attack.is_alive():
        rig.step()
        active |= rig.active()
        time.sleep(0.005)
    for _ in range(round(after / PERIOD)):
        rig.step()
        active |= rig.active()
    return active


@pytest.mark.slow
def test_a_second_page_cannot_drive_the_six_dof_keyboard(meshcat, rigs):
    rig = rigs(keyboard(meshcat, allow_forward=True))
    presses = [{"type": "button", "name": name}
               for name in [LEFT_KEY, MODE_LABELS[TRANSLATE], LEFT_KEY] * 5]
    assert not drive_through(rig, Attack(meshcat, presses=0, messages=presses))
    assert rig.operator.browser_guard.pauses >= 1
    assert rig.operator.mode(rig.context) == TRANSLATE  # its R was dropped too
    rig.press(LEFT_KEY)  # the person's own page drives again
    np.testing.assert_allclose(rig.twist(), twist(SPEED * LEFT), atol=1e-12)


@pytest.mark.slow
def test_a_second_pages_gamepad_is_ignored_until_the_controls_move(meshcat, rigs):
    rig = rigs(gamepad(meshcat, allow_forward=True))
    values = [0.0] * 17
    values[7] = 1.0  # the other page leaves the right trigger pulled
    pulled = {"type": "gamepad", "name": "",
              "gamepad": {"index": 0, "button_values": values, "axes": [0.0] * 4}}
    assert not drive_through(rig, Attack(meshcat, presses=0, messages=[pulled]))
    assert list(meshcat.GetGamepad().button_values)[7] == 1.0  # Meshcat still holds it
    assert not rig.active()
    rig.gamepad(axes=(0, 1, 0, 0))  # the person's gamepad moves: read again
    np.testing.assert_allclose(rig.twist(), twist(-SPEED * FORWARD), atol=1e-12)


def test_a_nan_hand_pose_is_refused_by_field(meshcat):
    operator = gamepad(meshcat, allow_forward=True)
    builder = DiagramBuilder()
    builder.AddSystem(operator)
    hand = np.zeros(13)
    hand[3:7] = FACING_Y
    hand[4] = np.nan
    source = builder.AddSystem(ConstantVectorSource(hand))
    builder.Connect(source.get_output_port(), operator.get_hand_state_input_port())
    simulator = Simulator(builder.Build())
    from_page = {"type": "gamepad", "name": "",
                 "gamepad": {"index": 0, "button_values": [0.0] * 17, "axes": [-1, 0, 0, 0]}}
    page = ForeignPage(meshcat.port(), origin=meshcat.web_url())
    try:
        page.send(from_page)
        wait_for(lambda: list(meshcat.GetGamepad().axes) == [-1, 0, 0, 0])
        with pytest.raises(ValueError, match="hand_state qx is NaN"):
            simulator.AdvanceTo(PERIOD)
    finally:
        page.close()


@pytest.mark.parametrize("make, field, value", [
    (lambda m, **f: PoseGamepadOperator(m, PERIOD, True, PoseGamepadParams(**f), 0.2),
     "dead_zone", 1.0),
    (lambda m, **f: PoseGamepadOperator(m, PERIOD, True, PoseGamepadParams(**f), 0.2),
     "rotation_speed", float("nan")),
    (lambda m, **f: PoseKeyboardOperator(m, PERIOD, True, PoseKeyboardParams(**f), 0.2),
     "hold_time", 0.0),
    (lambda m, **f: PoseKeyboardOperator(m, PERIOD, True, PoseKeyboardParams(**f), 0.2),
     "speed", -1.0),
])
def test_bad_params_are_refused_by_field(meshcat, make, field, value):
    with pytest.raises(ValueError, match=field):
        make(meshcat, **{field: value})
