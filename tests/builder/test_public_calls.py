"""The builder's public calls refuse what they cannot build or read, in words: an
operator config of the other kind of scene, a log read past its last sample, a scenario
run by the call of the other kind of run."""

import dataclasses

import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

from pbp_drake.builder import make_hsr_operator, make_operator, read_log, run_task, simulate
from pbp_drake.scenarios import ObstacleRepulsion, VirtualParticipant, load_scenario_file


def test_an_operator_of_the_other_kind_of_scene_is_refused_by_name(repo):
    toy = load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").scenario
    with pytest.raises(TypeError, match="unknown operator config VirtualParticipant"):
        make_operator(dataclasses.replace(toy, operator=VirtualParticipant()), 2)
    reach = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").resolved
    other = dataclasses.replace(reach, scenario=dataclasses.replace(
        reach.scenario, operator=ObstacleRepulsion()))
    with pytest.raises(TypeError, match="unknown operator config ObstacleRepulsion"):
        make_hsr_operator(other, None)


def test_a_log_read_past_its_samples_says_how_many_it_has():
    builder = DiagramBuilder()
    source = builder.AddSystem(ConstantVectorSource([1.0, 2.0]))
    logger = LogVectorOutput(source.get_output_port(), builder, publish_period=0.1)
    logger.set_name("log")
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(0.25)  # samples at 0, 0.1 and 0.2
    context = simulator.get_context()
    times, samples = read_log(diagram, context, "log", 2, shift=1)
    assert times.tolist() == pytest.approx([0.0, 0.1])
    assert samples.tolist() == [[1.0, 2.0], [1.0, 2.0]]
    with pytest.raises(ValueError, match="log has 3 samples; 4 are needed"):
        read_log(diagram, context, "log", 3, shift=1)
    assert read_log(diagram, context, "no_log", 3) == (None, None)


@pytest.mark.parametrize("rate", [-1.0, float("nan"), "fast"])
def test_a_realtime_rate_that_is_no_rate_is_refused_by_name(repo, rate):
    toy = load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").scenario
    with pytest.raises(ValueError, match=r"realtime_rate must be a number >= 0 \(0: as fast as "
                                         r"possible\), got "):
        simulate(toy, realtime_rate=rate)


def test_a_scenario_of_the_other_kind_of_run_says_which_call_runs_it(repo):
    """`run_task` of a 2-D scene ended in Drake's `does not have a subsystem named
    ee_state_log`, `simulate` of a robot task in an AttributeError of None."""
    toy = load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml").resolved
    with pytest.raises(ValueError, match=r"scenario 'toy_alt_vs_cont' is a 2-D scene "
                                         r"\(PointScenario\): run it with simulate\(scenario\)"):
        run_task(toy)
    reach = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    with pytest.raises(ValueError, match=r"is a robot task \(TaskScenario\): run it with "
                                         r"run_task\(scenario\)"):
        simulate(reach)
