"""`pbp-drake driver-sim FILE`: the robot of a scenario file in real time on the file's
bus, so that `pbp-drake run FILE --hardware` in another terminal drives it with no robot:
an arm behind its Drake LCM driver's channels and rules (`pbp_drake.robots.driver_sim`),
the HSR behind the task-space bridge's relay (`pbp_drake.robots.task_space_bridge`)."""

import math
import sys

from pydrake.lcm import DrakeLcm
from pydrake.systems.analysis import Simulator

from pbp_drake.cli_types import EXIT_DRIVER, EXIT_SUCCESS
from pbp_drake.commands.scenario_flags import add_override_flags, scenario_overrides
from pbp_drake.robots import ArmStationConfig, arm_driver_sim, make_hsr_station
from pbp_drake.robots.arm_station_config import DRIVERS
from pbp_drake.robots.driver_sim import DriverSimError
from pbp_drake.robots.task_space_bridge import RELAY_STATE_PERIOD, make_station_relay
from pbp_drake.scenarios import ScenarioError, load_scenario_file


def add_driver_sim_command(commands):
    """The `driver-sim` subcommand and its arguments."""
    parser = commands.add_parser(
        "driver-sim", help="simulate an arm's Drake LCM driver, or the HSR behind the "
        "task-space bridge's relay (the file's robot.hardware), in real time on its bus, "
        "for `pbp-drake run FILE --hardware` with no robot")
    parser.add_argument("scenario", help="a scenario file with robot.hardware, e.g. "
                        "diagrams/panda_reach.yaml")
    add_override_flags(parser)
    parser.add_argument("--duration", type=float, metavar="SECONDS",
                        help="end after this many seconds (default: at Ctrl-C)")
    parser.set_defaults(handler=_driver_sim)


def _driver_sim(args):
    if args.duration is not None and not args.duration > 0:
        raise ScenarioError(f"--duration must be positive, got {args.duration:g}")
    scenario_file = load_scenario_file(args.scenario, scenario_overrides(args, shorthands=False))
    robot = scenario_file.scenario.robot
    hardware = getattr(robot, "hardware", None)
    if hardware is None:
        raise ScenarioError("driver-sim simulates the robot on the far side of its bus: the "
                            "scenario's robot needs hardware: !Arm's {driver: panda} or "
                            "{driver: iiwa}, or !Hsr's {} (the task-space bridge)")
    if isinstance(robot, ArmStationConfig):
        driver = DRIVERS[hardware.driver]
        system = arm_driver_sim(robot.station_config(), DrakeLcm(hardware.lcm_bus))
        what = (f"the {hardware.driver} driver reads {driver.command_channel} and sends "
                f"{driver.status_channel} every {driver.period * 1000:g} ms")
    else:
        resolved = scenario_file.resolved
        system = make_station_relay(make_hsr_station(resolved.station),
                                    DrakeLcm(hardware.lcm_bus), hardware,
                                    resolved.initial_ee_state)
        what = (f"the HSR's relay reads {hardware.command_channel} and sends "
                f"{hardware.state_channel} every {RELAY_STATE_PERIOD * 1000:g} ms")
    simulator = Simulator(system)
    simulator.set_target_realtime_rate(1.0)
    simulator.Initialize()
    print(f"driver-sim: {what} on {hardware.lcm_bus.lcm_url}; Ctrl-C ends it", flush=True)
    try:
        simulator.AdvanceTo(math.inf if args.duration is None else args.duration)
    except DriverSimError as error:
        print(f"pbp-drake driver-sim: {error}", file=sys.stderr)
        return EXIT_DRIVER
    return EXIT_SUCCESS
