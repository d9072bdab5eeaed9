"""The Meshcat keyboard and gamepad operators, driven without a browser.

Input is injected as the websocket messages a browser would send (as Drake's own Meshcat
test does), between `simulator.AdvanceTo` calls on the thread that created Meshcat.
"""

import msgpack
import numpy as np
import pytest
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.systems.operators.gamepad_operator import GamepadOperator, GamepadParams
from pbp_drake.systems.operators.keyboard_operator import (
    BACK_BUTTON, FORWARD_BUTTON, KEY_BUTTONS, LEFT_BUTTON, TURN_LEFT_BUTTON,
    TURN_RIGHT_BUTTON, KeyboardOperator, KeyboardParams)

PERIOD = 0.05
SPEED, ROTATION_SPEED, HOLD_TIME = 0.2, 0.6, 0.25
HEADING = np.pi / 2  # the robot faces world +y: its left is world -x, forward is +y
LEFT_IN_WORLD = np.array([-1.0, 0.0])
FORWARD_IN_WORLD = np.array([0.0, 1.0])


@pytest.fixture
def meshcat():
    return Meshcat(MeshcatParams(host="localhost", port=0))  # port 0: any free port


class Rig:
    """An operator fed a fixed `ee_state`, in a simulator, and its sampled outputs."""

    def __init__(self, operator, heading=HEADING):
        builder = DiagramBuilder()
        builder.AddSystem(operator)
        ee_state = np.zeros(8)
        ee_state[6] = heading
        source = builder.AddSystem(ConstantVectorSource(ee_state))
        builder.Connect(source.get_output_port(), operator.get_ee_state_input_port())
        self.operator = operator
        self.simulator = Simulator(builder.Build())
        self.simulator.Initialize()
        self.context = operator.GetMyContextFromRoot(self.simulator.get_context())

    def advance(self, duration):
        time = self.simulator.get_context().get_time()
        self.simulator.AdvanceTo(time + duration)

    def command(self):
        return self.operator.get_operator_command_output_port().Eval(self.context)

    def active(self):
        return bool(self.operator.get_operator_active_output_port().Eval(self.context)[0])

    def active_time(self, duration):
        """How long the operator stays active over the next `duration` seconds."""
        ticks = 0
        for _ in range(int(round(duration / PERIOD))):
            self.advance(PERIOD)
            ticks += self.active()
        return ticks * PERIOD


def click(meshcat, name):
    meshcat._InjectWebsocketMessage(msgpack.packb({"type": "button", "name": name}))


def set_gamepad(meshcat, axes, index=0):
    gamepad = {} if axes is None else {
        "index": index, "button_values": [0.0] * 17, "axes": list(axes)}
    meshcat._InjectWebsocketMessage(
        msgpack.packb({"type": "gamepad", "name": "", "gamepad": gamepad}))


def keyboard_rig(meshcat, allow_forward):
    return Rig(KeyboardOperator(meshcat, PERIOD, allow_forward, KeyboardParams(
        speed=SPEED, rotation_speed=ROTATION_SPEED, hold_time=HOLD_TIME)))


def test_keyboard_buttons_carry_their_keys(meshcat):
    operator = KeyboardOperator(meshcat, PERIOD, allow_forward=True, nominal_speed=SPEED)
    assert set(meshcat.GetButtonNames()) == set(KEY_BUTTONS)
    assert KEY_BUTTONS[LEFT_BUTTON] == "ArrowLeft"
    assert KEY_BUTTONS[TURN_LEFT_BUTTON] == "KeyQ"
    operator.Delete()
    assert meshcat.GetButtonNames() == []


def test_left_arrow_moves_to_the_robots_left_for_the_hold_time(meshcat):
    rig = keyboard_rig(meshcat, allow_forward=False)
    rig.advance(0.2)
    assert not rig.active()
    click(meshcat, LEFT_BUTTON)
    rig.advance(PERIOD)
    assert rig.active()
    np.testing.assert_allclose(rig.command(), [*(SPEED * LEFT_IN_WORLD), 0.0, 0.0],
                               atol=1e-12)
    # Held for hold_time after the click (to within a tick), then it stops.
    assert abs(PERIOD + rig.active_time(1.0) - HOLD_TIME) <= PERIOD + 1e-9
    assert not rig.active()
    np.testing.assert_array_equal(rig.command(), np.zeros(4))


