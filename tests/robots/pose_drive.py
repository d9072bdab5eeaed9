"""Drives a pose station (``make_hsr_station(command="pose")``) along waypoints (a test
helper): the command moves the hand between poses at constant linear and angular
velocity (linear in position, slerp in orientation) and holds each pose for a while."""

import dataclasses

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput

from pbp_drake.core.quaternion import aligned, exp_map, log_map, multiply, conjugate
from pbp_drake.robots import HsrStationConfig, hsr_initial_hand_pose, make_hsr_station
from pbp_drake.systems.ports import PoseState


def turned(axis, degrees, quaternion):
    """``quaternion`` turned by ``degrees`` about the world ``axis``."""
    return multiply(exp_map(np.radians(degrees) * np.asarray(axis, float)), quaternion)


class PoseWaypoints(LeafSystem):
    """Outputs the ``PoseState`` command through ``segments``: (start time, duration,
    position (3), quaternion (4)) each, moving from the previous pose to this one over
    ``duration`` and holding it until the next segment starts."""

    def __init__(self, start, segments):
        super().__init__()
        poses = [(np.asarray(start[:3], float), np.asarray(start[3:7], float))]
        self._segments = []
        for begin, duration, position, quaternion in segments:
            p0, q0 = poses[-1]
            q1 = aligned(np.asarray(quaternion, float), q0)
            rotation = log_map(multiply(q1, conjugate(q0)))
            self._segments.append((begin, duration, p0, q0, np.asarray(position, float),
                                   rotation))
            poses.append((np.asarray(position, float), q1))
        self._start = poses[0]
        self.DeclareVectorOutputPort("pose_command", PoseState.size, self._calc)

    def _calc(self, context, output: BasicVector):
        time = context.get_time()
        p, q = self._start
        v = w = np.zeros(3)
        for begin, duration, p0, q0, p1, rotation in self._segments:
            if time < begin:
                break
            fraction = min(1.0, (time - begin) / duration)
            p = p0 + fraction * (p1 - p0)
            q = multiply(exp_map(fraction * rotation), q0)
            moving = fraction < 1.0
            v = (p1 - p0) / duration if moving else np.zeros(3)
            w = rotation / duration if moving else np.zeros(3)
        output.SetFromVector(np.concatenate([p, q, v, w]))


@dataclasses.dataclass
class PoseDrive:
    """What a drive logged every 10 ms: the hand's PoseState, the command and the plant's
    state (columns are samples)."""

    times: np.ndarray
    hand: np.ndarray
    commands: np.ndarray
    states: np.ndarray

    def at(self, time):
        """Column index of the sample nearest ``time``."""
        return int(np.argmin(np.abs(self.times - time)))


def drive(segments, duration, config=None):
    """Runs a pose station under ``PoseWaypoints(start, segments)`` from its start pose."""
    station = make_hsr_station(config or HsrStationConfig(), command="pose")
    builder = DiagramBuilder()
    builder.AddNamedSystem("hsr_station", station)
    source = builder.AddSystem(PoseWaypoints(hsr_initial_hand_pose(station), segments))
    builder.Connect(source.get_output_port(), station.GetInputPort("pose_command"))
    loggers = [LogVectorOutput(port, builder, 0.01) for port in (
        station.GetOutputPort("hand_pose"), source.get_output_port(),
        station.GetOutputPort("state"))]
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(duration)
    logs = [logger.FindLog(simulator.get_context()) for logger in loggers]
    return PoseDrive(logs[0].sample_times(), logs[0].data(), logs[1].data(), logs[2].data())
