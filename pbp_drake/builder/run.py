"""Running a built scenario: a 2-D scene for its duration (`simulate`), an HSR task to
success or its time limit (`run_task`), and reading back the builder's loggers (`read_log`).

Both take a `ResolvedScenario` (or a `Scenario`, resolved here once). `advance`, when given,
replaces `advance_to`: the operator's console (`pbp_drake.console.LiveRun`) advances in
slices and may end the run early.
"""

import contextlib
import dataclasses

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorStatus

from pbp_drake.builder.build import build_diagram, find_system
from pbp_drake.builder.grasp import grasp_series_fields
from pbp_drake.core.coordinates import is_real
from pbp_drake.core.interaction_metrics import InteractionMeter, idle_ratio
from pbp_drake.robots import drives_real_robot
from pbp_drake.robots.station_parts import joints_at_limits
from pbp_drake.scenarios import ResolvedScenario, counted, resolve
from pbp_drake.systems.operators.browser_guard import reset_pacing_after_pauses
from pbp_drake.systems.ports import TaskStatus
from pbp_drake.systems.tick import DECISION_LOG_SHIFT


@dataclasses.dataclass
class Trajectory:
    """One simulation, indexed by control tick k = 0..T-1 (`t_k = k * control_period`).

    Attributes:
        times: (T,). positions, velocities: (T, D) the robot's state at `t_k`.
        operator_active: (T,) bools, the operator's decision at tick k;
        operator_command: (T, D) its command at tick k.
        command: (T, 2 D) the reference the blender sent from tick k on.
        phase: (T, K) the DMP phases with which tick k stepped, or None without DMPs.
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    operator_active: np.ndarray
    operator_command: np.ndarray
    command: np.ndarray
    phase: np.ndarray | None


def initialized_simulator(scenario, meshcat=None, realtime_rate=None, diagram=None,
                          task=None):
    """`(scenario, diagram, simulator)` of a scenario (resolved once if it is not): the
    diagram built unless given, the simulator configured by the scenario's
    `SimulatorConfig` (`realtime_rate` overriding its target rate) and initialized. `task`:
    True for a robot task's run (`run_task`), False for a 2-D scene's (`simulate`); the
    other kind is refused saying which to call."""
    if realtime_rate is not None and not (is_real(realtime_rate) and realtime_rate >= 0):
        raise ValueError(f"realtime_rate must be a number >= 0 (0: as fast as possible), got "
                         f"{realtime_rate!r}")
    resolved = scenario if isinstance(scenario, ResolvedScenario) else resolve(scenario)
    if task is not None and resolved.has_task != task:
        kind = ("a robot task (TaskScenario)" if resolved.has_task
                else "a 2-D scene (PointScenario)")
        call = "run_task" if resolved.has_task else "simulate"
        raise ValueError(f"scenario {resolved.scenario.name!r} is {kind}: run it with "
                         f"{call}(scenario)")
    diagram = build_diagram(resolved, meshcat) if diagram is None else diagram
    simulator = Simulator(diagram)
    reset_pacing_after_pauses(diagram, simulator)
    ApplySimulatorConfig(resolved.scenario.simulator, simulator)
    if realtime_rate is not None:
        simulator.set_target_realtime_rate(realtime_rate)
    if drives_real_robot(getattr(resolved.scenario.robot, "hardware", None)):
        # A real robot lives on the wall clock, whatever the page asks.
        simulator.set_target_realtime_rate(1.0)
    simulator.Initialize()
    return resolved.scenario, diagram, simulator


def ticks_of(scenario):
    """How many control ticks the scenario's time limit holds."""
    return int(round(scenario.duration / scenario.control_period))


def advance_to(simulator, time):
    """Advances `simulator` to `time`; True when it stopped earlier, at a termination event
    (the task monitor's at success)."""
    return (simulator.AdvanceTo(time).reason()
            == SimulatorStatus.ReturnReason.kReachedTerminationCondition)


