"""HeadingCommand behind an operator sampled at the sense stage, as in the HSR diagram."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.systems.pbp.heading_command import HeadingCommand
from pbp_drake.systems.ports import OperatorCommand
from pbp_drake.systems.sample_hold import SampleHold
from pbp_drake.systems.tick import decide_offset

PERIOD = 0.1
INITIAL_HEADING = 0.3
YAW_RATE = 0.5
# The operator starts turning between two ticks: the tick at 1.0 s is the first to see it.
TURN_START = 0.95


def build(max_yaw_acceleration=None, max_turn=None):
    """A yaw rate that steps up at `TURN_START`, sampled at each tick like an operator."""
    builder = DiagramBuilder()
    commands = np.zeros((OperatorCommand.size, 2))
    OperatorCommand(commands[:, 1]).yaw_rate = YAW_RATE
    source = builder.AddSystem(TrajectorySource(
        PiecewisePolynomial.ZeroOrderHold([0.0, TURN_START, 100.0],
                                          np.column_stack([commands, commands[:, 1]]))))
    operator = builder.AddSystem(SampleHold(PERIOD, np.zeros(OperatorCommand.size)))
    builder.Connect(source.get_output_port(), operator.get_input_port())
    heading = builder.AddSystem(HeadingCommand(INITIAL_HEADING, PERIOD, max_yaw_acceleration,
                                               max_turn=max_turn))
    builder.Connect(operator.get_output_port(), heading.get_operator_command_input_port())
    return builder.Build(), heading


def heading_at(simulator, heading, time):
    simulator.AdvanceTo(time)
    context = heading.GetMyContextFromRoot(simulator.get_context())
    return heading.get_heading_output_port().Eval(context)[0]


def test_the_heading_starts_at_its_initial_value():
    diagram, heading = build()
    simulator = Simulator(diagram)
    simulator.Initialize()
    assert heading_at(simulator, heading, 0.0) == INITIAL_HEADING
    assert heading_at(simulator, heading, 0.95) == INITIAL_HEADING


def test_the_heading_turns_at_the_decide_stage_with_the_command_of_the_same_tick():
    diagram, heading = build()
    simulator = Simulator(diagram)
    # At the tick itself the operator has sampled the turn, the heading not yet.
    assert heading_at(simulator, heading, 1.0) == INITIAL_HEADING
    # Right after the decide stage of that tick the heading has moved by one period's turn.
    turned = heading_at(simulator, heading, 1.0 + 2 * decide_offset(PERIOD))
    assert turned == pytest.approx(INITIAL_HEADING + YAW_RATE * PERIOD, abs=1e-12)


def test_the_heading_integrates_the_yaw_rate_over_the_ticks():
    diagram, heading = build()
    simulator = Simulator(diagram)
    # Ticks 1.0, 1.1, ..., 2.0 s turn: 11 periods.
    assert heading_at(simulator, heading, 2.05) == pytest.approx(
        INITIAL_HEADING + 11 * YAW_RATE * PERIOD, abs=1e-12)


def test_with_an_acceleration_limit_the_turn_starts_as_a_ramp():
    diagram, heading = build(max_yaw_acceleration=1.0)
    simulator = Simulator(diagram)
    headings = [heading_at(simulator, heading, 0.95 + 0.1 * k) for k in range(12)]
    rates = np.diff(headings) / PERIOD
    # 0.1 rad/s more each tick until the operator's 0.5 rad/s, then steady.
    np.testing.assert_allclose(rates, [0.1, 0.2, 0.3, 0.4, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5],
                               atol=1e-12)


@pytest.mark.parametrize("limit", [0.0, -1.0, float("inf"), float("nan")])
def test_a_yaw_acceleration_limit_must_be_finite_and_positive(limit):
    with pytest.raises(ValueError, match="max_yaw_acceleration"):
        HeadingCommand(0.0, PERIOD, limit)


def test_with_a_bounded_turn_the_heading_stops_at_the_bound_and_turns_back_at_once():
    diagram, heading = build(max_turn=0.4)
    simulator = Simulator(diagram)
    # Turning at 0.5 rad/s from 1.0 s: at the bound 0.8 s later, and held there.
    assert INITIAL_HEADING < heading_at(simulator, heading, 1.5) < INITIAL_HEADING + 0.4
    assert heading_at(simulator, heading, 3.0) == pytest.approx(INITIAL_HEADING + 0.4)
    assert heading_at(simulator, heading, 9.0) == pytest.approx(INITIAL_HEADING + 0.4)
    # No turn is stored up beyond it: the rate was set to 0 at the bound.
    context = heading.GetMyContextFromRoot(simulator.get_context())
    assert context.get_discrete_state(1).get_value()[0] == 0.0


@pytest.mark.parametrize("turn", [0.0, -1.0, np.nan])
def test_a_bounded_turn_must_be_positive(turn):
    with pytest.raises(ValueError, match="max_turn"):
        HeadingCommand(0.0, PERIOD, max_turn=turn)
