"""The task-space bridge over Drake's LCM in one process (memq:// only): a controller drives
the HSR station through the bridge and a relay as it drives the station itself, a period
later; no relay and a bad state each end the run with one clear error."""

import dataclasses
import pathlib
import re
import time
import types
from unittest import mock

import numpy as np
import pytest
from drake import lcmt_drake_signal
from pydrake.lcm import DrakeLcm, DrakeLcmParams
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.lcm import LcmInterfaceSystem, LcmSubscriberSystem
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake import EeCommand, EeState, HsrStationConfig, hsr_initial_ee_state, make_hsr_station
from pbp_drake.builder.run import robot_told_to_hold
from pbp_drake.robots import DriverError, arm_driver
from pbp_drake.cli import main
from pbp_drake.commands import task_runs
from pbp_drake.scenarios import ScenarioError, load_scenario_file, resolve
from pbp_drake.robots.task_space_bridge import (
    STATE_FIELDS, BridgeLink, TaskSpaceBridgeConfig, make_station_relay,
    make_task_space_bridge, read_first_state, signal)

from first_message import FirstMessage
from run_loop import run_loop

PERIOD = 0.1
HSR_REACH = str(pathlib.Path(__file__).resolve().parents[2] / "diagrams" / "hsr_reach.yaml")
SUMMARY = re.compile(r"^hsr_reach \[pbp_alternated, seed 0\]: success in (\S+) s, .*"
                     r"hand at \[(\S+), (\S+), (\S+)\]$", re.MULTILINE)


class Sideways(LeafSystem):
    """The README's controller: the hand to its left at 5 cm/s, from where it is."""

    def __init__(self, start):
        super().__init__()
        self._ee_state = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._heading = start[6]
        command = self.DeclareDiscreteState(start[:EeCommand.size])
        self.DeclareStateOutputPort("ee_command", command)
        self.DeclarePeriodicDiscreteUpdateEvent(PERIOD, 0.0, self._update)

    def _update(self, context, state):
        hand, v = self._ee_state.Eval(context)[:3], np.array([0.0, 0.05, 0.0])
        state.set_value(np.concatenate([hand + v * PERIOD, v, [self._heading]]))


def hand_path(bridged, seconds=2.0):
    station = make_hsr_station(HsrStationConfig(control_period=PERIOD))
    start = hsr_initial_ee_state(station)
    builder = DiagramBuilder()
    if bridged:
        lcm = DrakeLcm("memq://")
        config = TaskSpaceBridgeConfig(connect=True, driver_sim=True)  # the simulation's clock
        builder.AddSystem(make_station_relay(station, lcm, config, start))
        station = builder.AddSystem(make_task_space_bridge(config, start, PERIOD, lcm))
    else:
        station = builder.AddSystem(station)
    controller = builder.AddSystem(Sideways(start))
    builder.Connect(station.GetOutputPort("ee_state"), controller.get_input_port())
    builder.Connect(controller.get_output_port(), station.GetInputPort("ee_command"))
    simulator = Simulator(builder.Build())
    context = station.GetMyContextFromRoot(simulator.get_context())
    path = []
    for tick in range(1, int(round(seconds / PERIOD)) + 1):
        simulator.AdvanceTo(tick * PERIOD)
        path.append(np.array(station.GetOutputPort("ee_state").Eval(context))[:3])
    return np.array(path), start


@pytest.mark.slow
def test_a_controller_drives_the_station_through_the_bridge_a_period_later():
    direct, start = hand_path(bridged=False)
    bridged, _ = hand_path(bridged=True)
    assert direct[-1][1] - start[1] > 0.06  # the hand went left
    # Across the bus the state the controller reads is at most the relay's state period
    # (5 ms) old: the hand moves the same way, at nearly the same speed; it starts at most
    # three ticks later (nothing is sent before the relay's second state has come: the
    # first may be as old as the bus's last handling).
    speed = np.linalg.norm(np.diff(bridged, axis=0), axis=1)[5:] / PERIOD
    np.testing.assert_allclose(speed, 0.05, atol=0.005)
    assert np.abs(bridged[-1] - direct[-1]).max() < 3 * PERIOD * 0.05 + 1e-3