def simulate(scenario, meshcat=None, realtime_rate=None, diagram=None, advance=None):
    """Simulates `scenario` for its duration and returns its Trajectory (the ticks up to
    where `advance` stopped, when it stopped early)."""
    scenario, diagram, simulator = initialized_simulator(scenario, meshcat, realtime_rate,
                                                         diagram, task=False)
    # One tick past the end: the loggers record tick k's decisions one sample later.
    ticks = ticks_of(scenario)
    context = simulator.get_context()
    if (advance or advance_to)(simulator, (ticks + 1) * scenario.control_period):
        samples = diagram.GetSubsystemByName("robot_state_log").FindLog(context).num_samples()
        ticks = max(0, samples - DECISION_LOG_SHIFT - 1)
    return read_trajectory(diagram, context, ticks + 1)


def read_log(diagram, context, name, tick_count, shift=0):
    """Tick times `(T,)` and samples `(T, n)` of the first `tick_count` ticks of the logger
    `name`, or (None, None) when the diagram has none.

    Drake dispatches the publish events of an instant (the loggers) before its discrete
    updates, so a logger at `t_k` sees the plant's state at `t_k` but the decisions of tick
    k - 1 (operator, blender, estimator): read those with `shift=DECISION_LOG_SHIFT` (one sample
    later), from a simulation run one tick past the last tick read.
    """
    if not diagram.HasSubsystemNamed(name):
        return None, None
    found = diagram.GetSubsystemByName(name).FindLog(context)
    if found.num_samples() < tick_count + shift:
        raise ValueError(f"{name} has {found.num_samples()} samples; "
                         f"{tick_count + shift} are needed")
    return found.sample_times()[:tick_count], found.data().T[shift:shift + tick_count]


def read_trajectory(diagram, context, tick_count):
    """The first `tick_count` ticks of the loggers the builder adds (see `read_log`)."""
    def log(name, shift=0):
        return read_log(diagram, context, name, tick_count, shift)

    times, state = log("robot_state_log")
    dimension = state.shape[1] // 2
    return Trajectory(
        times=times,
        positions=state[:, :dimension],
        velocities=state[:, dimension:],
        operator_active=log("operator_active_log", shift=DECISION_LOG_SHIFT)[1][:, 0] > 0.5,
        operator_command=log("operator_command_log", shift=DECISION_LOG_SHIFT)[1],
        command=log("command_log", shift=DECISION_LOG_SHIFT)[1],
        phase=log("phase_log")[1],
    )


