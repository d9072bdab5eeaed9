"""A lone `VirtualOperator` whose inputs a test sets each tick, the hand moved by hand (the
participant tests of `core/`)."""

import numpy as np
from pydrake.systems.analysis import Simulator

from pbp_drake.systems import VirtualOperator


class Participant:
    """A `VirtualOperator` (`period`, `speed`, its other arguments in `kwargs`) seeing
    `objects` (M, 3), `target_index` the target and `selected` the robot's shown intent
    (`NO_INTENT`, -1: the method shows none), the forward key enabled (`forward_key`: the
    method's keys, as teleop's) or not (as PBP's), the hand at `start` heading along +x."""

    def __init__(self, objects, target_index, selected=0, *, period, speed, start,
                 forward_key=False, **kwargs):
        self.period = period
        self.system = VirtualOperator(period, objects, nominal_speed=speed, seed=7, **kwargs)
        self.simulator = Simulator(self.system)
        self.context = self.simulator.get_mutable_context()
        self.objects = np.asarray(objects, float)
        self.target_index = target_index
        self.system.get_target_input_port().FixValue(
            self.context, [*self.objects[target_index], target_index])
        self.system.get_forward_key_input_port().FixValue(
            self.context, [1.0 if forward_key else 0.0])
        self.select(selected)
        self.move_to(start)
        self.ticks = 0

    def select(self, selected):
        """The robot shows it means object `selected` from now on (`NO_INTENT`: none)."""
        self.system.get_selected_goal_input_port().FixValue(self.context, [selected])

    def move_to(self, position, heading=0.0, velocity=(0.0, 0.0, 0.0), heading_rate=0.0):
        """The hand at `position` and `heading`, moving at `velocity` (3) and turning at
        `heading_rate` (still by default: held where it is)."""
        self.position, self.heading = np.asarray(position, float), float(heading)
        self.system.get_ee_state_input_port().FixValue(
            self.context, [*self.position, *velocity, self.heading, float(heading_rate)])

    def tick(self):
        """The command of the next control tick."""
        self.ticks += 1
        self.simulator.AdvanceTo((self.ticks - 0.5) * self.period)
        return np.array(self.system.get_operator_command_output_port().Eval(self.context))

    def follow(self, ticks):
        """The commands of `ticks` ticks, the hand moved by each as the robot would move it
        (and moving at it: the robot adds nothing of its own)."""
        commands = []
        for _ in range(ticks):
            command = self.tick()
            commands.append(command)
            self.move_to(self.position + self.period * command[:3],
                         self.heading + self.period * command[3], command[:3], command[3])
        return np.array(commands)
