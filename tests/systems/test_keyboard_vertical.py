"""The keyboard operator's optional up and down keys (R and F), driven without a browser:
clicks are injected as the websocket messages a page sends, between `AdvanceTo` calls on
the thread that created Meshcat (`meshcat`: the fixture of `tests/conftest.py`)."""

import msgpack
import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.systems.operators.keyboard_operator import (
    BACK_BUTTON, DOWN_BUTTON, FORWARD_BUTTON, KEY_BUTTONS, LEFT_BUTTON, UP_BUTTON,
    VERTICAL_KEY_BUTTONS, KeyboardOperator, KeyboardParams)

PERIOD = 0.05
SPEED, ROTATION_SPEED, HOLD_TIME = 0.2, 0.6, 0.25
HEADING = np.pi / 2  # the robot faces world +y: its left is world -x
LEFT_IN_WORLD = np.array([-1.0, 0.0, 0.0])
BACK_IN_WORLD = np.array([0.0, -1.0, 0.0])
UP = np.array([0.0, 0.0, 1.0])


class Rig:
    """A keyboard operator fed a fixed `ee_state`, in a simulator."""

    def __init__(self, meshcat, allow_forward, vertical=True):
        self.meshcat = meshcat
        self.operator = KeyboardOperator(meshcat, PERIOD, allow_forward, KeyboardParams(
            speed=SPEED, rotation_speed=ROTATION_SPEED, hold_time=HOLD_TIME),
            vertical=vertical)
        builder = DiagramBuilder()
        builder.AddSystem(self.operator)
        ee_state = np.zeros(8)
        ee_state[2], ee_state[6] = 0.35, HEADING
        source = builder.AddSystem(ConstantVectorSource(ee_state))
        builder.Connect(source.get_output_port(), self.operator.get_ee_state_input_port())
        self.simulator = Simulator(builder.Build())
        self.simulator.Initialize()
        self.context = self.operator.GetMyContextFromRoot(self.simulator.get_context())

    def press(self, *names):
        """Clicks the buttons as a page does on their keydowns, then runs one tick;
        returns the command and whether the operator is active."""
        for name in names:
            self.meshcat._InjectWebsocketMessage(
                msgpack.packb({"type": "button", "name": name}))
        self.simulator.AdvanceTo(self.simulator.get_context().get_time() + PERIOD)
        command = self.operator.get_operator_command_output_port().Eval(self.context)
        active = self.operator.get_operator_active_output_port().Eval(self.context)[0]
        return np.array(command), bool(active)

    def release_all(self):
        self.simulator.AdvanceTo(self.simulator.get_context().get_time() + 2 * HOLD_TIME)


def test_up_and_down_are_r_and_f_only_with_vertical_motion(meshcat):
    planar = KeyboardOperator(meshcat, PERIOD, allow_forward=True, nominal_speed=SPEED)
    assert set(meshcat.GetButtonNames()) == set(KEY_BUTTONS)
    assert UP_BUTTON not in planar.button_names() and DOWN_BUTTON not in planar.button_names()
    planar.Delete()
    vertical = KeyboardOperator(meshcat, PERIOD, allow_forward=True, nominal_speed=SPEED,
                                vertical=True)
    assert set(meshcat.GetButtonNames()) == set(KEY_BUTTONS) | {UP_BUTTON, DOWN_BUTTON}
    assert VERTICAL_KEY_BUTTONS == {UP_BUTTON: "KeyR", DOWN_BUTTON: "KeyF"}
    vertical.Delete()
    assert meshcat.GetButtonNames() == []


@pytest.mark.parametrize("button, sign", [(UP_BUTTON, 1.0), (DOWN_BUTTON, -1.0)])
def test_up_and_down_move_the_hand_vertically_at_speed(meshcat, button, sign):
    rig = Rig(meshcat, allow_forward=True)
    command, active = rig.press(button)
    assert active
    np.testing.assert_allclose(command, [0.0, 0.0, sign * SPEED, 0.0], atol=1e-12)


def test_up_with_a_sidestep_goes_diagonally_at_speed(meshcat):
    rig = Rig(meshcat, allow_forward=True)
    command, _ = rig.press(UP_BUTTON, LEFT_BUTTON)
    np.testing.assert_allclose(command[:3], SPEED * (UP + LEFT_IN_WORLD) / np.sqrt(2),
                               atol=1e-12)
    assert np.linalg.norm(command[:3]) == pytest.approx(SPEED)
    rig.release_all()
    command, active = rig.press(UP_BUTTON, DOWN_BUTTON)  # opposite keys cancel
    assert active and np.array_equal(command[:3], np.zeros(3))


def test_up_and_down_work_under_pbp_where_forward_is_off(meshcat):
    rig = Rig(meshcat, allow_forward=False)
    assert FORWARD_BUTTON not in meshcat.GetButtonNames()
    assert {UP_BUTTON, DOWN_BUTTON} <= set(meshcat.GetButtonNames())
    command, active = rig.press(FORWARD_BUTTON)  # not a button here: ignored
    assert not active
    command, active = rig.press(UP_BUTTON)
    assert active
    np.testing.assert_allclose(command, [0.0, 0.0, SPEED, 0.0], atol=1e-12)
    rig.release_all()
    command, _ = rig.press(DOWN_BUTTON, BACK_BUTTON)
    np.testing.assert_allclose(command[:3], SPEED * (BACK_IN_WORLD - UP) / np.sqrt(2),
                               atol=1e-12)


def test_without_vertical_motion_the_keys_are_as_before(meshcat):
    rig = Rig(meshcat, allow_forward=False, vertical=False)
    assert set(rig.operator.button_names()) == set(KEY_BUTTONS) - {FORWARD_BUTTON}
    command, active = rig.press(UP_BUTTON)  # not a button here: ignored
    assert not active and np.array_equal(command, np.zeros(4))
    command, _ = rig.press(LEFT_BUTTON, BACK_BUTTON)
    diagonal = SPEED * (LEFT_IN_WORLD + BACK_IN_WORLD) / np.sqrt(2)
    np.testing.assert_allclose(command[:2], diagonal[:2], atol=1e-12)
    assert command[2] == 0.0
