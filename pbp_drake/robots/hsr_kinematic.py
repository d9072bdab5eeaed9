"""Kinematic robots (the stations' ``motion: kinematic``): joints where the diff IK's plan
is at every instant. No plant is stepped: the MultibodyPlant, outside the Diagram, gives
the kinematics and the geometry (docs/tasks/hsr-station.md, "A kinematic robot")."""

import numpy as np
from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import LeafSystem
from pydrake.systems.rendering import MultibodyPositionToGeometryPose

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


def add_kinematic_plant(builder, time_step):
    """A SceneGraph in `builder` and a MultibodyPlant registered with it but not added:
    `(plant, scene_graph)`, the plant to be filled and finalized by the caller."""
    scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
    plant = MultibodyPlant(time_step)
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    return plant, scene_graph


def add_kinematic_joints(builder, plant, scene_graph, motor_joints, desired_state,
                         couplers=()):
    """`KinematicJoints` fed by `desired_state`, placing the plant's geometry in
    `scene_graph`; returns it (its `state` is the robot's)."""
    joints = builder.AddNamedSystem("joints", KinematicJoints(plant, motor_joints, couplers))
    builder.Connect(desired_state, joints.get_desired_state_input_port())
    # Keeps a reference to the plant, which the Diagram does not own (pydrake keeps the
    # plant alive as long as this system).
    to_pose = builder.AddNamedSystem(
        "geometry_poses", MultibodyPositionToGeometryPose(plant, input_multibody_state=True))
    builder.Connect(joints.get_state_output_port(), to_pose.get_input_port())
    builder.Connect(to_pose.get_output_port(),
                    scene_graph.get_source_pose_port(plant.get_source_id()))
    return joints
