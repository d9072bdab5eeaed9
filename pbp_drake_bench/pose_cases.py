"""The six-DoF cases timed: K goal poses, each a 3-D position DMP and a unit-quaternion
orientation DMP (`PoseDmpBank`), stepped by the bank math alone and inside the LeafSystem,
beside a LeafSystem with the same ports and state whose update does nothing.

The LeafSystem is wired as the grasp builder wires it: `followed_goal` connected (every DMP
continues from the followed DMP's velocities) and the compact state (16 numbers; the K
stepped DMPs a cache entry computed once per tick, `PoseDmpBank`), and its
`selected_reference` read at every period, as the pose blender reads it
(`pbp_drake_bench.cases.ReferenceReader`). The row also times it with the per-goal state
(`leaf_per_goal_us`: 12 K numbers, which Drake copies twice per update) and with
`followed_goal` unconnected (`leaf_own_us`: the per-goal state, each DMP keeps its own
velocities, and every update reads all K angular velocities back)."""

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake_bench.cases import (
    BASIS, DT, connect_reader, leaf_step, make_bank, make_case, motion_fields)
from pbp_drake_bench.checks import MOTION_ROWS
from pbp_drake_bench.table import microseconds
from pbp_drake_bench.timing import timed
from pbp_drake.core import quaternion
from pbp_drake.core.dmp import DmpSettings
from pbp_drake.core.dmp.orientation_bank import OrientationDmpBank
from pbp_drake.systems.pbp.goals_source import GoalsSource
from pbp_drake.systems.ports import GoalPose, PoseState
from pbp_drake.systems.pbp.pose_dmp_bank import PoseDmpBank


def make_pose_case(goal_count, distinct, seed=0):
    """(position case, orientation bank, goal poses (K, 7), hand state (13,))."""
    case = make_case(3, goal_count, distinct, seed)
    rng = np.random.default_rng(seed + 7 * goal_count)
    settings = DmpSettings(basis_count=BASIS)
    start = quaternion.exp_map(np.array([0.1, -0.2, 0.3]))
    orientations = OrientationDmpBank.straight(start, goal_count, 1.0, settings)
    if distinct:
        # Learned-looking weights, different for every goal (the bank does not care how).
        weights = (np.asarray(orientations._weights)[None]
                   * rng.uniform(0.5, 1.5, (goal_count, 1, 3)))
        orientations = OrientationDmpBank(weights, start, 1.0, settings)
    rows = rng.normal(size=(goal_count, 4))
    rows /= np.linalg.norm(rows, axis=1, keepdims=True)
    goals = np.hstack([case.goals, rows])
    hand = np.concatenate([case.robot, quaternion.exp_map(np.array([0.12, -0.18, 0.33])),
                           np.zeros(3), [0.05, -0.02, 0.1]])
    return case, orientations, goals, hand


def pose_math_step(positions, orientations, goals, hand):
    """One free step of both NumPy banks from the hand's pose, in place (`advance_into`,
    orientations read back for every DMP), goals validated each step as the position case."""
    phase, stepped, velocity = positions.initial_state()
    rotation_phase, rotations, eta = orientations.initial_state()
    position_workspace = positions.make_workspace()
    orientation_workspace = orientations.make_workspace()
    robot, measured = hand[:3, np.newaxis], hand[3:7, np.newaxis]
    goal_positions, goal_rows = goals[:, :3].reshape(-1), goals[:, 3:]

    def step():
        positions.advance_into(phase, robot, velocity, positions.goals_matrix(goal_positions),
                               DT, phase, stepped, velocity, position_workspace)
        orientations.advance_into(rotation_phase, measured, eta,
                                  orientations.goals_matrix(goal_rows), DT, rotation_phase,
                                  rotations, eta, orientation_workspace)
    return step


