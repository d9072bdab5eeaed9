"""Six-DoF blending as a Drake system: the operator's twist and the pose DMP's reference
become one pose reference (`pbp_drake.core.pose_arbitration`)."""

from pbp_drake.core import quaternion
from pbp_drake.core.arbitration import (
    DEFAULT_ALPHA_MAX, DEFAULT_CONFIDENCE_HIGH, DEFAULT_CONFIDENCE_LOW)
from pbp_drake.core.pose_arbitration import POSE_BLEND_LAWS, PoseReference, blend_pose
from pbp_drake.systems.pbp.blender import BlenderBase
from pbp_drake.systems.ports import OperatorTwist, PoseState


class PoseBlender(BlenderBase):
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
    `PoseState` (`PoseDmpBank.selected_reference`); `operator_twist` an `OperatorTwist`
    (world frame; NaN or infinite fields refused by name). `reference` is a `PoseState`.
    The modes are `pbp_drake.core.pose_arbitration.POSE_BLEND_MODES`; `confidence_alpha`
    and `fixed_alpha` are as in `Blender`.
    """

    _laws = POSE_BLEND_LAWS
    _estimator_name = "PoseGoalEstimator"

    def __init__(self, mode, goal_count, control_period, alpha=None, *,
                 confidence_range=(DEFAULT_CONFIDENCE_LOW, DEFAULT_CONFIDENCE_HIGH),
                 alpha_max=DEFAULT_ALPHA_MAX):
        super().__init__(mode, goal_count, control_period, alpha, confidence_range, alpha_max)
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", PoseState.size)
        self._policy_port = self.DeclareVectorInputPort("policy_reference", PoseState.size)
        self._twist_port = self.DeclareVectorInputPort("operator_twist", OperatorTwist.size)
        self._active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._goal_probabilities_port = self.DeclareVectorInputPort("goal_probabilities",
                                                                    self._goal_count)
        # A function of the inputs (and alpha) alone: not redone between control ticks.
        self._reference_port = self.DeclareVectorOutputPort(
            "reference", PoseState.size, self._calc_reference,
            prerequisites_of_calc={self.all_input_ports_ticket(),
                                   self.all_parameters_ticket()})

    def _calc_reference(self, context, output):
        alpha = self.alpha(context)
        robot = self._robot_state_port.Eval(context)
        orientation = quaternion.unit_quaternions(robot[3:7], "robot_state orientation")
        policy = PoseReference.from_vector(self._policy_port.Eval(context))
        reference = blend_pose(self._mode, robot[:3], orientation, policy,
                               self._twist_port.Eval(context),
                               self._active_port.Eval(context)[0] > 0.5, self._period, alpha)
        output.SetFromVector(reference.to_vector())
