"""SampleHold: starts at its initial value, samples at the ticks, holds in between."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.systems.sample_hold import SampleHold

PERIOD = 0.1
INITIAL = [5.0, -5.0]


def ramp(time):
    """The input: [t, 2 t]."""
    return np.array([time, 2.0 * time])


def build():
    builder = DiagramBuilder()
    source = builder.AddSystem(TrajectorySource(PiecewisePolynomial.FirstOrderHold(
        [0.0, 10.0], np.column_stack([ramp(0.0), ramp(10.0)]))))
    hold = builder.AddSystem(SampleHold(PERIOD, INITIAL))
    builder.Connect(source.get_output_port(), hold.get_input_port())
    return builder.Build(), hold


def output_at(simulator, hold, time):
    simulator.AdvanceTo(time)
    return hold.get_output_port().Eval(hold.GetMyContextFromRoot(simulator.get_context()))


def test_it_starts_at_its_initial_value_not_at_zero():
    diagram, hold = build()
    simulator = Simulator(diagram)
    simulator.Initialize()
    context = hold.GetMyContextFromRoot(simulator.get_context())
    np.testing.assert_array_equal(hold.get_output_port().Eval(context), INITIAL)
    # The first sample, of the input at 0 s, is taken as the simulation leaves 0 s.
    np.testing.assert_array_equal(output_at(simulator, hold, 0.0), ramp(0.0))


@pytest.mark.parametrize("time, sampled_at", [
    (0.01, 0.0), (0.09, 0.0), (0.1, 0.0), (0.11, 0.1), (0.19, 0.1), (0.55, 0.5)])
def test_it_holds_the_sample_of_the_last_tick_between_ticks(time, sampled_at):
    diagram, hold = build()
    simulator = Simulator(diagram)
    # At a tick itself the output still holds the previous sample (updates come first in
    # the next step); just after, the new one.
    np.testing.assert_allclose(output_at(simulator, hold, time), ramp(sampled_at), atol=1e-12)


def test_a_new_context_starts_again_from_the_initial_value():
    diagram, hold = build()
    simulator = Simulator(diagram)
    output_at(simulator, hold, 0.55)
    fresh = hold.GetMyContextFromRoot(diagram.CreateDefaultContext())
    np.testing.assert_array_equal(hold.get_output_port().Eval(fresh), INITIAL)
