"""What the HSR's and an arm's stations share: the plant, the robot on the diff IK's plan
and its `ee_state`, the obstacles measured against the robot, the Meshcat visualizers."""

import numpy as np
from pydrake.geometry import (
    CollisionFilterDeclaration, GeometrySet, MeshcatVisualizer, MeshcatVisualizerParams, Rgba,
    Role, SceneGraph)
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant
from pydrake.systems.framework import Diagram
from pydrake.systems.rendering import MultibodyPositionToGeometryPose

from pbp_drake.robots.hsr_ee_systems import EeStateFromPlant
from pbp_drake.robots.hsr_kinematic import KinematicJoints
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
    """What `visualization` (Drake's `VisualizationConfig`, without its LCM side) asks of
    Meshcat: the illustration geometry, and the proximity geometry (hidden at first)."""
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


def add_station_plant(builder, config, kinematic):
    """`(plant, scene_graph)` of a station's robot, its gravity off (which stands for the
    real robot's gravity compensation): the plant of `config.plant` in `builder`, or with
    `kinematic` one registered with the SceneGraph but outside the Diagram, to be filled
    and finalized by the caller."""
    if kinematic:
        scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
        plant = MultibodyPlant(config.plant.time_step)
        plant.RegisterAsSourceForSceneGraph(scene_graph)
    else:
        plant, scene_graph = AddMultibodyPlant(config.plant, builder)
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    return plant, scene_graph


def pose_at(plant, frame, q):
    """The world pose of `frame` with the plant at positions `q`."""
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    return frame.CalcPoseInWorld(context)


def add_robot(builder, plant, scene_graph, model, diff_ik, ramp, ee_frame, motor_joints,
              joints_input=None, couplers=()):
    """The robot on the diff IK's plan and its `ee_state` (of `ee_frame`, a body or a
    frame): with `joints_input` (`[q, v]` of `motor_joints`) `KinematicJoints` there, else
    the plant's PD tracking the plan. Exports the command input and `ee_state`; returns the
    robot's state port."""
    if joints_input is not None:
        joints = builder.AddNamedSystem("joints", KinematicJoints(plant, motor_joints,
                                                                  couplers))
        builder.Connect(joints_input, joints.get_desired_state_input_port())
        # Keeps a reference to the plant, which the Diagram does not own (pydrake keeps the
        # plant alive as long as this system).
        to_pose = builder.AddNamedSystem("geometry_poses", MultibodyPositionToGeometryPose(
            plant, input_multibody_state=True))
        builder.Connect(joints.get_state_output_port(), to_pose.get_input_port())
        builder.Connect(to_pose.get_output_port(),
                        scene_graph.get_source_pose_port(plant.get_source_id()))
        state = joints.get_state_output_port()
    else:
        state = plant.get_state_output_port()
        builder.Connect(diff_ik.get_desired_state_output_port(),
                        plant.get_desired_state_input_port(model))
    # Read at initialization only: the plan starts from the robot's state.
    builder.Connect(state, diff_ik.get_robot_state_input_port())
    ee_state = builder.AddNamedSystem("ee_state", EeStateFromPlant(plant, ee_frame))
    builder.Connect(state, ee_state.get_plant_state_input_port())
    builder.ExportInput(diff_ik.get_command_input_port(), ramp.port_name)
    builder.ExportOutput(ee_state.get_ee_state_output_port(), "ee_state")
    return state


def finish_station(builder, plant, scene_graph, model, config, meshcat, name):
    """Exports `query_object`, adds `config.obstacles` and, with `meshcat`, the
    visualizers, and builds the station Diagram named `name`."""
    builder.ExportOutput(scene_graph.get_query_output_port(), "query_object")
    if config.obstacles:
        add_obstacles(builder, plant, scene_graph, model, config.obstacles)
    if meshcat is not None:
        add_meshcat_visualizers(builder, scene_graph, meshcat, config.visualization)
    station = builder.Build()
    station.set_name(name)
    return station


def checked_station(station):
    """`station`; ValueError naming it unless it is a Diagram (a station's config is the
    likely mistake: the `*_ready_ee_state` functions take that)."""
    if not isinstance(station, Diagram):
        raise ValueError(f"station must be the Diagram of make_hsr_station or "
                         f"make_arm_station, got {type(station).__name__} (hsr_ready_ee_state "
                         "and arm_ready_ee_state take a config)")
    return station


def station_plant(station):
    """The MultibodyPlant of a station from `make_hsr_station` or `make_arm_station` (with
    kinematic motion, outside the Diagram)."""
    if checked_station(station).HasSubsystemNamed("plant"):
        return station.GetSubsystemByName("plant")
    return station.GetSubsystemByName("joints").plant()


#: A joint within this of a position limit (rad or m) stands at it (`joints_at_limits`).
AT_LIMIT_TOLERANCE = 1e-3


def joints_at_limits(station, station_context):
    """The names of a station's joints (`make_hsr_station`, `make_arm_station`) that stand
    at a position limit in `station_context`: where a hand that stopped short is held."""
    plant = station_plant(station)
    q = station.GetOutputPort("state").Eval(station_context)[:plant.num_positions()]
    lower, upper = plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()
    at_limit = (q - lower < AT_LIMIT_TOLERANCE) | (upper - q < AT_LIMIT_TOLERANCE)
    return [plant.get_joint(index).name() for index in plant.GetJointIndices()
            if plant.get_joint(index).num_positions() == 1
            and at_limit[plant.get_joint(index).position_start()]]


def initial_ee_state(station):
    """The hand's ``ee_state`` (``EeState``) where a station (`make_hsr_station`,
    `make_arm_station`) starts: read off a fresh context."""
    port = checked_station(station).GetOutputPort("ee_state")
    return np.array(port.Eval(station.CreateDefaultContext()))