def test_repeated_clicks_keep_a_key_held(meshcat):
    """Browser key auto-repeat clicks every ~33 ms: the motion does not stutter."""
    rig = keyboard_rig(meshcat, allow_forward=False)
    active = []
    for _ in range(20):
        click(meshcat, LEFT_BUTTON)
        rig.advance(PERIOD)
        active.append(rig.active())
    assert all(active)


def test_clicks_before_initialisation_are_ignored(meshcat):
    operator = KeyboardOperator(meshcat, PERIOD, allow_forward=False, nominal_speed=SPEED)
    click(meshcat, LEFT_BUTTON)
    rig = Rig(operator)
    rig.advance(2 * PERIOD)
    assert not rig.active()


def test_forward_only_when_allowed(meshcat):
    rig = keyboard_rig(meshcat, allow_forward=False)
    assert FORWARD_BUTTON not in meshcat.GetButtonNames()
    click(meshcat, FORWARD_BUTTON)  # an unknown button: Meshcat ignores it
    rig.advance(PERIOD)
    assert not rig.active()
    click(meshcat, BACK_BUTTON)  # back is always allowed
    rig.advance(PERIOD)
    np.testing.assert_allclose(rig.command()[:2], -SPEED * FORWARD_IN_WORLD, atol=1e-12)
    rig.operator.Delete()

    rig = keyboard_rig(meshcat, allow_forward=True)
    click(meshcat, FORWARD_BUTTON)
    rig.advance(PERIOD)
    assert rig.active()
    np.testing.assert_allclose(rig.command(), [*(SPEED * FORWARD_IN_WORLD), 0.0, 0.0],
                               atol=1e-12)


@pytest.mark.parametrize("button, sign", [(TURN_LEFT_BUTTON, 1.0), (TURN_RIGHT_BUTTON, -1.0)])
def test_q_and_e_turn(meshcat, button, sign):
    rig = keyboard_rig(meshcat, allow_forward=False)
    click(meshcat, button)
    rig.advance(PERIOD)
    assert rig.active()
    np.testing.assert_allclose(rig.command(), [0.0, 0.0, 0.0, sign * ROTATION_SPEED])


def test_two_keys_combine(meshcat):
    rig = keyboard_rig(meshcat, allow_forward=True)
    click(meshcat, LEFT_BUTTON)
    click(meshcat, TURN_LEFT_BUTTON)
    rig.advance(PERIOD)
    np.testing.assert_allclose(rig.command(), [*(SPEED * LEFT_IN_WORLD), 0.0, ROTATION_SPEED],
                               atol=1e-12)
    # Forward and left together go diagonally, still at `speed`.
    rig.advance(1.0)
    click(meshcat, FORWARD_BUTTON)
    click(meshcat, LEFT_BUTTON)
    rig.advance(PERIOD)
    diagonal = SPEED * (FORWARD_IN_WORLD + LEFT_IN_WORLD) / np.sqrt(2)
    np.testing.assert_allclose(rig.command(), [*diagonal, 0.0, 0.0], atol=1e-12)


def gamepad_rig(meshcat, allow_forward):
    return Rig(GamepadOperator(meshcat, PERIOD, allow_forward, GamepadParams(
        speed=SPEED, rotation_speed=ROTATION_SPEED, dead_zone=0.15)))


def test_no_gamepad_is_inactive(meshcat):
    rig = gamepad_rig(meshcat, allow_forward=True)
    rig.advance(2 * PERIOD)
    assert not rig.active()
    np.testing.assert_array_equal(rig.command(), np.zeros(4))
    # A disconnected gamepad: the browser sends an empty status.
    set_gamepad(meshcat, [-1.0, 0.0, 0.0, 0.0])
    rig.advance(PERIOD)
    assert rig.active()
    set_gamepad(meshcat, None)
    rig.advance(PERIOD)
    assert not rig.active()


