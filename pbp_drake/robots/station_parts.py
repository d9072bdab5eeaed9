"""What every station has besides its robot: the obstacles measured against the robot and
the Meshcat visualizers (the HSR's and an arm's stations share them)."""

from pydrake.geometry import (
    CollisionFilterDeclaration, GeometrySet, MeshcatVisualizer, MeshcatVisualizerParams, Rgba,
    Role)

from pbp_drake.systems.tasks.collision_monitor import CollisionMonitor
from pbp_drake.systems.tasks.obstacle_geometry import CylinderObstacleGeometry


def add_obstacles(builder, plant, scene_graph, model, obstacles):
    """The cylinders, placed by the input obstacle_positions and measured against the
    robot's collision geometry (in_collision, clearance)."""
    geometry = builder.AddNamedSystem("obstacle_geometry", CylinderObstacleGeometry(
        scene_graph, [(obstacle.radius, obstacle.height) for obstacle in obstacles]))
    builder.Connect(geometry.get_geometry_pose_output_port(),
                    scene_graph.get_source_pose_port(geometry.source_id))
    robot_geometries = [geometry_id for body in plant.GetBodyIndices(model)
                        for geometry_id in plant.GetCollisionGeometriesForBody(
                            plant.get_body(body))]
    # The obstacles are measured, not felt: keep them out of the plant's contact (which
    # also refuses pairs of geometries it does not own, such as two obstacles meeting).
    scene_graph.collision_filter_manager().Apply(
        CollisionFilterDeclaration()
        .ExcludeBetween(GeometrySet(robot_geometries), GeometrySet(geometry.geometry_ids))
        .ExcludeWithin(GeometrySet(geometry.geometry_ids)))
    collisions = builder.AddNamedSystem(
        "collision_monitor", CollisionMonitor(robot_geometries, geometry.geometry_ids))
    builder.Connect(scene_graph.get_query_output_port(),
                    collisions.get_query_object_input_port())
    builder.ExportInput(geometry.get_obstacle_positions_input_port(), "obstacle_positions")
    builder.ExportOutput(collisions.get_in_collision_output_port(), "in_collision")
    builder.ExportOutput(collisions.get_clearance_output_port(), "clearance")


def add_meshcat_visualizers(builder, scene_graph, meshcat, visualization):
    """What `visualization` asks of Meshcat (Drake's `VisualizationConfig`, read here
    without its LCM side): the illustration geometry, and the proximity geometry (hidden
    at first) when `publish_proximity`."""
    if visualization.publish_illustration:
        MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat, MeshcatVisualizerParams(
            role=Role.kIllustration, publish_period=visualization.publish_period,
            default_color=visualization.default_illustration_color,
            delete_on_initialization_event=visualization.delete_on_initialization_event,
            enable_alpha_slider=visualization.enable_alpha_sliders))
    if visualization.publish_proximity:
        color = visualization.default_proximity_color
        MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat, MeshcatVisualizerParams(
            role=Role.kProximity, prefix="proximity", visible_by_default=False,
            publish_period=visualization.publish_period,
            default_color=Rgba(color.r(), color.g(), color.b(),
                               visualization.initial_proximity_alpha),
            delete_on_initialization_event=visualization.delete_on_initialization_event))
