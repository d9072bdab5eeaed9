"""The Drake diagram built from a scenario and the plain NumPy loop give the same trajectory."""

import dataclasses

import numpy as np
import pytest

from pbp_drake.scenarios import load_scenario_file
from pbp_drake.builder.run import simulate
from plain_loop import plain_loop


@pytest.mark.slow
@pytest.mark.parametrize("method", ["pbp_alternated", "pbp_continuous", "fixed_alpha",
                                    "teleop", "pbp_no_user"])
def test_alpha_study_scene_matches_the_plain_loop(repo, method):
    scenario = load_scenario_file(repo / "diagrams/toy_alpha_study.yaml").scenario
    scenario = dataclasses.replace(scenario, method=method, alpha=0.3)
    trajectory = simulate(scenario)
    expected = plain_loop(scenario)
    assert trajectory.positions.shape == expected.shape
    np.testing.assert_allclose(trajectory.positions, expected, rtol=0, atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["pbp_alternated", "pbp_continuous"])
def test_alt_vs_cont_scenario_matches_the_plain_loop(repo, method):
    scenario = load_scenario_file(repo / "diagrams/toy_alt_vs_cont.yaml").scenario
    scenario = dataclasses.replace(scenario, method=method)
    np.testing.assert_allclose(simulate(scenario).positions, plain_loop(scenario),
                               rtol=0, atol=1e-9)
