"""The schema nests Drake's config structs and round-trips through `yaml_dump_typed`, and
through pickle (how a study sends its scenario to its workers)."""

import pathlib
import pickle

import pytest
from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed

from pbp_drake.scenarios import (
    ScenarioFile, TaskScenario, TaskScenarioFile, load_scenario_file)

SHIPPED = sorted(pathlib.Path(__file__).resolve().parents[2].glob("diagrams/*.yaml"))


@pytest.mark.parametrize("path", SHIPPED, ids=lambda path: path.stem)
def test_shipped_scenarios_round_trip(path):
    loaded = load_scenario_file(path)
    schema = TaskScenarioFile if isinstance(loaded.scenario, TaskScenario) else ScenarioFile
    original = schema(scenario=loaded.scenario, study=loaded.study)
    text = yaml_dump_typed(original)
    again = yaml_load_typed(schema=schema, data=text)
    assert yaml_dump_typed(again) == text
    # Drake's config structs (the plant's, the simulator's, an arm's LCM bus) by their YAML.
    assert yaml_dump_typed(pickle.loads(pickle.dumps(original))) == text
    assert type(again.scenario.operator) is type(original.scenario.operator)
    assert again.scenario.simulator.target_realtime_rate == (
        original.scenario.simulator.target_realtime_rate)
