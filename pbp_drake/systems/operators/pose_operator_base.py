"""What the six-DoF browser operators share: the hand's pose in, a world-frame twist out,
the operator frame and the forward drop of PBP modes (`core.operator_frame`)."""

import numpy as np

from pbp_drake.core.operator_frame import capped, operator_twist, without_forward_twist
from pbp_drake.core.pose_arbitration import validate_twist
from pbp_drake.core.quaternion import unit_quaternions
from pbp_drake.systems.operators.browser_input import BrowserOperator, check_params
from pbp_drake.systems.ports import OperatorTwist, PoseState, finite_pose_state


class PoseOperatorBase(BrowserOperator):
    """A six-DoF operator's ports and frame; subclasses read the browser in `_update`.

    .. pydrake_system::

        name: PoseOperatorBase
        input_ports:
        - hand_state
        output_ports:
        - operator_twist
        - operator_active

    Input `hand_state` is the hand's `PoseState` (its orientation sets the operator frame).
    Output `operator_twist` is an `OperatorTwist` in the world frame. Unit inputs
    `(forward, left, up)` and `(yaw, pitch, roll)`, each capped at length 1, are scaled by
    `speed` (m/s) and `rotation_speed` (rad/s). Without `allow_forward` (PBP modes) the
    velocity's forward part along the approach axis z_H is dropped.
    """

    def __init__(self, meshcat, control_period, allow_forward, params, nominal_speed,
                 exclusive):
        check_params(params, positive=("rotation_speed",))
        super().__init__(meshcat, OperatorTwist.size, control_period, allow_forward, params,
                         nominal_speed, exclusive, command_name="operator_twist")
        self._hand_state_port = self.DeclareVectorInputPort("hand_state", PoseState.size)

    def _validate(self, command):
        return validate_twist(command, "operator_twist")

    def _orientation(self, context):
        state = finite_pose_state(self._hand_state_port.Eval(context), "hand_state")
        return unit_quaternions(state[3:7], "hand_state orientation")

    def _twist(self, context, linear, angular):
        """The world twist of unit inputs (each capped at 1), forward dropped in PBP."""
        orientation = self._orientation(context)
        twist = operator_twist(orientation, self._speed * capped(linear),
                               self._rotation_speed * capped(angular))
        if not self._allow_forward:
            twist = without_forward_twist(twist, orientation)
        # A push wholly dropped leaves rounding residue (1e-17): zero, so it reads inactive.
        return np.where(np.abs(twist) < 1e-12, 0.0, twist)