def test_gamepad_left_stick_moves_beyond_the_dead_zone(meshcat):
    rig = gamepad_rig(meshcat, allow_forward=True)
    set_gamepad(meshcat, [-0.1, 0.05, 0.1, 0.0])  # a resting stick's drift
    rig.advance(PERIOD)
    assert not rig.active()
    np.testing.assert_array_equal(rig.command(), np.zeros(4))

    set_gamepad(meshcat, [-1.0, 0.0, 0.0, 0.0])  # full left
    rig.advance(PERIOD)
    assert rig.active()
    np.testing.assert_allclose(rig.command(), [*(SPEED * LEFT_IN_WORLD), 0.0, 0.0],
                               atol=1e-12)

    set_gamepad(meshcat, [0.0, -1.0, 0.0, 0.0])  # full up (y is down) = forward
    rig.advance(PERIOD)
    np.testing.assert_allclose(rig.command(), [*(SPEED * FORWARD_IN_WORLD), 0.0, 0.0],
                               atol=1e-12)

    set_gamepad(meshcat, [0.0, -0.16, 0.0, 0.0])  # just past the dead zone: barely moves
    rig.advance(PERIOD)
    assert rig.active()
    # Rescaled from the dead zone's edge, so the speed rises continuously from 0.
    np.testing.assert_allclose(np.linalg.norm(rig.command()[:2]),
                               SPEED * (0.16 - 0.15) / (1.0 - 0.15))


def test_gamepad_right_stick_turns(meshcat):
    rig = gamepad_rig(meshcat, allow_forward=False)
    set_gamepad(meshcat, [0.0, 0.0, -1.0, 0.0])  # right stick left: turn left
    rig.advance(PERIOD)
    np.testing.assert_allclose(rig.command(), [0.0, 0.0, 0.0, ROTATION_SPEED], atol=1e-12)
    set_gamepad(meshcat, [0.0, 0.0, 0.5, 0.0])
    rig.advance(PERIOD)
    assert rig.command()[3] < 0.0


def test_gamepad_forward_only_when_allowed(meshcat):
    rig = gamepad_rig(meshcat, allow_forward=False)
    set_gamepad(meshcat, [0.0, -1.0, 0.0, 0.0])  # full forward: ignored
    rig.advance(PERIOD)
    assert not rig.active()
    np.testing.assert_array_equal(rig.command(), np.zeros(4))
    set_gamepad(meshcat, [0.0, 1.0, 0.0, 0.0])  # full back: allowed
    rig.advance(PERIOD)
    np.testing.assert_allclose(rig.command()[:2], -SPEED * FORWARD_IN_WORLD, atol=1e-12)


def test_forgotten_input_drives_nothing_until_it_changes(meshcat):
    # A page closed with its stick tilted: Meshcat keeps that last state.
    rig = gamepad_rig(meshcat, allow_forward=True)
    set_gamepad(meshcat, [-1.0, 0.0, 0.0, 0.0])
    rig.advance(PERIOD)
    assert rig.active()
    rig.operator.forget_input(rig.simulator.get_mutable_context())
    rig.advance(2 * PERIOD)
    assert not rig.active()
    set_gamepad(meshcat, [-0.9, 0.0, 0.0, 0.0])  # a page's pad that moves: read again
    rig.advance(PERIOD)
    assert rig.active()
    # The keys: one held is released.
    keys = keyboard_rig(meshcat, allow_forward=False)
    click(meshcat, LEFT_BUTTON)
    keys.advance(PERIOD)
    assert keys.active()
    keys.operator.forget_input(keys.simulator.get_mutable_context())
    keys.advance(PERIOD)
    assert not keys.active()


@pytest.mark.parametrize("operator", [KeyboardOperator, GamepadOperator])
def test_a_browser_operator_names_a_meshcat_or_params_it_cannot_use(meshcat, operator):
    with pytest.raises(ValueError, match=r"^meshcat must be a pydrake Meshcat "
                                         r"\(StartMeshcat\(\)\), got NoneType"):
        operator(None, PERIOD, allow_forward=False, nominal_speed=SPEED)
    with pytest.raises(ValueError, match=r"^params must be the operator's parameters \(e.g. "
                                         r"KeyboardParams\), got NoneType"):
        operator(meshcat, PERIOD, False, None, nominal_speed=SPEED)
    with pytest.raises(ValueError, match="the operator's speed must be positive: got speed "
                                         "0.0 and nominal_speed 'fast'"):
        operator(meshcat, PERIOD, allow_forward=False, nominal_speed="fast")
