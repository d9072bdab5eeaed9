"""`pbp-drake driver-sim FILE`: the arm of a scenario file behind its Drake LCM driver's
channels and rules, in real time on the file's bus, so that `pbp-drake run FILE --hardware`
in another terminal drives it with no robot (`pbp_drake.robots.driver_sim`)."""

import math
import sys

from pydrake.lcm import DrakeLcm
from pydrake.systems.analysis import Simulator

from pbp_drake.cli_types import EXIT_DRIVER, EXIT_SUCCESS
from pbp_drake.commands.scenario_flags import add_override_flags, scenario_overrides
from pbp_drake.robots import ArmStationConfig, arm_driver_sim
from pbp_drake.robots.arm_station_config import DRIVERS
from pbp_drake.robots.driver_sim import DriverSimError
from pbp_drake.scenarios import ScenarioError, load_scenario_file


def add_driver_sim_command(commands):
    """The `driver-sim` subcommand and its arguments."""
    parser = commands.add_parser(
        "driver-sim", help="simulate an arm's Drake LCM driver (the file's robot.hardware) "
        "in real time on its bus, for `pbp-drake run FILE --hardware` with no robot")
    parser.add_argument("scenario", help="an arm's scenario file with robot.hardware, e.g. "
                        "diagrams/panda_reach.yaml")
    add_override_flags(parser)
    parser.add_argument("--duration", type=float, metavar="SECONDS",
                        help="end after this many seconds (default: at Ctrl-C)")
    parser.set_defaults(handler=_driver_sim)


def _driver_sim(args):
    if args.duration is not None and not args.duration > 0:
        raise ScenarioError(f"--duration must be positive, got {args.duration:g}")
    robot = load_scenario_file(args.scenario, scenario_overrides(args, shorthands=False)
                               ).scenario.robot
    if not isinstance(robot, ArmStationConfig) or robot.hardware is None:
        raise ScenarioError("driver-sim simulates an arm's driver: the scenario's robot must "
                            "be !Arm with hardware: {driver: panda} or {driver: iiwa}")
    hardware = robot.hardware
    driver = DRIVERS[hardware.driver]
    simulator = Simulator(arm_driver_sim(robot.station_config(), DrakeLcm(hardware.lcm_bus)))
    simulator.set_target_realtime_rate(1.0)
    simulator.Initialize()
    print(f"driver-sim: the {hardware.driver} driver reads {driver.command_channel} and "
          f"sends {driver.status_channel} every {driver.period * 1000:g} ms on "
          f"{hardware.lcm_bus.lcm_url}; Ctrl-C ends it", flush=True)
    try:
        simulator.AdvanceTo(math.inf if args.duration is None else args.duration)
    except DriverSimError as error:
        print(f"pbp-drake driver-sim: {error}", file=sys.stderr)
        return EXIT_DRIVER
    return EXIT_SUCCESS
