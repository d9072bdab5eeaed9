"""The surrogate pilots in scenario files: their tags and fields reach the systems, the
registry's names give the pilots with their defaults, and bad values are refused naming
the field, with did-you-mean, exit 2 and nothing written."""

import pytest
from pydrake.common.yaml import yaml_load_typed

from pbp_drake.builder import build_diagram
from pbp_drake.cli import main
from pbp_drake.core.surrogate_pilots import lag_per_tick
from pbp_drake.scenarios import (
    PILOT_NAMES, LaggyPilot, NoisyPilot, ParticipantPopulation, ProportionalPilot,
    ScenarioError, TaskScenario, load_scenario_file, resolve, with_pilot)

REACH = "diagrams/hsr_reach.yaml"


def with_operator(repo, tmp_path, operator):
    """diagrams/hsr_reach.yaml with `operator` (a YAML flow value) instead of its own."""
    text = (repo / REACH).read_text()
    start = text.index("  operator: !VirtualParticipant")
    end = text.index("  seed: 0")
    path = tmp_path / "pilot.yaml"
    path.write_text(text[:start] + f"  operator: {operator}\n" + text[end:])
    return path


@pytest.mark.parametrize("operator, message", [
    ("!NoisyPliot {}", "scenario.operator: the tag !NoisyPliot is unknown; expected one of "),
    ("!NoisyPilot {eps: 1.5}", "scenario.operator.eps 1.5 is no probability; expected a "
                               "number in [0, 1]"),
    ("!NoisyPilot {eps: -0.1}", "scenario.operator.eps -0.1 is no probability"),
    ("!LaggyPilot {p: 1.01}", "scenario.operator.p 1.01 is no probability"),
    ("!LaggyPilot {p: .nan}", "scenario.operator.p: NaN is not a number here"),
    ("!ParticipantPopulation {insist_time: [2.0, 1.0]}",
     "scenario.operator.insist_time [2.0, 1.0] is reversed; expected [low, high]"),
    ("!ParticipantPopulation {speed_factor: [.nan, 1.0]}",
     "scenario.operator.speed_factor[0]: NaN is not a number here"),
    ("!ParticipantPopulation {reaction_delay: [0.2]}",
     "scenario.operator.reaction_delay [0.2] needs two numbers"),
    ("!ProportionalPilot {gain: 0}", "scenario.operator.gain must be finite and positive"),
    ("!ProportionalPilot {max_speed: -0.1}",
     "scenario.operator.max_speed must be finite and not negative"),
    ("!NoisyPilot {participant: {slow_radius: -1}}",
     "scenario.operator.participant.slow_radius must be finite and positive"),
    ("!LaggyPilot {lag: 0.5}", "lag"),
])
def test_bad_pilot_values_are_refused_naming_the_field(repo, tmp_path, capsys, operator,
                                                       message):
    output = tmp_path / "out"
    code = main(["study", str(with_operator(repo, tmp_path, operator)), "--trials", "1",
                 "--methods", "teleop", "--output", str(output)])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not output.exists()


def test_an_unknown_tag_gets_a_did_you_mean(repo, tmp_path):
    with pytest.raises(ScenarioError, match=r"\(did you mean !LaggyPilot\?\)"):
        load_scenario_file(with_operator(repo, tmp_path, "!LagyPilot {}"))


def test_an_unknown_pilot_name_gets_a_did_you_mean(repo):
    scenario = load_scenario_file(repo / REACH).scenario
    with pytest.raises(ScenarioError, match=r"pilot 'lagy' is unknown; choose one of "
                                            r"attentive, noisy.*\(did you mean 'laggy'\?\)"):
        with_pilot(scenario, "lagy")


def test_with_pilot_gives_each_pilot_its_defaults_on_the_scenarios_participant(repo):
    scenario = load_scenario_file(repo / REACH).scenario
    participant = scenario.operator
    assert with_pilot(scenario, "attentive") is scenario
    pilots = {name: with_pilot(scenario, name).operator for name in PILOT_NAMES[1:]}
    assert isinstance(pilots["noisy"], NoisyPilot) and pilots["noisy"].eps == 0.3
    assert isinstance(pilots["laggy"], LaggyPilot) and pilots["laggy"].p == 0.85
    assert isinstance(pilots["proportional"], ProportionalPilot)
    assert pilots["proportional"].gain == 10.0
    assert pilots["proportional"].max_speed == participant.speed
    assert isinstance(pilots["population"], ParticipantPopulation)
    for name in ("noisy", "laggy", "population"):
        # The file's own calibration, not the defaults of the dataclass.
        assert pilots[name].participant.reaction_delay == participant.reaction_delay
        assert pilots[name].participant.rotation_speed == participant.rotation_speed
    # The scenario itself is left as it was.
    assert scenario.operator is participant


def test_a_scenario_without_the_participant_has_no_pilots(repo):
    scenario = load_scenario_file(repo / REACH).scenario
    keyboard = yaml_load_typed(schema=TaskScenario, data="operator: !Keyboard {}").operator
    with pytest.raises(ScenarioError, match="stands in for the virtual participant"):
        with_pilot(type(scenario)(**{**vars(scenario), "operator": keyboard}), "noisy")


@pytest.mark.slow
def test_the_tags_fields_reach_the_systems(repo, tmp_path):
    noisy = build_diagram(load_scenario_file(with_operator(
        repo, tmp_path, "!NoisyPilot {eps: 0.2, participant: {speed: 0.07}}")).resolved)
    operator = noisy.GetSubsystemByName("operator")
    assert operator.GetSubsystemByName("pilot_filter").eps == 0.2
    assert operator.GetSubsystemByName("pilot_filter").keys.speed == 0.07
    assert operator.GetSubsystemByName("participant").params.speed == 0.07
    laggy = build_diagram(load_scenario_file(with_operator(
        repo, tmp_path, "!LaggyPilot {p: 0.5}")).resolved)
    assert laggy.GetSubsystemByName("operator").GetSubsystemByName(
        "pilot_filter").p_tick == pytest.approx(lag_per_tick(0.5, 0.03))
    proportional = build_diagram(load_scenario_file(with_operator(
        repo, tmp_path, "!ProportionalPilot {gain: 4.0, max_speed: 0.05}")).resolved)
    operator = proportional.GetSubsystemByName("operator")
    assert (operator.params.gain, operator.max_speed) == (4.0, 0.05)


def test_the_proportional_pilot_moves_at_the_tasks_operator_speed_by_default(repo):
    resolved = resolve(with_pilot(load_scenario_file(repo / REACH).scenario, "proportional"))
    operator = build_diagram(resolved).GetSubsystemByName("operator")
    assert operator.max_speed == resolved.nominal_speed