class Sent:
    """The bus as the bridge's link sees it, keeping each command it sends: a Python
    callback on a bus the bridge's LcmInterfaceSystem pumps would be called from inside the
    simulation, which newer Drakes run without Python's lock."""

    def __init__(self, lcm):
        self._lcm, self.commands = lcm, []

    def Publish(self, channel, data):
        self.commands.append(np.array(lcmt_drake_signal.decode(data).val))
        self._lcm.Publish(channel, data)


COMMAND = np.array([0.1, 0.0, 0.0, 0.05, 0.0, 0.0, 0.0])  # [x y z vx vy vz heading]


def bridge_alone(messages, seconds, sent=None, wall_clock=None, **config):
    """The bridge with a constant command, fed `messages(t)` on the state channel, its run
    ended as a command's (`robot_told_to_hold`); the commands it sent are appended to
    `sent` (and returned). On the simulation's clock, or with `wall_clock(t)` on that."""
    lcm, bus = DrakeLcm("memq://"), None
    config = TaskSpaceBridgeConfig(**{"connect": True, "driver_sim": wall_clock is None,
                                      **config})
    builder = DiagramBuilder()
    builder.AddSystem(LcmInterfaceSystem(lcm))
    subscriber = builder.AddSystem(LcmSubscriberSystem.Make(config.state_channel,
                                                            lcmt_drake_signal, lcm))
    bus = Sent(lcm)
    link = builder.AddNamedSystem("bridge_link", BridgeLink(config, bus, np.zeros(8), PERIOD))
    command = builder.AddSystem(ConstantVectorSource(COMMAND))
    builder.Connect(subscriber.get_output_port(), link.GetInputPort("state_message"))
    builder.Connect(command.get_output_port(), link.GetInputPort("ee_command"))
    diagram = builder.Build()
    simulator = Simulator(diagram)
    sent = [] if sent is None else sent
    wall = types.SimpleNamespace(time=lambda: wall_clock(simulator.get_context().get_time()))
    try:
        with robot_told_to_hold(diagram, simulator), mock.patch.object(
                arm_driver, "time", wall if wall_clock else time):
            for tick in range(1, int(round(seconds / PERIOD)) + 1):
                message = messages(tick * PERIOD)
                if message is not None:
                    lcm.Publish(config.state_channel, message.encode())
                simulator.AdvanceTo(tick * PERIOD)
    finally:
        sent.extend(bus.commands)
    return sent


def test_no_relay_ends_the_run_within_its_connect_timeout():
    with pytest.raises(DriverError, match=r"no state from the robot's relay on PBP_EE_STATE "
                                          r"\(bus memq://\) within 0.5 s"):
        bridge_alone(lambda t: None, 2.0, connect_timeout=0.5,
                     lcm_bus=DrakeLcmParams(lcm_url="memq://"))


def test_a_state_of_the_wrong_size_ends_the_run_and_nothing_is_sent():
    sent = []
    with pytest.raises(DriverError, match="holds 7 values"):
        bridge_alone(lambda t: signal(np.zeros(7), list("abcdefg"), t), 1.0, sent)
    assert sent == []


def test_a_hand_away_from_the_start_ends_the_run_and_nothing_is_sent():
    # The bridge was built for a hand at the origin; the robot's stands 6 cm off.
    def hand_at(x):
        return lambda t: signal([x] + [0.0] * 7, STATE_FIELDS, t)

    sent = []
    with pytest.raises(DriverError, match=r"^the robot's hand stands at \[0.060, 0.000, "
                                          r"0.000\] m, 0.060 m from the start the run was "
                                          r"built for, \[0.000, 0.000, 0.000\] m "
                                          r"\(start_tolerance 0.05 m\)"):
        bridge_alone(hand_at(0.06), 1.0, sent)
    assert sent == []
    assert bridge_alone(hand_at(0.04), 0.5)  # within the tolerance, commands go out


