"""The grasping task's virtual participant as a Drake system."""

import numpy as np

from pbp_drake.core.participant_grasp import GraspParticipant, ParticipantMemory
from pbp_drake.core.participant_impairment import delay_ticks
from pbp_drake.core.participant_serving import ServingMemory
from pbp_drake.systems.operators.virtual_operator import ParticipantOperator
from pbp_drake.systems.ports import OperatorTwist, PoseState, Target


class PoseVirtualOperator(ParticipantOperator):
    """Stands in for a person in the grasping task: a thin wrapper of
    `pbp_drake.core.participant_grasp.GraspParticipant.step`.

    .. pydrake_system::

        name: PoseVirtualOperator
        input_ports:
        - hand_pose
        - target
        - selected_goal
        - forward_key
        output_ports:
        - operator_command
        - operator_active

    `hand_pose` is the hand's `PoseState`, `target` the task monitor's `Target`;
    `selected_goal` and `forward_key` are as `VirtualOperator`'s. `operator_command` is an
    `OperatorTwist`, world frame. Its memory (`ParticipantMemory`), motor noise and command
    delay (`impairment`) are discrete state.
    """

    def __init__(self, participant, control_period):
        if not isinstance(participant, GraspParticipant):
            raise ValueError("participant must be a GraspParticipant (GraspParticipant.create)")
        super().__init__(OperatorTwist.size, control_period)
        self._participant = participant
        self._hand_port = self.DeclareVectorInputPort("hand_pose", PoseState.size)
        self._target_port = self.DeclareVectorInputPort("target", Target.size)
        self._selected_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._forward_key_port = self.DeclareVectorInputPort("forward_key", 1)
        self._memory_index = self.DeclareDiscreteState(np.array(ParticipantMemory(),
                                                                dtype=float))
        impairment = participant.params.impairment
        self._declare_participant(impairment, participant.seed, participant.motor_noise_scales)
        self._declare_operator_outputs(delay_ticks(impairment.command_delay, control_period))

    @property
    def participant(self):
        return self._participant

    def _update(self, context, discrete_state):
        memory = ParticipantMemory.from_array(
            context.get_discrete_state(self._memory_index).value())
        hand = np.asarray(self._hand_port.Eval(context), float)
        time = context.get_time()
        participant = self._participant
        velocity = hand[7:10]
        own_motion = self._sense_own_motion(context, discrete_state, participant.params,
                                            velocity)
        serving = ServingMemory.from_vector(
            context.get_discrete_state(self._serving_index).value())
        tick = int(round(time / self._period))
        noise = self._next_noise(context, discrete_state, tick)
        twist, active, memory, serving = participant.step(
            memory, serving, time, tick, hand[:3], hand[3:7] / np.linalg.norm(hand[3:7]),
            velocity, own_motion, int(Target(self._target_port.Eval(context)).index),
            int(round(self._selected_port.Eval(context)[0])),
            self._forward_key_port.Eval(context)[0] > 0.5, self._period, noise)
        discrete_state.set_value(self._serving_index, serving.as_vector())
        discrete_state.get_mutable_vector(self._memory_index).set_value(
            np.array(memory, dtype=float))
        self._store_sample(discrete_state, twist, active)