class NullPoseBank(LeafSystem):
    """The PoseDmpBank's ports and state (compact or per goal), an update that does
    nothing: Drake's own cost (and the read's)."""

    def __init__(self, goal_count, compact):
        super().__init__()
        self.DeclareVectorInputPort("robot_state", PoseState.size)
        self.DeclareVectorInputPort("goal_poses", goal_count * GoalPose.size)
        self.DeclareVectorInputPort("followed_goal", 1)
        self.DeclareDiscreteState(np.zeros(PoseDmpBank.state_size(goal_count, compact)))
        self.DeclareVectorOutputPort("selected_reference", PoseState.size,
                                     self._calc_reference,
                                     prerequisites_of_calc={self.xd_ticket()})
        self.DeclarePeriodicDiscreteUpdateEvent(DT, 0.0, self._update)

    def _update(self, context, discrete_state):
        pass

    def _calc_reference(self, context, output):
        pass


def pose_leaf_simulator(goal_count, goals, hand, banks=None, followed=True, compact=True):
    """A Simulator of the PoseDmpBank (or the null system) fed by constant sources, in the
    compact state or per goal (which `followed=False` needs)."""
    builder = DiagramBuilder()
    if banks is None:
        system = builder.AddSystem(NullPoseBank(goal_count, compact))
        followed_port = system.get_input_port(2)
    else:
        system = builder.AddSystem(PoseDmpBank(*banks, DT, compact_state=compact))
        followed_port = system.get_followed_goal_input_port()
    state = builder.AddSystem(ConstantVectorSource(hand))
    source = builder.AddSystem(GoalsSource(goals))
    builder.Connect(state.get_output_port(), system.get_input_port(0))
    builder.Connect(source.get_output_port(), system.get_input_port(1))
    if followed:
        index = builder.AddSystem(ConstantVectorSource([0.0]))
        builder.Connect(index.get_output_port(), followed_port)
    connect_reader(builder, system.GetOutputPort("selected_reference"))
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    return simulator


def measure_pose_row(goal_count, distinct, min_time, bandwidth):
    """One row of the table for the six-DoF bank (`pose` True, `D` 6: 3 + 3)."""
    case, orientations, goals, hand = make_pose_case(goal_count, distinct)
    positions = make_bank(case)
    row = {"D": 6, "K": goal_count, "weights": "distinct" if distinct else "shared",
           "pose": True}
    median, minimum, repeats = timed(pose_math_step(positions, orientations, goals, hand),
                                     min_time)
    row.update(bank_math_us=microseconds(median), bank_math_min_us=microseconds(minimum),
               bank_math_repeats=repeats)
    periods = 10
    banks = (positions, orientations)
    for label, system_banks, followed, compact in [
            ("leaf", banks, True, True), ("leaf_per_goal", banks, True, False),
            ("leaf_own", banks, False, False), ("drake_overhead", None, True, True)]:
        simulator = pose_leaf_simulator(goal_count, goals, hand, system_banks, followed,
                                        compact)
        median, minimum, _ = timed(leaf_step(simulator, periods), min_time, warmup=1)
        row[f"{label}_us"] = microseconds(median / periods)
        row[f"{label}_min_us"] = microseconds(minimum / periods)
        del simulator
    if ((6, goal_count, row["weights"]), True) in MOTION_ROWS:
        row.update(motion_fields(pose_leaf_simulator(goal_count, goals, hand, banks),
                                 positions.duration, periods))
    weight_bytes = ((case.weights.nbytes if distinct else case.shared_weights.nbytes)
                    + np.asarray(orientations._weights).nbytes)
    row["weight_bytes"] = weight_bytes
    row["bandwidth_bound_us"] = microseconds(weight_bytes / (bandwidth["read_gb_per_s"] * 1e9))
    row["cache_bandwidth_bound_us"] = microseconds(
        weight_bytes / (bandwidth["cache_read_gb_per_s"] * 1e9))
    for key in ("pydmps_per_goal_us", "mp_per_goal_us", "mp_stacked_us",
                "speedup_vs_per_goal", "speedup_vs_stacked"):
        row[key] = None  # no peer library steps orientations on quaternions this way
    row["control_rate_hz"] = 1e6 / row["leaf_us"]
    return row