def test_the_start_is_checked_on_a_fresh_state_not_on_the_first_the_bus_kept():
    # udpm:// keeps the first state that came since the bus was last handled: at the run's
    # first step, one from when the run was built (the page's wait for Start since), with
    # the hand at the start. The hand has moved since: commands from the start would pull
    # it back in a jump, and the controller would read where it is not.
    sent = []
    with pytest.raises(DriverError, match=r"^the robot's hand stands at \[0.060, 0.000, "):
        bridge_alone(lambda t: signal([0.0 if t < 0.15 else 0.06] + [0.0] * 7, STATE_FIELDS,
                                      t), 1.0, sent)
    assert sent == []


def held(command):
    return np.concatenate([command[:3], [0.0, 0.0, 0.0], command[6:]])


def test_a_run_that_ends_tells_the_robot_to_hold_where_it_was_last_commanded():
    # The relay passes each command on: a last one with a velocity would keep a robot whose
    # controller holds its last input moving once the run is over.
    sent = bridge_alone(lambda t: signal(np.zeros(8), STATE_FIELDS, t), 1.0)
    np.testing.assert_array_equal(sent[0], COMMAND)
    np.testing.assert_array_equal(sent[-1], held(COMMAND))
    sent = []
    with pytest.raises(DriverError, match=r"PBP_EE_STATE .* silent for 0.2\d* s \(at most "
                                          r"0.2 s\): nothing more is sent, the robot is told "
                                          r"to hold$"):
        bridge_alone(lambda t: signal(np.zeros(8), STATE_FIELDS, t) if t < 0.5 else None, 2.0,
                     sent)
    assert len(sent) > 2 and np.array_equal(sent[-1], held(COMMAND))


def test_a_control_loop_ahead_of_the_wall_clock_ends_before_the_robot_is_sent_too_fast():
    # The simulation ahead of the wall clock (the page's real-time rate above 1, or a
    # Simulator of one's own with no rate set): each command's step is the speed bound's in
    # simulated time, so the robot would be driven faster than it.
    sent = []
    with pytest.raises(DriverError, match=r"ran 0.120 s ahead of the wall clock \(at most "
                                          r"0.1 s; the simulator's real-time rate must be 1\): "
                                          r"nothing more is sent, the robot is told to hold$"):
        bridge_alone(lambda t: signal(np.zeros(8), STATE_FIELDS, t), 1.0, sent,
                     wall_clock=lambda t: 1000.0 + 0.7 * t)
    assert len(sent) == 3 and np.array_equal(sent[-1], held(COMMAND))


@pytest.mark.parametrize("field, value, message", [
    ("status_timeout", 0.0, "status_timeout must be finite and positive"),
    ("state_channel", "", "state_channel must be a channel name"),
    ("start_tolerance", float("nan"), "start_tolerance must be finite and positive"),
    ("driver_sim", True, "driver_sim needs connect"),
    ("lcm_bus", DrakeLcmParams(lcm_url="udpm://10.0.0.1:7667"),
     "lcm_bus.lcm_url 'udpm://10.0.0.1:7667' is not an LCM URL"),
])
def test_a_bad_bridge_config_is_refused_naming_the_field(field, value, message):
    with pytest.raises(ValueError, match=f"^TaskSpaceBridgeConfig.{message}"):
        make_task_space_bridge(TaskSpaceBridgeConfig(**{field: value}), np.zeros(8), PERIOD,
                               DrakeLcm("memq://"))


@pytest.mark.parametrize("change, message", [
    ({"initial_ee_state": np.zeros(7)}, r"initial_ee_state must be 8 finite numbers \(an "
                                        r"EeState\), got \[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0\]"),
    ({"initial_ee_state": [np.nan] * 8}, "initial_ee_state must be 8 finite numbers"),
    ({"control_period": 0.0}, "control_period must be positive, got 0.0"),
    ({"control_period": None}, "control_period must be positive, got None"),
    ({"config": None}, "config must be TaskSpaceBridgeConfig, got NoneType"),
])
def test_a_bridge_s_arguments_that_cannot_work_are_refused_by_name(change, message):
    arguments = {"config": TaskSpaceBridgeConfig(), "initial_ee_state": np.zeros(8),
                 "control_period": PERIOD, "lcm": DrakeLcm("memq://"), **change}
    with pytest.raises(ValueError, match=f"^{message}"):
        make_task_space_bridge(**arguments)


