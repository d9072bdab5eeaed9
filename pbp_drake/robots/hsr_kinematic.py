"""Kinematic robots (the stations' ``motion: kinematic``): joints where the diff IK's plan
is at every instant. No plant is stepped: the MultibodyPlant, outside the Diagram, gives
the kinematics and the geometry (docs/tasks/hsr-station.md, "A kinematic robot")."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.ports import PortGetters


class KinematicJoints(PortGetters, LeafSystem):
    """The plant's state, read off the diff IK's ``desired_state`` with no dynamics.

    .. pydrake_system::

        name: KinematicJoints
        input_ports:
        - desired_state
        output_ports:
        - state

    ``desired_state`` is ``[q_d, v_d]`` of ``motor_joints`` (in that order; the diff IK's
    plan at this instant); ``state`` is ``plant``'s ``[q, v]`` with every motor there and
    each coupled joint where its coupler keeps it (``couplers``: ``(follower, leader,
    ratio)`` joints, such as the HSR's torso). No state of its own.
    """

    def __init__(self, plant, motor_joints, couplers=()):
        super().__init__()
        self._plant = plant
        nq = plant.num_positions()
        # Where the motors' [q_d, v_d] go in [q, v], and the couplers' entries.
        self._scatter = np.array([joint.position_start() for joint in motor_joints]
                                 + [nq + joint.velocity_start() for joint in motor_joints])
        self._couplers = [([follower.position_start(), nq + follower.velocity_start()],
                           [leader.position_start(), nq + leader.velocity_start()], ratio)
                          for follower, leader, ratio in couplers]
        self._desired_port = self.DeclareVectorInputPort("desired_state",
                                                         2 * len(motor_joints))
        self.DeclareVectorOutputPort(
            "state", plant.num_multibody_states(), self._calc_state)

    def plant(self):
        """The MultibodyPlant (outside any Diagram) whose state this system outputs."""
        return self._plant

    def _calc_state(self, context, output):
        state = np.zeros(output.size())
        state[self._scatter] = self._desired_port.Eval(context)
        for follower, leader, ratio in self._couplers:
            state[follower] = ratio * state[leader]
        output.SetFromVector(state)

