"""The 2-D alpha study's operator speeds and goal distances, on one small scene (fast)."""

import dataclasses
import json

import pytest

from pbp_drake import cli
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.scenarios.loading import check_operator_speeds
from pbp_drake.scenarios.schema import ScenarioError
from pbp_drake.studies.toy import run_alpha_study

# Its tests share fixtures that take seconds to make: `make test-fast` leaves it out.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def inside_the_bow(repo, tmp_path_factory):
    """scene_3 of the shipped study (an obstacle inside the path's bow) at speeds 1 and 2,
    with two alphas only."""
    loaded = load_scenario_file(repo / "diagrams/toy_alpha_study.yaml")
    scene = next(s for s in loaded.study.scenes if s.name == "scene_3")
    study = dataclasses.replace(loaded.study, scenes=[scene], alphas=[0.0, 1.0],
                                operator_speeds=[1.0, 2.0])
    output = tmp_path_factory.mktemp("inside_the_bow")
    run_alpha_study(loaded.resolved, study, output)
    return json.loads((output / "summary.json").read_text())


def test_each_speed_has_its_own_results_and_the_operator_pushes_at_it(inside_the_bow):
    by_speed = inside_the_bow["scenes"][0]["by_operator_speed"]
    assert list(by_speed) == ["1", "2"]
    for key, results in by_speed.items():
        assert results["operator_speed"] == float(key)
        assert results["measured_operator_speed"] == pytest.approx(float(key))
    # Speed matters: PBP-Cont passes over this obstacle at 1 and cuts through it at 2.
    assert by_speed["1"]["pbp_continuous"]["collision_ratio"] == 0.0
    assert by_speed["2"]["pbp_continuous"]["collision_ratio"] > 0.05


def test_every_method_reports_its_final_distance_and_whether_it_reached(inside_the_bow):
    tolerance = inside_the_bow["goal_tolerance"]
    assert tolerance == 0.01
    for results in inside_the_bow["scenes"][0]["by_operator_speed"].values():
        outcomes = [results["pbp_alternated"], results["pbp_continuous"],
                    *results["fixed_alpha"].values()]
        assert len(outcomes) == 4
        for outcome in outcomes:
            assert outcome["reached"] == (outcome["final_distance"] <= tolerance)
            # Here every method ends at the goal (1, 0).
            assert outcome["reached"]


def test_operator_speeds_are_checked_when_the_file_loads(repo):
    loaded = load_scenario_file(repo / "diagrams/toy_alpha_study.yaml")
    for speeds, message in (([1.0, float("nan")], "finite"), ([2.0, 2.0], "repeats")):
        study = dataclasses.replace(loaded.study, operator_speeds=speeds)
        with pytest.raises(ScenarioError, match=message):
            check_operator_speeds(study, loaded.scenario)
    with pytest.raises(ScenarioError, match="goal_tolerance"):
        check_operator_speeds(dataclasses.replace(loaded.study, goal_tolerance=0.0),
                              loaded.scenario)


def test_the_scenario_operator_s_own_speed_runs_beside_the_listed_ones(repo, tmp_path):
    # An edited operator.speed was ignored while study.operator_speeds listed others, and
    # panel (d), "at the scenario's speed", drew the first listed speed.
    output = tmp_path / "study"
    assert cli.main(["study", str(repo / "diagrams/toy_alpha_study.yaml"), "--output",
                     str(output), "--set", "operator.speed=3", "--set",
                     "study.operator_speeds=[1]", "--set", "study.alphas=[0.5]", "--set",
                     "study.scenes=[{name: s, obstacles: [{center: [0.5, 0.3], "
                     "radius: 0.2}]}]"]) == 0
    by_speed = json.loads((output / "summary.json").read_text())["scenes"][0][
        "by_operator_speed"]
    assert list(by_speed) == ["1", "3"]
    assert by_speed["3"]["measured_operator_speed"] == pytest.approx(3.0)