@dataclasses.dataclass
class TaskResult:
    """One run of an HSR task, its metrics and its time series indexed by control tick k.

    Attributes:
        success: the end effector came within the success distance of the final target.
        task_time: seconds until success (the time limit when it failed).
        intervention_ratio: ticks with operator input / ticks of the task.
        switches: how many times the target switched.
        times: (T,) tick times. ee_positions: (T, 3); headings: (T,).
        commands: (T, 7) `[p, v, heading]` sent from tick k on.
        operator_active: (T,) bools; operator_commands: (T, 4).
        selected_goals, targets: (T,) object indices (estimate and truth) at tick k.
        objects: (M, 3).
        collision_ratio: ratio of ticks with the robot in collision (obstacle tasks; 0 in
            tasks without obstacles). in_collision: (T,) bools, or None without obstacles.
        peak_hand_speed: m/s, the largest one-tick hand speed over the run's ticks 0..T-1,
            `max_k |ee(t_{k+1}) - ee(t_k)| / control_period`, ee = `ee_positions`.
        peak_command_acceleration: m/s^2, the largest change of the commanded velocity
            between two ticks over the period, `max_k |v(k+1) - v(k)| / control_period`,
            v = `commands[:, 3:6]`. Both from `SeriesPeaks`; None when unknown (fewer
            than two ticks, or a TaskResult made without them).
        angles_to_target: (T,) degrees from the hand's orientation to the current target's
            grasp orientation (the grasping task; None in the others).
        command_angular_velocities: (T, 3) the commanded angular velocity (rad/s) sent from
            tick k on; operator_twists: (T, 6) the operator's whole twist (the grasping
            task; None in the others). `operator_commands` there is `[v, wz]`.
        hand_orientations: (T, 4) the hand's orientation, unit quaternions (w, x, y, z)
            (the grasping task; None in the others).
        peak_command_angular_change: rad/s, the largest change of the commanded angular
            velocity between two ticks (the grasping task; None in the others).
        final_angle_to_target: degrees, `angles_to_target` of the last tick (the grasping
            task; None in the others), kept when the series are not (a streamed run's).
        posterior_clipped_ratio: ticks whose goal posterior update was clipped at the
            scenario's `hop.max_probability` / ticks of the task, where the controller has
            HOP's posterior (hop, predict_then_assist, the maxent_command estimator; None
            elsewhere): how often the belief sat at its guard against certainty.
        input_integral, turn_input_integral, idle_ratio, agreement, prediction_accuracy,
            time_to_prediction, mean_time_to_prediction, unpredicted_switches: how the
            operator and the method worked together (`pbp_drake.core.interaction_metrics`,
            over the series' ticks; `idle_ratio` is `1 - intervention_ratio`, on the task
            monitor's ticks). None when unknown (a TaskResult made without them).
        joints_at_limits: the names of the robot's joints standing at a position limit
            when the run ended (`robots.station_parts.joints_at_limits`): where a hand
            that stopped short is held. None without a simulated robot (the bridge's)
            and in a trial read back from its files, which do not hold it.
    """

    success: bool
    task_time: float
    intervention_ratio: float
    switches: int
    times: np.ndarray
    ee_positions: np.ndarray
    headings: np.ndarray
    commands: np.ndarray
    operator_active: np.ndarray
    operator_commands: np.ndarray
    selected_goals: np.ndarray
    targets: np.ndarray
    objects: np.ndarray
    collision_ratio: float = 0.0
    in_collision: np.ndarray | None = None
    peak_hand_speed: float | None = None
    peak_command_acceleration: float | None = None
    angles_to_target: np.ndarray | None = None
    command_angular_velocities: np.ndarray | None = None
    operator_twists: np.ndarray | None = None
    hand_orientations: np.ndarray | None = None
    peak_command_angular_change: float | None = None
    final_angle_to_target: float | None = None
    posterior_clipped_ratio: float | None = None
    input_integral: float | None = None
    turn_input_integral: float | None = None
    idle_ratio: float | None = None
    agreement: float | None = None
    prediction_accuracy: float | None = None
    time_to_prediction: list | None = None
    mean_time_to_prediction: float | None = None
    unpredicted_switches: int | None = None
    joints_at_limits: list | None = None

    def __post_init__(self):
        if (self.final_angle_to_target is None and self.angles_to_target is not None
                and len(self.angles_to_target)):
            self.final_angle_to_target = float(self.angles_to_target[-1])

    def summary_line(self, stopped=False):
        """One line: outcome, time, intervention ratio, the collision ratio where the task
        measures collisions (the obstacle task: `in_collision` is logged), target switches,
        the peaks and, where measured, the interaction metrics. `stopped`: the person ended
        the run before its end ("stopped at")."""
        outcome = "success" if self.success else "FAILED"
        # Only the obstacle task measures collisions.
        collisions = ("" if self.in_collision is None
                      else f", collision ratio {self.collision_ratio:.3f}")
        turning = ("" if self.angles_to_target is None else
                   f", final angle to target {_or_na(self.final_angle_to_target, 1)} deg, peak "
                   f"command angular change {_or_na(self.peak_command_angular_change, 3)} "
                   "rad/s per tick")
        ended = (f"stopped at {self.task_time:.2f} s" if stopped and not self.success
                 else f"{outcome} in {self.task_time:.2f} s")
        clipped = ("" if self.posterior_clipped_ratio is None else
                   f", posterior at its clip {self.posterior_clipped_ratio:.3f} of the time")
        return (f"{ended}, intervention ratio "
                f"{self.intervention_ratio:.3f}{collisions}, "
                f"{counted(self.switches, 'target switch', 'target switches')}, "
                f"peak hand speed {_or_na(self.peak_hand_speed, 3)} m/s, "
                f"peak command acceleration {_or_na(self.peak_command_acceleration, 2)} m/s^2"
                f"{turning}{clipped}{self._interaction_text()}")

    def _interaction_text(self):
        """The interaction metrics' part of `summary_line` ("" when not measured)."""
        if self.input_integral is None:
            return ""
        text = (f", input {self.input_integral:.3f} m and {self.turn_input_integral:.3f} rad, "
                f"idle ratio {_or_na(self.idle_ratio, 3)}, "
                f"agreement {_or_na(self.agreement, 3)}")
        if self.prediction_accuracy is None:
            return text + ", no goal named"
        never = self.unpredicted_switches or 0
        return (text + f", prediction accuracy {self.prediction_accuracy:.3f}, "
                f"time to prediction {_or_na(self.mean_time_to_prediction, 2)} s"
                + (f" ({counted(never, 'switch', 'switches')} never named)" if never else ""))


