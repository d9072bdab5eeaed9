"""Running a task with its per-tick rows streamed to a CSV file (`run_task_streamed`), for
runs too long to keep their time series in memory (`pbp_drake_bench.soak`): after each
chunk of simulated time the rows of the ticks it completed are appended and every logger
is cleared; the peaks (`run.SeriesPeaks`) carry over. A chunk's last state sample waits
for its decisions (`DECISION_LOG_SHIFT`) in the next chunk; the run's last is not written.
"""

import numpy as np
from pydrake.systems.primitives import VectorLogSink

from pbp_drake.builder.run import (
    DECISION_LOGS, OPTIONAL_DECISION_LOGS, STATE_LOGS, SeriesPeaks, advance_to,
    initialized_simulator, robot_told_to_hold, state_log_name, task_series, ticks_of)
from pbp_drake.builder.time_series import time_series_header, time_series_rows
from pbp_drake.systems.tick import DECISION_LOG_SHIFT

DEFAULT_CHUNK_SECONDS = 10.0


def run_task_streamed(scenario, log_path, meshcat=None, realtime_rate=None, diagram=None,
                      chunk_seconds=DEFAULT_CHUNK_SECONDS, after_chunk=None, advance=None):
    """`run_task`, writing one CSV row per control tick to `log_path` (header first) as it
    goes. Returns `run_task`'s TaskResult, whose time series are empty (they are in the
    file). `after_chunk(time)`, when given, is called after each chunk is written with the
    simulated time reached; `advance` as `run_task`'s.
    """
    scenario, diagram, simulator = initialized_simulator(scenario, meshcat, realtime_rate,
                                                         diagram)
    period = scenario.control_period
    chunk_ticks = max(1, int(round(chunk_seconds / period)))
    # One tick past the end, as run_task: the loggers record tick k's decisions one sample later.
    last_tick = ticks_of(scenario) + 1
    tail = _LogTail(diagram)
    peaks = SeriesPeaks(period)
    context = simulator.get_context()
    with open(log_path, "w", newline="") as stream, robot_told_to_hold(diagram, simulator):
        stream.write(time_series_header(tail.has_collision, tail.has_grasp))
        tick = 0
        while True:
            tick = min(tick + chunk_ticks, last_tick)
            ended = (advance or advance_to)(simulator, tick * period)
            series = tail.take(context)
            stream.write(time_series_rows(series))
            stream.flush()
            peaks.add(series.fields)
            peaks.add_clipped(series.posterior_clipped)
            if after_chunk is not None:
                after_chunk(context.get_time())
            if tick == last_tick or ended:
                break
    return peaks.task_result(diagram, context, tail.empty_series())


class _Series:
    """A TaskResult's time series fields as attributes (what `time_series_rows` reads), and
    the `posterior_clipped_log` samples of the same ticks (None without HOP's posterior)."""

    def __init__(self, fields, posterior_clipped=None):
        self.__dict__.update(fields)
        self.fields = fields
        self.posterior_clipped = posterior_clipped


class _LogTail:
    """The samples read from the diagram's loggers and not yet written as rows."""

    def __init__(self, diagram):
        self._diagram = diagram
        # The hand's state: the grasping task logs its pose, the others ee_state.
        self._state_log = state_log_name(diagram)
        self._named = {name: diagram.GetSubsystemByName(name)
                       for name in ((self._state_log,) + STATE_LOGS + DECISION_LOGS
                                    + OPTIONAL_DECISION_LOGS)
                       if diagram.HasSubsystemNamed(name)}
        self._decisions = [name for name in DECISION_LOGS + OPTIONAL_DECISION_LOGS
                           if name in self._named]
        # Every logger, those not written too (phase_log): all are cleared.
        self._all = [system for system in diagram.GetSystems()
                     if isinstance(system, VectorLogSink)]
        self._times = np.zeros(0)
        self._samples = {name: np.zeros((0, logger.get_input_port().size()))
                         for name, logger in self._named.items()}
        self._to_skip = DECISION_LOG_SHIFT  # decision samples before tick 0's
        self.has_collision = "in_collision_log" in self._named
        self.has_grasp = self._state_log == "hand_pose_log"

    def take(self, context):
        """Reads the new samples of every logger and clears them all; returns the `_Series`
        of the ticks whose state and decisions are both read, and keeps the rest."""
        times = self._named[self._state_log].FindLog(context).sample_times()
        self._times = np.concatenate([self._times, times])
        for name, logger in self._named.items():
            self._samples[name] = np.vstack([self._samples[name],
                                             logger.FindLog(context).data().T])
        for logger in self._all:
            logger.FindMutableLog(context).Clear()
        skipped = min(self._to_skip, len(self._samples[DECISION_LOGS[0]]))
        for name in self._decisions:
            self._samples[name] = self._samples[name][skipped:]
        self._to_skip -= skipped
        return self._split(len(self._samples[DECISION_LOGS[0]]))

    def _split(self, count):
        """The `_Series` of the first `count` pending ticks, which leave the tail (as copies:
        a slice would keep alive the whole chunk it was cut from)."""
        times, self._times = self._times[:count].copy(), self._times[count:].copy()
        taken = {}
        for name in self._samples:
            taken[name], self._samples[name] = (self._samples[name][:count].copy(),
                                                self._samples[name][count:].copy())
        return _Series(task_series(self._diagram, times, taken[self._state_log],
                                   taken.get("in_collision_log"),
                                   {name: taken[name] for name in DECISION_LOGS}),
                       taken.get("posterior_clipped_log"))

    def empty_series(self):
        """The series fields of no ticks (what a streamed run's TaskResult holds)."""
        return self._split(0).fields
