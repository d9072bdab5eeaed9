"""The one entry point from a scenario to a Drake Diagram."""

from pbp_drake.builder.grasp import build_grasp_diagram
from pbp_drake.builder.reach import build_reach_diagram
from pbp_drake.builder.point_robot import build_point_robot_diagram
from pbp_drake.scenarios import GraspTask, ResolvedScenario, resolve


def build_diagram(scenario, meshcat=None, prediction_steps=None, hand_trail=False):
    """The Diagram of a `ResolvedScenario` (or of a `Scenario`, resolved here once); with
    `meshcat`, also drawn there. `prediction_steps` (2-D scenes) sets how far ahead the DMPs'
    paths are drawn (default: their duration, when drawing); `hand_trail` (the reaching and
    obstacle tasks) draws the hand's path as it grows."""
    resolved = scenario if isinstance(scenario, ResolvedScenario) else resolve(scenario)
    if resolved.has_task and isinstance(resolved.scenario.task, GraspTask):
        return build_grasp_diagram(resolved, meshcat)
    if resolved.has_task:
        return build_reach_diagram(resolved, meshcat, hand_trail)
    return build_point_robot_diagram(resolved, meshcat, prediction_steps)


def find_system(diagram, name):
    """The subsystem called `name` anywhere in `diagram` (nested diagrams included, depth
    first), e.g. `find_system(diagram, "dmp_bank")` inside the HSR task's
    `pbp_controller`. Raises KeyError when there is none."""
    if diagram.HasSubsystemNamed(name):
        return diagram.GetSubsystemByName(name)
    for system in diagram.GetSystems():
        if hasattr(system, "HasSubsystemNamed"):
            try:
                return find_system(system, name)
            except KeyError:
                pass
    raise KeyError(f"{diagram.get_name()!r} has no subsystem named {name!r}")
