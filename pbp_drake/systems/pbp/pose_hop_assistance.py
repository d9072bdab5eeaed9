"""HOP's assistance on the hand's pose as a Drake system (the grasping task)."""

from pbp_drake.core import quaternion
from pbp_drake.core.hindsight_optimization import assisted_command, hop_targets
from pbp_drake.core.pose_arbitration import PoseReference, turned
from pbp_drake.systems.pbp.hop_assistance import HopAssistanceBase
from pbp_drake.systems.ports import GoalPose, OperatorTwist, PoseState


class PoseHopAssistance(HopAssistanceBase):
    """The six-DoF command of ``hop`` or ``predict_then_assist`` (`HopAssistance` with the
    pose).

    .. pydrake_system::

        name: PoseHopAssistance
        input_ports:
        - robot_state
        - goal_poses
        - operator_twist
        - goal_probabilities
        output_ports:
        - reference

    `robot_state` is the hand's `PoseState` sampled at the tick, `goal_poses` the K
    `GoalPose` rows flattened, `operator_twist` an `OperatorTwist`, `goal_probabilities`
    the belief. `reference` is the `PoseState` of one control period, the hand moved by
    `v + a_v` and turned by `Exp((w + a_w) dt)`, for the `PoseHandOver`.
    """

    def __init__(self, method, goal_count, settings, control_period):
        super().__init__(method, goal_count, settings, control_period)
        k = self._goal_count
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", PoseState.size)
        self._goals_port = self.DeclareVectorInputPort("goal_poses", k * GoalPose.size)
        self._twist_port = self.DeclareVectorInputPort("operator_twist", OperatorTwist.size)
        self._probabilities_port = self.DeclareVectorInputPort("goal_probabilities", k)
        self._reference_port = self.DeclareVectorOutputPort(
            "reference", PoseState.size, self._calc_reference,
            prerequisites_of_calc={self.all_input_ports_ticket()})

    def _calc_reference(self, context, output):
        robot = self._robot_state_port.Eval(context)
        orientation = quaternion.unit_quaternions(robot[3:7], "robot_state orientation")
        poses = self._goals_port.Eval(context).reshape(self._goal_count, GoalPose.size)
        twist = self._twist_port.Eval(context)
        command = assisted_command(
            self._method, self._settings, hop_targets(poses[:, :3], poses[:, 3:]),
            self._probabilities_port.Eval(context), robot[:3], twist[:3], orientation,
            twist[3:])
        reference = PoseReference(
            robot[:3] + command.velocity * self._period,
            turned(orientation, command.angular_velocity, self._period),
            command.velocity, command.angular_velocity)
        output.SetFromVector(reference.to_vector())