def _or_na(value, digits):
    return "n/a" if value is None else f"{value:.{digits}f}"


class LargestStep:
    """The largest step `max_k |x(k+1) - x(k)|` of a series, fed whole (`run_task`) or in
    pieces (a streamed run), the step across two pieces included."""

    def __init__(self):
        self._last = None
        self._largest = None  # until two rows

    def add(self, rows):
        if len(rows) == 0:
            return
        rows = np.asarray(rows, float)
        joined = rows if self._last is None else np.vstack([self._last, rows])
        if len(joined) >= 2:
            step = float(np.linalg.norm(np.diff(joined, axis=0), axis=1).max())
            self._largest = step if self._largest is None else max(self._largest, step)
        self._last = rows[-1:].copy()

    def peak(self, control_period):
        """The largest step over the period, or None before two rows."""
        return None if self._largest is None else float(self._largest / control_period)


def run_task(scenario, meshcat=None, realtime_rate=None, diagram=None, advance=None):
    """Simulates an HSR task until success or `scenario.duration` (the time limit), or
    until `advance` stops it."""
    scenario, diagram, simulator = initialized_simulator(scenario, meshcat, realtime_rate,
                                                         diagram, task=True)
    # The task monitor itself ends the simulation at success.
    with robot_told_to_hold(diagram, simulator):
        (advance or advance_to)(simulator, (ticks_of(scenario) + 1) * scenario.control_period)
    context = simulator.get_context()
    state_log = state_log_name(diagram)
    # The last sample holds only the decisions of the tick before it (see read_log).
    tick_count = diagram.GetSubsystemByName(state_log).FindLog(context).num_samples() - 1
    times, state = read_log(diagram, context, state_log, tick_count)
    in_collision = read_log(diagram, context, "in_collision_log", tick_count)[1]
    decisions = {name: read_log(diagram, context, name, tick_count, shift=DECISION_LOG_SHIFT)[1]
                 for name in DECISION_LOGS}
    series = task_series(diagram, times, state, in_collision, decisions)
    peaks = SeriesPeaks(scenario.control_period)
    peaks.add(series)
    peaks.add_clipped(read_log(diagram, context, "posterior_clipped_log", tick_count,
                               shift=DECISION_LOG_SHIFT)[1])
    return peaks.task_result(diagram, context, series)


@contextlib.contextmanager
def robot_told_to_hold(diagram, simulator):
    """Tells the robot on the far side of a task-space bridge in `diagram` to hold however
    its run ends, Ctrl-C and the bridge's own errors included (`BridgeLink.send_hold`)."""
    try:
        yield
    finally:
        try:
            link = find_system(diagram, "bridge_link")
        except KeyError:
            link = None
        if link is not None:
            link.send_hold(link.GetMyContextFromRoot(simulator.get_context()))


def final_joints_at_limits(diagram, context):
    """`joints_at_limits` of the task's simulated station (the HSR's or an arm's) once its
    simulation has ended; None when the diagram has none (the task-space bridge's)."""
    for name in ("hsr_station", "arm_station"):
        if diagram.HasSubsystemNamed(name):
            station = diagram.GetSubsystemByName(name)
            return joints_at_limits(station, station.GetMyContextFromRoot(context))
    return None


# The loggers that hold decisions (read `DECISION_LOG_SHIFT` samples later, see read_log)
# and those measured on the plant's state (not shifted) that make a TaskResult's series.
DECISION_LOGS = ("command_log", "operator_active_log", "operator_command_log",
                 "selected_goal_log", "target_log")
# The decision loggers only some controllers have (HOP's posterior), read as those above.
OPTIONAL_DECISION_LOGS = ("posterior_clipped_log",)
STATE_LOGS = ("ee_state_log", "in_collision_log")


def state_log_name(diagram):
    """The logger of the hand's state in a task's diagram: the grasping task logs the hand's
    pose (`builder.grasp`), the others `ee_state`."""
    return "hand_pose_log" if diagram.HasSubsystemNamed("hand_pose_log") else "ee_state_log"