@pytest.mark.parametrize("change, message", [
    ({"initial_ee_state": np.zeros(3)}, "initial_ee_state must be 8 finite numbers"),
    ({"state_period": 0.0}, "state_period must be positive, got 0.0"),
    ({"config": None}, "config must be TaskSpaceBridgeConfig, got NoneType"),
    ({"station": None}, r"station must be a Diagram \(a station\), got NoneType"),
])
def test_a_relay_s_arguments_that_cannot_work_are_refused_by_name(change, message):
    arguments = {"station": make_hsr_station(), "lcm": DrakeLcm("memq://"),
                 "config": TaskSpaceBridgeConfig(), "initial_ee_state": np.zeros(8), **change}
    with pytest.raises(ValueError, match=f"^{message}"):
        make_station_relay(**arguments)


def run(*argv, capsys):
    code = main(list(argv))
    return code, capsys.readouterr()


@pytest.mark.slow
def test_the_hsr_task_runs_through_the_bridge_as_it_runs_on_the_station(capsys):
    direct = SUMMARY.search(run("run", HSR_REACH, "--operator", "virtual", "--headless",
                                capsys=capsys)[1].out)
    code, out = run("run", HSR_REACH, "--set", "robot.hardware={}", "--hardware",
                    "--driver-sim", "--operator", "virtual", "--headless", capsys=capsys)
    assert code == 0, out.err
    bridged = SUMMARY.search(out.out)
    assert direct and bridged, out.out
    # A period later on the far side of the bus: the same object, a little later.
    assert 0 <= float(bridged.group(1)) - float(direct.group(1)) < 1.5
    hands = np.array([[float(v) for v in match.groups()[1:]] for match in (direct, bridged)])
    assert np.abs(hands[0] - hands[1]).max() < 0.05


def test_a_run_with_no_relay_is_refused_in_its_connect_timeout_before_it_is_built(capsys):
    # A run longer than the wait: the refusal comes from the wait, not the run's end.
    code, out = run("run", HSR_REACH, "--set", "robot.hardware={lcm_bus: {lcm_url: "
                    "'memq://'}, connect_timeout: 0.3}", "--hardware", "--operator",
                    "virtual", "--headless", "--duration", "30", capsys=capsys)
    assert code == 2
    assert out.err.strip().splitlines() == [
        "pbp-drake: no state from the robot's relay on PBP_EE_STATE (bus memq://) within "
        "0.3 s: is the relay running on that bus?"]
    assert out.out == ""  # nothing ran


def test_the_first_state_is_read_before_a_run_or_refused_with_both_hands():
    config, start = TaskSpaceBridgeConfig(connect=True), np.zeros(8)

    def relay_sending(values):
        return FirstMessage("PBP_EE_STATE", signal(values, STATE_FIELDS, 1.0))

    near = [0.03, 0.0, 0.0, 0.0, 0.0, 0.0, 0.2, 0.0]
    np.testing.assert_array_equal(read_first_state(config, relay_sending(near), start), near)
    with pytest.raises(DriverError, match=r"^the robot's hand stands at \[0.000, 0.060, "
                                          r"0.000\] m, 0.060 m from the start"):
        read_first_state(config, relay_sending([0.0, 0.06] + [0.0] * 6), start)
    with pytest.raises(DriverError, match=r"on PBP_EE_STATE holds 8 values \(EeState's 8, "
                                          r"finite\)"):
        read_first_state(config, relay_sending([np.nan] * 8), start)


@pytest.mark.parametrize("off, code, line", [
    (0.0, 1, "The robot's relay answers on memq://: the hand stands at "),
    (0.06, 2, "pbp-drake: the robot's hand stands at "),
])
def test_a_run_reads_the_relay_s_first_state_before_it_is_built(off, code, line, monkeypatch,
                                                                 capsys):
    # The relay's first state, the hand `off` (m) to the side of the scenario's start.
    start = resolve(load_scenario_file(HSR_REACH).scenario).initial_ee_state
    state = signal(start + np.array([0.0, off] + [0.0] * 6), STATE_FIELDS, 1.0)
    monkeypatch.setattr("pbp_drake.commands.task_runs.DrakeLcm",
                        lambda bus: FirstMessage("PBP_EE_STATE", state))
    # Then no relay answers in the run (memq://): it ends at its time limit, 0.2 s.
    got, out = run("run", HSR_REACH, "--set", "robot.hardware={lcm_bus: {lcm_url: "
                   "'memq://'}}", "--hardware", "--operator", "virtual", "--headless",
                   "--duration", "0.2", capsys=capsys)
    assert got == code
    assert line in (out.out if code == 1 else out.err)
    assert code == 1 or len(out.err.strip().splitlines()) == 1  # one line, no traceback


