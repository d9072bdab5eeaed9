"""The hand-over: goal switches, presses and releases keep the command's velocity
continuous, in every blending mode, and PBP still does not stall behind a lagging robot."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput, ZeroOrderHold

from pbp_drake.core.arbitration import BLEND_MODES
from pbp_drake.core.dmp import DmpBankModel as DmpModel
from pbp_drake.core.hand_over import hand_over
from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.core.hindsight_optimization import HopSettings
from pbp_drake.core.intent_filter import IntentFilterSettings
from pbp_drake.systems import (
    Blender, DemonstrationPlayer, DmpBank, GoalEstimator, GoalsSource, HandOver, HeadingCommand,
    HopAssistance, IdleOperator, IntentFilterGoalEstimator, LikelyGoals, MaxEntGoalEstimator,
    ObstacleRepulsionOperator, PointRobotDynamics, SampleHold, ScriptedOperator, TaskMonitor)
from pbp_drake.systems.operators.obstacle_repulsion_operator import ObstacleRepulsionParams
from pbp_drake.systems.tasks.point_robot_dynamics import PointRobotParams
from pbp_drake.systems.tick import decide_offset

GOALS = np.array([[2.0, 1.0], [2.0, -1.0]])


def test_the_law_bounds_the_change_of_velocity_and_the_speed():
    rng = np.random.default_rng(1)
    velocity = np.zeros(3)
    for _ in range(500):
        reference_position, reference_velocity = rng.normal(size=(2, 3))
        position, new_velocity = hand_over(velocity, reference_position, reference_velocity,
                                           2.0, 0.5, 0.03)
        assert np.linalg.norm(new_velocity - velocity) <= 2.0 * 0.03 + 1e-12
        assert np.linalg.norm(new_velocity) <= 0.5 + 1e-12
        # The position is the reference's, shifted by the velocity not yet reached.
        np.testing.assert_allclose(
            position, reference_position + (new_velocity - reference_velocity) * 0.03)
        velocity = new_velocity


def test_the_law_passes_steady_motion_through_unchanged():
    position, velocity = hand_over([0.1, 0.0], [1.0, 2.0], [0.11, 0.01], 1.0, 0.25, 0.03)
    np.testing.assert_array_equal(position, [1.0, 2.0])
    np.testing.assert_array_equal(velocity, [0.11, 0.01])


@pytest.mark.parametrize("limits", [(0.0, 1.0), (-1.0, 1.0), (1.0, float("inf")),
                                    (float("nan"), 1.0), (True, 1.0)])
def test_hand_over_refuses_limits_that_are_not_finite_positive_numbers(limits):
    with pytest.raises(ValueError, match="max_acceleration|max_speed"):
        HandOver(np.zeros(2), *limits, 0.03)


@pytest.mark.parametrize("build, message", [
    (lambda: HandOver([0.0, np.nan], 1.0, 0.5, 0.03), "initial_position must be finite"),
    (lambda: GoalsSource(np.zeros(2)),
     r"goals must be a non-empty \(K, D\) array, got shape \(2,\)"),
    (lambda: ScriptedOperator([0.0, 1.0], [0.1], 0.03),
     "commands: 1 for 2 times; expected one command per time"),
    (lambda: ScriptedOperator([0.0], [[np.nan, 0.0]], 0.03),
     "commands contain NaN or infinite values"),
    (lambda: ScriptedOperator([0.0, 0.0], [[0.1, 0.0], [0.0, 0.1]], 0.03),
     r"times \[0.0, 0.0\] do not increase; expected finite times \(s\) that increase "
     "strictly"),
    (lambda: DmpBank(DmpModel.straight([0.0, 0.0], 2, 1.0), 0.03, prediction_steps=5,
                     predicted_goal_count=3),
     r"predicted_goal_count must be in \[1, 2\] \(the goal count\), got 3"),
])
def test_the_loops_systems_refuse_what_they_cannot_run(build, message):
    with pytest.raises(ValueError, match=message):
        build()


_PERIOD_USERS = {
    "Blender": lambda period: Blender("pbp_continuous", 2, 2, period),
    "DmpBank": lambda period: DmpBank(DmpModel.straight([0.0, 0.0], 2, 1.0), period),
    "ScriptedOperator": lambda period: ScriptedOperator([0.0], [[0.0, 0.0]], period),
    "IdleOperator": lambda period: IdleOperator(2, period),
    "HeadingCommand": lambda period: HeadingCommand(0.0, period),
    "DemonstrationPlayer": lambda period: DemonstrationPlayer(
        [0.0, 0.5, 1.0], [[0.0], [0.5], [1.0]], period),
    "TaskMonitor": lambda period: TaskMonitor([[0.5, 0.0, 0.4]], [0], [0.0], [0.0, 0.0, 0.0],
                                              0.05, period),
    "SampleHold": lambda period: SampleHold(period, [0.0, 0.0]),
}


@pytest.mark.parametrize("period", [0.0, -0.03, np.nan, np.inf, "0.03s", None])
@pytest.mark.parametrize("system", sorted(_PERIOD_USERS))
def test_every_system_names_a_control_period_that_is_not_positive(system, period):
    name = "period" if system == "SampleHold" else "control_period"
    with pytest.raises(ValueError, match=f"^{name} must be positive, got "):
        _PERIOD_USERS[system](period)


@pytest.mark.parametrize("build, message", [
    (lambda: Blender("pbp_continuous", 2, -1, 0.03), "goal_count must be an integer >= 1"),
    (lambda: Blender("pbp_continuous", 2, 1.5, 0.03), "goal_count must be an integer >= 1"),
    (lambda: Blender("pbp_continuous", 0, 2, 0.03), "dimension must be an integer >= 1"),
    (lambda: Blender("pbp_continuous", None, 2, 0.03), "dimension must be an integer >= 1"),
    (lambda: HopAssistance("hop", -1, HopSettings(), 0.03),
     "goal_count must be an integer >= 1"),
    (lambda: GoalEstimator(np.inf, GoalEstimatorSettings(), 0.03),
     "goal_count must be an integer >= 1, got inf"),
    (lambda: GoalEstimator(None, GoalEstimatorSettings(), 0.03),
     "goal_count must be an integer >= 1, got None"),
    (lambda: LikelyGoals(3, 1.5), "count must be an integer >= 1, got 1.5"),
    (lambda: IdleOperator(-1, 0.03), "dimension must be an integer >= 1, got -1"),
])
def test_the_systems_name_a_count_that_is_no_whole_number(build, message):
    with pytest.raises(ValueError, match=message):
        build()


@pytest.mark.parametrize("options, message", [
    ({"max_speed": 0.0}, r"max_speed must be positive \(None: no limit\), got 0.0"),
    ({"max_speed": -1.0}, r"max_speed must be positive \(None: no limit\), got -1.0"),
    ({"max_speed": np.nan}, r"max_speed must be positive \(None: no limit\), got nan"),
    ({"prediction_steps": -1}, r"prediction_steps must be a whole number >= 0, got -1"),
    ({"prediction_steps": 1.5}, r"prediction_steps must be a whole number >= 0, got 1.5"),
    ({"prediction_steps": None}, r"prediction_steps must be a whole number >= 0, got None"),
    ({"prediction_steps": 3, "prediction_period": -0.1},
     r"prediction_period must be positive, got -0.1"),
    ({"prediction_steps": 3, "prediction_period": np.nan},
     r"prediction_period must be positive, got nan"),
    ({"prediction_steps": 3, "predicted_goal_count": np.nan},
     r"predicted_goal_count must be in \[1, 2\] \(the goal count\), got nan"),
    ({"prediction_steps": 3, "predicted_goal_count": 1.5},
     r"predicted_goal_count must be in \[1, 2\] \(the goal count\), got 1.5"),
])
def test_the_bank_names_an_option_it_cannot_run(options, message):
    with pytest.raises(ValueError, match=message):
        DmpBank(DmpModel.straight([0.0, 0.0], 2, 1.0), 0.03, **options)


@pytest.mark.parametrize("bank", [None, "bank", np.zeros((50, 2))])
def test_the_bank_names_a_bank_that_is_no_dmp_bank_model(bank):
    with pytest.raises(ValueError, match="^bank must be a DmpBankModel, got "):
        DmpBank(bank, 0.03)


def test_an_unbounded_anti_windup_is_no_limit():
    DmpBank(DmpModel.straight([0.0, 0.0], 2, 1.0), 0.03, max_speed=np.inf)


@pytest.mark.parametrize("build, message", [
    (lambda: HandOver([], 1.0, 0.5, 0.03), r"initial_position must be finite, got \[\]"),
    (lambda: HeadingCommand(np.nan, 0.03), "initial_heading must be a finite angle"),
    (lambda: HeadingCommand(None, 0.03), "initial_heading must be a finite angle .*, got None"),
    (lambda: Blender("fixed_alpha", 2, 2, 0.03, alpha="half"),
     "alpha must lie in \\[0, 1\\] for fixed_alpha, got half"),
    (lambda: PointRobotDynamics([np.nan, 0.0]), "initial_position must be a non-empty finite"),
    (lambda: PointRobotDynamics([]), "initial_position must be a non-empty finite"),
    (lambda: PointRobotDynamics([0.0, 0.0], None), "params must be PointRobotParams"),
    (lambda: SampleHold(0.03, []), r"initial_value must be a non-empty vector, got \[\]"),
    (lambda: SampleHold(0.03, [[0.0, 1.0]]), "initial_value must be a non-empty vector"),
    (lambda: ObstacleRepulsionOperator([[np.nan, 0.0]], [0.1], 2, 0.03),
     r"centres must be finite, got \[\[nan, 0.0\]\]"),
    (lambda: ObstacleRepulsionOperator([[0.5, 0.0]], [-0.1], 2, 0.03),
     r"radii must be one positive radius per centre \(1\), got \[-0.1\]"),
    (lambda: ObstacleRepulsionOperator([[0.5, 0.0]], [], 2, 0.03), "radii must be one positive"),
    # Two 3-D centres were read as three 2-D ones.
    (lambda: ObstacleRepulsionOperator([[0.5, 0.0, 0.0], [1.0, 0.0, 0.0]], [0.1] * 3, 2, 0.03),
     r"centres must be \(M, 2\), an obstacle's centre a row, got shape \(2, 3\)"),
    (lambda: ObstacleRepulsionOperator([[0.5, 0.0]], [0.1], 2, 0.03,
                                       ObstacleRepulsionParams(distance_threshold=np.nan)),
     "params.distance_threshold must be finite and positive, got nan"),
    (lambda: ObstacleRepulsionOperator([[0.5, 0.0]], [0.1], 2, 0.03,
                                       ObstacleRepulsionParams(speed=np.inf)),
     "params.speed must be finite and not negative, got inf"),
    (lambda: ObstacleRepulsionOperator([[0.5, 0.0]], [0.1], 2, 0.03,
                                       ObstacleRepulsionParams(axis=[1.0, 0.0, 0.0])),
     r"params.axis must be empty \(radially\) or a direction of dimension 2"),
    (lambda: ObstacleRepulsionOperator([[0.5, 0.0]], [0.1], 2, 0.03, {"speed": 1.0}),
     "params must be ObstacleRepulsionParams, got dict"),
    # 0 was taken for the default, the control period.
    (lambda: DmpBank(DmpModel.straight([0.0, 0.0], 2, 1.0), 0.03, prediction_steps=3,
                     prediction_period=0), "prediction_period must be positive, got 0"),
    (lambda: IntentFilterGoalEstimator(2, IntentFilterSettings(), 0.03, margin=None),
     "margin must lie in \\[0, 1\\), got None"),
    (lambda: MaxEntGoalEstimator(2, HopSettings(), 0.03, hold_steps=None),
     "hold_steps must be an integer >= 1, got None"),
])
def test_a_constructor_names_an_argument_it_cannot_use(build, message):
    with pytest.raises(ValueError, match=message):
        build()


def test_a_script_of_single_numbers_is_a_one_dimensional_operator():
    person = ScriptedOperator([0.0, 1.0], [0.1, -0.2], 0.03)
    assert person.get_operator_command_output_port().size() == 1


def test_a_selected_goal_that_is_no_goal_is_refused_by_the_bank():
    bank = DmpBank(DmpModel.straight([0.0, 0.0], 2, 1.0), 0.03)
    context = bank.CreateDefaultContext()
    bank.get_selected_goal_input_port().FixValue(context, [2.0])
    with pytest.raises(ValueError, match="selected_goal 2 is not one of the 2 goals"):
        bank.get_selected_reference_output_port().Eval(context)


@pytest.mark.parametrize("selected", [np.nan, 0.5, np.inf])
def test_a_selected_goal_that_is_no_whole_index_is_refused_by_the_blender(selected):
    blender = Blender("pbp_continuous", 2, 2, 0.03)
    context = blender.CreateDefaultContext()
    for port, value in [("robot_state", np.zeros(4)), ("references", np.zeros(8)),
                        ("selected_goal", [selected]), ("operator_command", np.zeros(2)),
                        ("operator_active", [0.0])]:
        blender.GetInputPort(port).FixValue(context, value)
    with pytest.raises(ValueError, match=f"selected_goal {selected:g} is not one of the 2 goals"):
        blender.get_command_output_port().Eval(context)


def test_a_nan_robot_state_is_refused_by_the_bank_naming_the_entry():
    bank = DmpBank(DmpModel.straight([0.0, 0.0], 2, 1.0), 0.03)
    simulator = Simulator(bank)
    context = bank.GetMyContextFromRoot(simulator.get_mutable_context())
    bank.get_robot_state_input_port().FixValue(context, [0.0, 0.0, np.nan, 0.0])
    bank.get_goals_input_port().FixValue(context, GOALS.reshape(-1))
    with pytest.raises(ValueError, match=r"robot_state velocity\[0\] is NaN or infinite"):
        simulator.AdvanceTo(0.03)


def test_a_nan_robot_state_is_refused_by_the_repulsion_naming_the_entry():
    # NaN is no nearer than the threshold, nor farther: the push went up at full speed.
    person = ObstacleRepulsionOperator([[0.5, 0.0]], [0.1], 2, 0.03)
    simulator = Simulator(person)
    context = person.GetMyContextFromRoot(simulator.get_mutable_context())
    person.get_robot_state_input_port().FixValue(context, [np.nan, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"robot_state position\[0\] is NaN or infinite"):
        simulator.AdvanceTo(0.03)


class ScriptedSelection(LeafSystem):
    """The selected goal as a goal estimator publishes it: a state updated at the decide
    stage, so that the DMP bank (same stage) reads the goal followed until then."""

    def __init__(self, switch_time, period):
        super().__init__()
        self._switch_time = switch_time
        index = self.DeclareDiscreteState(np.zeros(1))
        self.DeclareStateOutputPort("selected_goal", index)
        self.DeclarePeriodicDiscreteUpdateEvent(period, decide_offset(period), self._update)

    def _update(self, context, state):
        state.set_value([1.0 if context.get_time() >= self._switch_time else 0.0])


def run_loop(mode, dt=0.03, continuous=True, operator=None, params=PointRobotParams(),
             duration=10.0, goals=GOALS, switch_time=3.0, limits=(1.0, 0.5), seconds=9.0):
    """A point robot under a DMP bank, the blender and (with `continuous`) the hand-over
    and the followed goal; the selection switches from goal 0 to 1 at `switch_time`.
    Returns the commands (T, 2 D) and the robot's states (T, 2 D) at the ticks."""
    dimension = goals.shape[1]
    builder = DiagramBuilder()
    robot = builder.AddSystem(PointRobotDynamics(np.zeros(dimension), params))
    sample = builder.AddSystem(ZeroOrderHold(dt, 2 * dimension))
    builder.Connect(robot.get_state_output_port(), sample.get_input_port())
    bank = builder.AddSystem(DmpBank(DmpModel.straight(np.zeros(dimension), len(goals),
                                                       duration), dt,
                                     lock_phase_when_operator_acts=mode == "pbp_alternated"))
    builder.Connect(builder.AddSystem(GoalsSource(goals)).get_output_port(),
                    bank.get_goals_input_port())
    builder.Connect(robot.get_state_output_port(), bank.get_robot_state_input_port())
    times, commands = operator if operator is not None else ([0.0], [[0.0] * dimension])
    person = builder.AddSystem(ScriptedOperator(times, commands, dt))
    selection = builder.AddSystem(ScriptedSelection(switch_time, dt))
    blender = builder.AddSystem(Blender(mode, dimension, len(goals), dt, alpha=0.5))
    builder.Connect(sample.get_output_port(), blender.get_robot_state_input_port())
    builder.Connect(bank.get_references_output_port(), blender.get_references_input_port())
    builder.Connect(selection.get_output_port(), blender.get_selected_goal_input_port())
    builder.Connect(person.get_operator_command_output_port(),
                    blender.get_operator_command_input_port())
    for port in (blender.get_operator_active_input_port(),
                 bank.get_operator_active_input_port()):
        builder.Connect(person.get_operator_active_output_port(), port)
    # confidence_alpha reads probabilities: one-hot on goal 0 gives alpha_max.
    builder.Connect(builder.AddSystem(ConstantVectorSource([1.0, 0.0])).get_output_port(),
                    blender.get_goal_probabilities_input_port())
    command = blender.get_command_output_port()
    if continuous:
        builder.Connect(selection.get_output_port(), bank.get_followed_goal_input_port())
        hand = builder.AddSystem(HandOver(np.zeros(dimension), *limits, dt))
        builder.Connect(command, hand.get_reference_input_port())
        command = hand.get_command_output_port()
    builder.Connect(command, robot.get_command_input_port())
    command_log = LogVectorOutput(command, builder, dt)
    state_log = LogVectorOutput(sample.get_output_port(), builder, dt)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(seconds)
    context = simulator.get_context()
    # A log sample at t_k holds the decisions of tick k - 1 (pbp_drake.systems.tick).
    return (command_log.FindLog(context).data().T[1:],
            state_log.FindLog(context).data().T[1:])


