"""The cases timed: one bank of K DMPs in D dimensions, and the steps of it that the bench
times (the bank math alone, the bank inside its LeafSystem, and a LeafSystem with the same
ports and state whose update does nothing: Drake's own cost).

The LeafSystem is wired as the builder wires it: its `followed_goal` and `selected_goal`
connected, the compact state with shared weights (`DmpBank(compact_state=True)`, as every
scenario's bank) and the per-goal state with distinct ones, and a reader that evaluates its
`selected_reference` at every period, as the blender does: a step's time is its update
and that read. (A bank could otherwise look fast by leaving its work to an output no
timing reads.)"""

import dataclasses

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake_bench.table import microseconds
from pbp_drake_bench.timing import timed_span
from pbp_drake.core.dmp import DmpBankModel, DmpSettings, fit_weights, minimum_jerk
from pbp_drake.systems.pbp.dmp_bank import DmpBank as DmpBankSystem
from pbp_drake.systems.pbp.goals_source import GoalsSource
from pbp_drake.systems.tick import report_offset

BASIS = 50
DT = 0.001  # a 1 kHz control loop
# The LeafSystem checks time a whole movement and as long again after it: the phase goes
# from 1 to 0.01 at tau, then to 1e-4. A step's cost moves with the phase (how many weight
# rows matter), so the first moments alone could hide a slow phase of the machine.
MOTION_DURATIONS = 2.0


@dataclasses.dataclass
class Case:
    dimension: int
    goal_count: int
    start: np.ndarray  # (D,)
    goals: np.ndarray  # (K, D)
    robot: np.ndarray  # (D,) the robot's position every step re-integrates from
    weights: np.ndarray | None  # (K, N, D) distinct, or None
    shared_weights: np.ndarray  # (N, D) of one demonstration


def make_case(dimension, goal_count, distinct, seed=0):
    rng = np.random.default_rng(seed + 1000 * dimension + goal_count)
    start = np.zeros(dimension)
    goals = rng.uniform(0.5, 1.5, (goal_count, dimension))
    robot = rng.uniform(-0.05, 0.05, dimension)
    times, path = minimum_jerk(start, np.ones(dimension), 1.0)
    path = path + 0.2 * np.sin(np.pi * times / times[-1])[:, None] * np.arange(dimension)
    shared, _ = fit_weights(times, path, DmpSettings(basis_count=BASIS))
    weights = None
    if distinct:
        # Learned-looking weights, different for every goal (the bank does not care how).
        weights = shared[None] * rng.uniform(0.5, 1.5, (goal_count, 1, dimension))
    return Case(dimension, goal_count, start, goals, robot, weights, shared)


def make_bank(case):
    settings = DmpSettings(basis_count=BASIS)
    if case.weights is not None:
        return DmpBankModel(case.weights, case.start, 1.0, settings)
    return DmpBankModel(case.shared_weights, case.start, 1.0, settings, goal_count=case.goal_count)


def bank_math_step(bank, case):
    """One step of the bank from the robot's position, in place, goals validated each step."""
    phase, positions, scaled_velocity = bank.initial_state()
    robot = case.robot[:, None]
    goals = case.goals.reshape(-1)
    workspace = bank.make_workspace()

    def step():
        bank.advance_into(phase, robot, scaled_velocity, bank.goals_matrix(goals), DT,
                          phase, positions, scaled_velocity, workspace)
    return step


class NullBank(LeafSystem):
    """A LeafSystem with the DmpBankModel system's ports and state (compact or per goal)
    and an update that does nothing: Drake's own cost of one periodic discrete update (and
    of the read)."""

    def __init__(self, goal_count, dimension, compact):
        super().__init__()
        k, d = goal_count, dimension
        self.DeclareVectorInputPort("robot_state", 2 * d)
        self.DeclareVectorInputPort("goals", k * d)
        self.DeclareVectorInputPort("operator_active", 1)
        self.DeclareVectorInputPort("followed_goal", 1)
        self.DeclareVectorInputPort("selected_goal", 1)
        size = DmpBankSystem.state_size(k, d, compact_state=compact)
        self.DeclareDiscreteState(np.zeros(size))
        self.DeclareVectorOutputPort("selected_reference", 2 * d, self._calc_reference,
                                     prerequisites_of_calc={self.xd_ticket()})
        self.DeclarePeriodicDiscreteUpdateEvent(DT, 0.0, self._update)

    def _update(self, context, discrete_state):
        pass

    def _calc_reference(self, context, output):
        pass


class ReferenceReader(LeafSystem):
    """Evaluates its input once a period, after the bank's update (at the report stage of
    `pbp_drake.systems.tick`, as the hand-over reads the blender): a consumer's read."""

    def __init__(self, size, period=DT):
        super().__init__()
        self._port = self.DeclareVectorInputPort("reference", size)
        self.DeclarePeriodicPublishEvent(period, report_offset(period), self._read)

    def _read(self, context):
        self._port.EvalAbstract(context)


def connect_reader(builder, port, period=DT):
    """A `ReferenceReader` of `port` in `builder`, reading every `period`."""
    reader = builder.AddSystem(ReferenceReader(port.size(), period))
    builder.Connect(port, reader.get_input_port())


def leaf_simulator(case, bank=None, read="selected_reference"):
    """A Simulator of the bank's LeafSystem (or the null one) fed by constant sources, its
    followed and selected goal 0 and its output `read` read every period (`references`,
    all K, for the report: the null system has none)."""
    builder = DiagramBuilder()
    d = case.dimension
    # The compact state, as the builder's, for shared weights (they come with one start,
    # `make_bank`, so the DMPs are affine in the goal); distinct ones keep the per-goal one.
    compact = case.weights is None
    if bank is None:
        system = builder.AddSystem(NullBank(case.goal_count, d, compact))
    else:
        system = builder.AddSystem(DmpBankSystem(bank, DT, compact_state=compact))
    robot = builder.AddSystem(ConstantVectorSource(np.concatenate([case.robot, np.zeros(d)])))
    # Our goals source, as the builder uses: Drake's ConstantVectorSource would make the
    # bank re-read its goals at every update.
    goals = builder.AddSystem(GoalsSource(case.goals))
    goal = builder.AddSystem(ConstantVectorSource([0.0]))
    builder.Connect(robot.get_output_port(), system.GetInputPort("robot_state"))
    builder.Connect(goals.get_output_port(), system.GetInputPort("goals"))
    for name in ("followed_goal", "selected_goal"):
        builder.Connect(goal.get_output_port(), system.GetInputPort(name))
    connect_reader(builder, system.GetOutputPort(read))
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    return simulator


def leaf_step(simulator, steps):
    """Advances `steps` control periods; the timed unit is one period."""
    def step():
        context = simulator.get_context()
        simulator.AdvanceTo(context.get_time() + steps * DT)
    return step


def motion_timing(simulator, duration, periods):
    """Seconds per period of a fresh Simulator run over a whole movement of `duration` and as
    long after it (`MOTION_DURATIONS`), in timed calls of `periods` periods: the median, and
    the slowest eighth's median (a quarter of `duration`)."""
    end = MOTION_DURATIONS * duration - 0.5 * DT
    median, slowest, _ = timed_span(leaf_step(simulator, periods),
                                    lambda: simulator.get_context().get_time() >= end)
    return median / periods, slowest / periods


def motion_fields(simulator, duration, periods):
    """A row's `leaf_motion_us` and `leaf_slowest_us` (`motion_timing`, microseconds)."""
    median, slowest = motion_timing(simulator, duration, periods)
    return {"leaf_motion_us": microseconds(median), "leaf_slowest_us": microseconds(slowest)}
