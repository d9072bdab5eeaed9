"""The operators: whoever or whatever commands the robot beside the PBP policy (a person in
the browser, the virtual participant, the 2-D scenes' open-loop operators)."""

from pbp_drake.systems.operators.gamepad_operator import GamepadOperator
from pbp_drake.systems.operators.idle_operator import IdleOperator
from pbp_drake.systems.operators.keyboard_operator import KeyboardOperator
from pbp_drake.systems.operators.obstacle_repulsion_operator import ObstacleRepulsionOperator
from pbp_drake.systems.operators.pose_gamepad_operator import PoseGamepadOperator
from pbp_drake.systems.operators.pose_keyboard_operator import PoseKeyboardOperator
from pbp_drake.systems.operators.pose_virtual_operator import PoseVirtualOperator
from pbp_drake.systems.operators.scripted_operator import ScriptedOperator
from pbp_drake.systems.operators.virtual_operator import VirtualOperator

__all__ = ["GamepadOperator", "IdleOperator", "KeyboardOperator", "ObstacleRepulsionOperator",
           "PoseGamepadOperator", "PoseKeyboardOperator", "PoseVirtualOperator",
           "ScriptedOperator", "VirtualOperator"]
