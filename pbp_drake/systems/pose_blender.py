"""Six-DoF blending as a Drake system: the operator's twist and the pose DMP's reference
become one pose reference (`pbp_drake.core.pose_arbitration`)."""

from pydrake.systems.framework import BasicVector, LeafSystem

from pbp_drake.core import quaternion
from pbp_drake.core.arbitration import (
    DEFAULT_ALPHA_MAX, DEFAULT_CONFIDENCE_HIGH, DEFAULT_CONFIDENCE_LOW, confidence_alpha,
    validate_confidence_ramp)
from pbp_drake.core.pose_arbitration import PoseReference, blend_pose, validate_pose_mode
from pbp_drake.systems.layouts import OperatorTwist, PoseState, goal_index


class PoseBlender(LeafSystem):
    """Mixes the operator's twist into the policy's pose reference by one blending law.

    .. pydrake_system::

        name: PoseBlender
        input_ports:
        - robot_state
        - policy_reference
        - operator_twist
        - operator_active
        - selected_goal (optional)
        - goal_probabilities (optional)
        output_ports:
        - reference

    `robot_state` is the hand's `PoseState` sampled at the tick; `policy_reference` a
    `PoseState` (pose after one period and twist: `PoseDmpBank.selected_reference`);
    `operator_twist` an `OperatorTwist` `[vx, vy, vz, wx, wy, wz]` (world frame), refused
    with its NaN or infinite fields named. `reference` is a `PoseState`.

    Modes (`pbp_drake.core.pose_arbitration`): `pbp_continuous`, `pbp_alternated`,
    `fixed_alpha`, `confidence_alpha`, `teleop`, `pbp_no_user`; linear parts blend as the
    position `Blender`'s, angular velocities as world-frame vectors, orientations on SO(3)
    (turned by `Exp(w dt)`, mixed by slerp). `confidence_alpha` reads `goal_probabilities`
    (K) and `selected_goal` (goal 0 unconnected), as `Blender`; `fixed_alpha`'s weight is
    a Context parameter (`set_alpha`).
    """

    def __init__(self, mode, goal_count, control_period, alpha=None, *,
                 confidence_range=(DEFAULT_CONFIDENCE_LOW, DEFAULT_CONFIDENCE_HIGH),
                 alpha_max=DEFAULT_ALPHA_MAX):
        super().__init__()
        validate_pose_mode(mode, alpha)
        try:
            low, high = confidence_range
        except (TypeError, ValueError):
            raise ValueError(f"confidence_range must be a pair (confidence_low, "
                             f"confidence_high), got {confidence_range!r}") from None
        validate_confidence_ramp(low, high, alpha_max)
        self._mode, self._alpha = mode, alpha
        self._confidence_range = (float(low), float(high))
        self._alpha_max = float(alpha_max)
        self._goal_count = int(goal_count)
        self._period = float(control_period)
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", PoseState.size)
        self._policy_port = self.DeclareVectorInputPort("policy_reference", PoseState.size)
        self._twist_port = self.DeclareVectorInputPort("operator_twist", OperatorTwist.size)
        self._active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._probabilities_port = self.DeclareVectorInputPort("goal_probabilities",
                                                               self._goal_count)
        self._alpha_index = (self.DeclareNumericParameter(BasicVector([float(alpha)]))
                             if mode == "fixed_alpha" else None)
        # A function of the inputs (and alpha) alone: not redone between control ticks.
        self._reference_port = self.DeclareVectorOutputPort(
            "reference", PoseState.size, self._calc_reference,
            prerequisites_of_calc={self.all_input_ports_ticket(),
                                   self.all_parameters_ticket()})

    @property
    def mode(self):
        return self._mode

    def get_robot_state_input_port(self):
        return self._robot_state_port

    def get_policy_reference_input_port(self):
        return self._policy_port

    def get_operator_twist_input_port(self):
        return self._twist_port

    def get_operator_active_input_port(self):
        return self._active_port

    def get_selected_goal_input_port(self):
        return self._selected_goal_port

    def get_goal_probabilities_input_port(self):
        return self._probabilities_port

    def get_reference_output_port(self):
        return self._reference_port

    def alpha(self, context):
        """The weight used in `context`: the parameter (`fixed_alpha`), the confidence ramp
        (`confidence_alpha`), None for the other modes."""
        if self._alpha_index is not None:
            return float(context.get_numeric_parameter(self._alpha_index)[0])
        if self._mode != "confidence_alpha":
            return None
        if not self._probabilities_port.HasValue(context):
            raise RuntimeError("PoseBlender in confidence_alpha mode needs its "
                               "goal_probabilities input port connected")
        selected = goal_index(self._selected_goal_port, context, self._goal_count,
                              unconnected=0)
        return confidence_alpha(self._probabilities_port.Eval(context), selected,
                                *self._confidence_range, self._alpha_max)

    def set_alpha(self, context, alpha):
        """Sets `fixed_alpha`'s weight in `context`; ValueError outside [0, 1] or in another
        mode."""
        if self._alpha_index is None:
            raise ValueError(f"alpha is a weight of fixed_alpha; this blender is {self._mode}")
        validate_pose_mode(self._mode, alpha)
        context.get_mutable_numeric_parameter(self._alpha_index).SetAtIndex(0, float(alpha))

    def _calc_reference(self, context, output):
        alpha = self.alpha(context)
        robot = self._robot_state_port.Eval(context)
        orientation = quaternion.unit_quaternions(robot[3:7], "robot_state orientation")
        policy = PoseReference.from_vector(self._policy_port.Eval(context))
        reference = blend_pose(self._mode, robot[:3], orientation, policy,
                               self._twist_port.Eval(context),
                               self._active_port.Eval(context)[0] > 0.5, self._period, alpha)
        output.SetFromVector(reference.to_vector())