def task_series(diagram, times, state, in_collision, decisions):
    """A TaskResult's time series fields, as a dict, of the task of `diagram`:
    `grasp_series_fields` for the grasping task, `series_fields` for the others; `state`
    the samples of `state_log_name(diagram)`."""
    if state_log_name(diagram) == "hand_pose_log":
        grasps = diagram.GetSubsystemByName("task_monitor").grasp_orientations
        return grasp_series_fields(times, state, decisions, grasps)
    return series_fields(times, state, in_collision, decisions)


class SeriesPeaks:
    """What a TaskResult keeps of a run's whole series, fed whole (`run_task`) or chunk by
    chunk (a streamed run): the peaks, the final angle to the target, the interaction
    metrics (`InteractionMeter`) and, fed the `posterior_clipped_log` samples
    (`add_clipped`), the posterior's clipped ratio (see `TaskResult`)."""

    def __init__(self, control_period):
        self._period = control_period
        self._interaction = InteractionMeter(control_period)
        self._hand, self._command, self._turning = LargestStep(), LargestStep(), LargestStep()
        self._grasp = False
        self._final_angle = None
        self._clipped_ticks = self._posterior_ticks = None  # without a posterior

    def add(self, series):
        """Feeds the next ticks' series fields (a dict, see `task_series`)."""
        self._hand.add(series["ee_positions"])
        self._command.add(series["commands"][:, 3:6])
        commands, twists = series["operator_commands"], series.get("operator_twists")
        self._interaction.add(
            series["times"], commands[:, :3],
            commands[:, 3] if twists is None else np.asarray(twists)[:, 3:6],
            series["operator_active"], series["ee_positions"], series["selected_goals"],
            series["targets"])
        if series.get("angles_to_target") is not None:
            self._grasp = True
            self._turning.add(series["command_angular_velocities"])
            if len(series["angles_to_target"]):
                self._final_angle = float(series["angles_to_target"][-1])

    def add_clipped(self, samples):
        """Feeds the next ticks' `posterior_clipped_log` samples (T, 1), already shifted;
        None (a controller without HOP's posterior) feeds nothing."""
        if samples is None:
            return
        flags = np.asarray(samples, float).reshape(-1) > 0.5
        self._clipped_ticks = (self._clipped_ticks or 0) + int(flags.sum())
        self._posterior_ticks = (self._posterior_ticks or 0) + len(flags)

    def task_result(self, diagram, context, series):
        """The TaskResult of the run of `diagram` ended in `context`: its task monitor's
        status, its station's `joints_at_limits`, `series` and the peaks fed."""
        monitor = diagram.GetSubsystemByName("task_monitor")
        status = TaskStatus(monitor.get_task_status_output_port().Eval(
            monitor.GetMyContextFromRoot(context)))
        if self._grasp:
            series = dict(series, peak_command_angular_change=self._turning.peak(1.0),
                          final_angle_to_target=self._final_angle)
        if self._posterior_ticks:
            series = dict(series, posterior_clipped_ratio=(
                self._clipped_ticks / self._posterior_ticks))
        return TaskResult(
            success=bool(status.success > 0.5),
            task_time=float(status.task_time),
            intervention_ratio=float(status.intervention_ratio),
            switches=int(status.stage),
            objects=monitor.objects.copy(),
            collision_ratio=float(status.collision_ratio),
            peak_hand_speed=self._hand.peak(self._period),
            peak_command_acceleration=self._command.peak(self._period),
            idle_ratio=idle_ratio(status.intervention_ratio),
            joints_at_limits=final_joints_at_limits(diagram, context),
            **series, **self._interaction.metrics().fields())


def series_fields(times, ee_state, in_collision, decisions):
    """A TaskResult's time series fields, as a dict, from the samples of its ticks: `times`
    and `ee_state` of `ee_state_log`, `in_collision` of `in_collision_log` (None without
    obstacles), and `decisions` of each of DECISION_LOGS by name, already shifted."""
    return dict(
        times=times,
        ee_positions=ee_state[:, :3],
        headings=ee_state[:, 6],
        commands=decisions["command_log"],
        operator_active=decisions["operator_active_log"][:, 0] > 0.5,
        operator_commands=decisions["operator_command_log"],
        selected_goals=decisions["selected_goal_log"][:, 0].astype(int),
        targets=decisions["target_log"][:, 3].astype(int),
        in_collision=None if in_collision is None else in_collision[:, 0] > 0.5)