def largest_velocity_change(commands):
    dimension = commands.shape[1] // 2
    return np.linalg.norm(np.diff(commands[:, dimension:], axis=0), axis=1).max()


@pytest.mark.slow
def test_minimal_reproduction_the_switch_keeps_the_dmps_velocity():
    """Two straight DMPs to (2, 1) and (2, -1), tau 10 s, periods 0.03 s and 0.015 s, the
    robot on DMP 0 for 3 s, then DMP 1 selected: with a velocity of its own per DMP the
    command jumps by 0.42 m/s in one tick; stepped from the followed DMP's velocity, by
    0.036 m/s at 0.03 s and 0.018 m/s at 0.015 s (the numbers the hand-over and DMP pages
    quote)."""
    stiff = PointRobotParams(stiffness=4e4, damping=400.0)  # follows its command closely
    jumps = {}
    for dt in (0.03, 0.015):
        for continuous in (False, True):
            commands, _ = run_loop("pbp_alternated", dt, continuous, params=stiff,
                                   limits=(1e3, 1e3), seconds=4.0)
            jumps[dt, continuous] = largest_velocity_change(commands)
    assert jumps[0.03, False] == pytest.approx(0.42, abs=0.005)
    assert jumps[0.015, False] == pytest.approx(0.42, abs=0.005)
    # The DMPs step from the followed DMP's velocity: what is left is the other attractor's
    # pull over one period, which halves with the period (continuous in the limit).
    assert jumps[0.03, True] == pytest.approx(0.036, abs=0.0005)
    assert jumps[0.015, True] == pytest.approx(0.018, abs=0.0005)