@pytest.mark.parametrize("scenario, setting, extra, message", [
    ("hsr_reach.yaml", "{lcm_bus: {lcm_url: 'udpm://10.0.0.1:7667'}}", [],
     "scenario.robot.hardware.lcm_bus.lcm_url 'udpm://10.0.0.1:7667' is not an LCM URL"),
    ("hsr_reach.yaml", "{driver_sim: true}", [],
     "scenario.robot.hardware.driver_sim needs connect"),
    ("hsr_reach.yaml", "{status_timeout: -1}", [],
     "scenario.robot.hardware.status_timeout must be finite and positive, got -1.0"),
    ("hsr_obstacles.yaml", "{connect: true}", [],
     "scenario.task !DynamicObstacles needs more of the station"),
    ("hsr_grasp.yaml", "{connect: true}", [],
     "scenario.task !GraspTask needs more of the station"),
    ("hsr_reach.yaml", "{connect: true}", ["--camera", "robot"],
     "--camera robot looks from the simulated HSR's head"),
])
def test_a_bridge_that_cannot_work_is_refused_naming_the_field(scenario, setting, extra,
                                                               message, capsys):
    path = str(pathlib.Path(HSR_REACH).with_name(scenario))
    code, out = run("run", path, "--set", f"robot.hardware={setting}", "--operator",
                    "virtual", *extra, capsys=capsys)
    assert code == 2
    assert message in out.err and len(out.err.strip().splitlines()) == 1, out.err


def test_a_study_does_not_drive_a_real_robot_through_the_bridge(tmp_path, capsys):
    code, out = run("study", HSR_REACH, "--set", "robot.hardware={connect: true}",
                    "--output", str(tmp_path / "study"), capsys=capsys)
    assert code == 2
    assert "a study runs its trials unattended in simulation" in out.err
    assert not (tmp_path / "study").exists()


def test_driver_sim_runs_the_hsr_behind_its_relay_on_the_bus(capsys):
    code, out = run("driver-sim", HSR_REACH, "--set", "robot.hardware={lcm_bus: {lcm_url: "
                    "'memq://'}}", "--duration", "0.2", capsys=capsys)
    assert code == 0, out.err
    assert out.out == ("driver-sim: the HSR's relay reads PBP_EE_COMMAND and sends "
                       "PBP_EE_STATE every 5 ms on memq://; Ctrl-C ends it\n")


@pytest.mark.parametrize("choice", ["restart", "next"])
def test_restart_and_next_scene_say_where_the_robot_s_hand_must_be_brought(choice, monkeypatch):
    # The scenario's start is fixed, and the hand ended the run elsewhere: the next run was
    # built for the start and ended at its first fresh state, exit 5, after Start.
    scenario = load_scenario_file(HSR_REACH).scenario
    scenario = dataclasses.replace(scenario, robot=dataclasses.replace(
        scenario.robot, hardware=TaskSpaceBridgeConfig(connect=True)))
    start = resolve(scenario).initial_ee_state
    state = signal(start + np.array([0.1] + [0.0] * 7), STATE_FIELDS, 1.0)
    monkeypatch.setattr(task_runs, "DrakeLcm", lambda bus: FirstMessage("PBP_EE_STATE", state))
    built = []
    with pytest.raises(ScenarioError, match=r"^the robot's hand stands at \[.*\] m, 0.100 m "
                                            r"from the start the run was built for, \[.*\] m "
                                            r"\(start_tolerance 0.05 m\): bring it there first"):
        run_loop(monkeypatch, resolve(scenario), [choice, "stop"],
                 lambda resolved: built.append(resolved.scenario.seed))
    assert built == [scenario.seed]  # the next run is not built
