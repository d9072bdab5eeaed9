"""Tests of CollisionMonitor on a small scene of anchored spheres: the clearance is the
smallest signed distance over robot-obstacle pairs, it sees overlaps that collision
filters hide, and one evaluation queries each pair once."""

import pytest
from pydrake.geometry import (
    CollisionFilterDeclaration, GeometryInstance, GeometrySet, ProximityProperties,
    SceneGraph, Sphere)
from pydrake.math import RigidTransform
from pydrake.systems.framework import DiagramBuilder

from pbp_drake.systems.tasks.collision_monitor import CollisionMonitor


class CountingCollisionMonitor(CollisionMonitor):
    """Counts how often the clearance is computed (each time queries every pair)."""

    def __init__(self, *args):
        super().__init__(*args)
        self.clearance_computations = 0

    def _calc_clearance(self, context, output):
        self.clearance_computations += 1
        super()._calc_clearance(context, output)


def anchored_sphere(scene_graph, source, name, radius, x):
    geometry = scene_graph.RegisterAnchoredGeometry(source, GeometryInstance(
        RigidTransform([x, 0.0, 0.0]), Sphere(radius), name))
    scene_graph.AssignRole(source, geometry, ProximityProperties())
    return geometry


def make_scene(obstacle_xs, monitor_type=CollisionMonitor):
    """Robot spheres of radius 0.1 at x = 0 and 0.3; obstacle spheres of radius 0.2 at
    ``obstacle_xs``, filtered against the robot as the station filters them. Returns the
    diagram, its context and the monitor."""
    builder = DiagramBuilder()
    scene_graph = builder.AddSystem(SceneGraph())
    source = scene_graph.RegisterSource("scene")
    robot = [anchored_sphere(scene_graph, source, f"robot_{i}", 0.1, x)
             for i, x in enumerate([0.0, 0.3])]
    obstacles = [anchored_sphere(scene_graph, source, f"obstacle_{i}", 0.2, x)
                 for i, x in enumerate(obstacle_xs)]
    scene_graph.collision_filter_manager().Apply(
        CollisionFilterDeclaration().ExcludeBetween(GeometrySet(robot), GeometrySet(obstacles)))
    monitor = builder.AddSystem(monitor_type(robot, obstacles))
    builder.Connect(scene_graph.get_query_output_port(), monitor.get_query_object_input_port())
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    return diagram, monitor, monitor.GetMyContextFromRoot(context)


def test_clearance_is_the_nearest_pair():
    # Nearest pair: the robot sphere at 0.3 and the obstacle at 1.0: 0.7 - 0.1 - 0.2.
    _, monitor, context = make_scene([1.0, -2.0])
    assert monitor.get_clearance_output_port().Eval(context)[0] == pytest.approx(0.4)
    assert monitor.get_in_collision_output_port().Eval(context)[0] == 0.0


def test_overlap_is_seen_through_the_collision_filter():
    _, monitor, context = make_scene([0.5])  # 0.2 from the sphere at 0.3: 0.1 overlap
    assert monitor.get_clearance_output_port().Eval(context)[0] == pytest.approx(-0.1)
    assert monitor.get_in_collision_output_port().Eval(context)[0] == 1.0


def test_each_pair_is_queried_once_per_evaluation():
    _, monitor, context = make_scene([0.5, 1.0], CountingCollisionMonitor)
    monitor.get_in_collision_output_port().Eval(context)
    monitor.get_clearance_output_port().Eval(context)
    monitor.get_in_collision_output_port().Eval(context)
    assert monitor.clearance_computations == 1


def test_needs_geometry_on_both_sides():
    with pytest.raises(ValueError, match="robot and obstacle geometries"):
        CollisionMonitor([], [])