@pytest.mark.slow
@pytest.mark.parametrize("mode", BLEND_MODES)
def test_switch_press_and_release_change_the_command_by_at_most_the_limit(mode):
    """A forced switch at 3 s, a press at 5 s (0.15 m/s sideways) and a release at 6 s."""
    operator = ([0.0, 5.0, 6.0], [[0.0, 0.0], [0.0, 0.15], [0.0, 0.0]])
    commands, _ = run_loop(mode, operator=operator)
    assert largest_velocity_change(commands) <= 1.0 * 0.03 + 1e-9
    assert np.linalg.norm(commands[:, 2:], axis=1).max() <= 0.5 + 1e-9
    # Without the hand-over the same script makes steps far over the limit.
    commands, _ = run_loop(mode, operator=operator, continuous=False)
    assert largest_velocity_change(commands) > 0.1


@pytest.mark.slow
def test_pbp_does_not_stall_behind_a_lagging_robot():
    """The re-integration trap (each step resetting the DMP to the robot's measured velocity
    stalls it behind a lagging tracker): a soft robot, no operator, a 1 m reach of 1 s at
    100 Hz is within 5 cm of its goal at 1.5 s."""
    soft = PointRobotParams(stiffness=100.0, damping=20.0)
    goals = np.array([[1.0, 0.0], [0.0, 1.0]])
    _, states = run_loop("pbp_continuous", dt=0.01, params=soft, duration=1.0, goals=goals,
                         switch_time=100.0, limits=(20.0, 5.0), seconds=1.52)
    assert np.linalg.norm(states[150, :2] - goals[0]) < 0.05
