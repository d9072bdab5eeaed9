"""The virtual participant's `impairment` in a scenario file: its values reach the
participant of each HSR task, and unusable ones are refused, naming the field."""

import pathlib

import pytest
from pydrake.common.yaml import yaml_load_typed

from pbp_drake.builder import build_diagram
from pbp_drake.core.participant_impairment import ParticipantImpairment
from pbp_drake.scenarios import ScenarioError, TaskScenario, load_scenario_file, resolve

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"
REACH = "robot: !Hsr {}\ntask: {}\ncontrol_period: 0.03\n"


def with_impairment(tmp_path, file, impairment):
    """A shipped scenario file whose participant has `impairment` (YAML flow mapping)."""
    text = (DIAGRAMS / file).read_text()
    old = "operator: !VirtualParticipant\n"
    assert old in text
    path = tmp_path / file
    path.write_text(text.replace(old, f"{old}    impairment: {impairment}\n", 1))
    return path


@pytest.mark.parametrize("file", ["hsr_reach.yaml", "hsr_obstacles.yaml", "hsr_grasp.yaml"])
@pytest.mark.parametrize("impairment, message", [
    ("{command_delay: -0.1}",
     r"scenario.operator.impairment.command_delay must be finite and not negative, got -0.1"),
    ("{command_noise: .nan}", r"scenario.operator.impairment.command_noise: NaN"),
    ("{command_noise: -0.2}",
     r"scenario.operator.impairment.command_noise must be finite and not negative"),
    ("{mistake_probability: 1.5}",
     r"scenario.operator.impairment.mistake_probability must be a probability, 0 to 1, "
     r"got 1.5"),
    ("{mistake_time: -1.0}",
     r"scenario.operator.impairment.mistake_time must be finite and not negative"),
    ("{command_delay: 100.0}",
     r"scenario.operator.impairment.command_delay 100.0 s is longer than any person's"),
    ("{command_dealy: 0.3}", r"command_dealy"),
])
def test_unusable_impairments_are_refused_naming_the_field(tmp_path, file, impairment,
                                                          message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(with_impairment(tmp_path, file, impairment))


def test_the_impairment_reaches_the_reach_participant():
    text = REACH + ("operator: !VirtualParticipant\n  impairment: {command_noise: 0.2, "
                    "command_delay: 0.3, mistake_probability: 0.5}\n")
    diagram = build_diagram(resolve(yaml_load_typed(schema=TaskScenario, data=text)), None)
    impairment = diagram.GetSubsystemByName("operator").params.impairment
    assert impairment == ParticipantImpairment(command_noise=0.2, command_delay=0.3,
                                               mistake_probability=0.5)


def test_the_impairment_reaches_the_grasp_participant(tmp_path):
    path = with_impairment(tmp_path, "hsr_grasp.yaml", "{command_delay: 0.3, "
                           "mistake_probability: 0.2}")
    diagram = build_diagram(load_scenario_file(path).resolved, None)
    participant = diagram.GetSubsystemByName("operator").participant
    assert participant.params.impairment == ParticipantImpairment(command_delay=0.3,
                                                                  mistake_probability=0.2)
