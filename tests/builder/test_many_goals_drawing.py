"""A page of many goals: what the task's drawing sends does not grow with the goal count
once the scene is drawn, and `scenario.likely_paths` sets how many paths it draws."""

import dataclasses

import numpy as np
import pytest
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.builder import build_diagram
from pbp_drake.scenarios import ScenarioError, load_scenario_file, resolve
from pbp_drake.systems.ports import Target
from pbp_drake.systems.visualizers.reach_scene_visualizer import ReachSceneVisualizer


@pytest.fixture(scope="module")
def meshcat():
    return Meshcat(MeshcatParams(host="localhost", port=0))  # any free port; this thread only


class CountingMeshcat:
    """Forwards to a Meshcat and counts the calls made after `start()`."""

    def __init__(self, meshcat):
        self._meshcat, self.calls = meshcat, None

    def start(self):
        self.calls = 0

    def __getattr__(self, name):
        method = getattr(self._meshcat, name)

        def counted(*args, **kwargs):
            if self.calls is not None:
                self.calls += 1
            return method(*args, **kwargs)
        return counted


def calls_in_a_second(meshcat, goal_count):
    rng = np.random.default_rng(goal_count)
    objects = np.column_stack([rng.uniform(1.2, 2.5, goal_count),
                               rng.uniform(-1.0, 1.0, goal_count), np.full(goal_count, 0.7)])
    steps, paths = 10, 4
    counting = CountingMeshcat(meshcat)
    builder = DiagramBuilder()
    visualizer = builder.AddSystem(ReachSceneVisualizer(counting, objects, steps, paths))
    probabilities = rng.uniform(size=goal_count)
    for value, port in [(np.zeros(Target.size), visualizer.get_target_input_port()),
                        ([1.0], visualizer.get_selected_goal_input_port()),
                        (np.linspace(0, 1, paths * (steps + 1) * 3),
                         visualizer.get_predicted_paths_input_port()),
                        (probabilities / probabilities.sum(),
                         visualizer.get_goal_probabilities_input_port())]:
        source = builder.AddSystem(ConstantVectorSource(np.asarray(value, float)))
        builder.Connect(source.get_output_port(), port)
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    counting.start()
    simulator.AdvanceTo(1.0)
    meshcat.Delete("/task")
    return counting.calls


def test_what_a_page_is_sent_each_second_does_not_grow_with_the_goals(meshcat):
    few, many = calls_in_a_second(meshcat, 5), calls_in_a_second(meshcat, 2000)
    assert few == many
    assert few < 1200  # four paths of 24 dots at 10 Hz, the markers at 30 Hz


def test_likely_paths_sets_how_many_paths_the_page_draws(repo, meshcat):
    scenario = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    scenario = dataclasses.replace(scenario, likely_paths=1, task=dataclasses.replace(
        scenario.task, object_count=[4, 4]))
    Simulator(build_diagram(resolve(scenario), meshcat)).Initialize()
    assert meshcat.HasPath("/task/predictions/selected/0")
    assert meshcat.HasPath("/task/predictions/likely/1/0")
    assert not meshcat.HasPath("/task/predictions/likely/2")
    meshcat.Delete("/task")
    with pytest.raises(ScenarioError, match=r"scenario.likely_paths 21 is out of range"):
        resolve(dataclasses.replace(scenario, likely_paths=21))
