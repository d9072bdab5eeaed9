"""A lone `VirtualOperator` whose inputs a test sets each tick, the hand moved by hand (the
participant tests of `core/`)."""

import numpy as np
from pydrake.systems.analysis import Simulator

from pbp_drake.systems import VirtualOperator


class Participant:
    """A `VirtualOperator` (`period`, `speed`, its other arguments in `kwargs`) seeing
    `objects` (M, 3), `target_index` the target and `selected` the estimate, the hand at
    `start` heading along +x."""

    def __init__(self, objects, target_index, selected=0, *, period, speed, start,
                 **kwargs):
        self.period = period
        self.system = VirtualOperator(period, objects, nominal_speed=speed, seed=7, **kwargs)
        self.simulator = Simulator(self.system)
        self.context = self.simulator.get_mutable_context()
        self.objects = np.asarray(objects, float)
        self.target_index = target_index
        self.system.get_target_input_port().FixValue(
            self.context, [*self.objects[target_index], target_index])
        self.select(selected)
        self.move_to(start)
        self.ticks = 0

    def select(self, selected):
        """The estimate names object `selected` from now on."""
        self.system.get_selected_goal_input_port().FixValue(self.context, [selected])

    def move_to(self, position, heading=0.0):
        self.position, self.heading = np.asarray(position, float), float(heading)
        self.system.get_ee_state_input_port().FixValue(
            self.context, [*self.position, 0, 0, 0, self.heading, 0.0])

    def tick(self):
        """The command of the next control tick."""
        self.ticks += 1
        self.simulator.AdvanceTo((self.ticks - 0.5) * self.period)
        return np.array(self.system.get_operator_command_output_port().Eval(self.context))

    def follow(self, ticks):
        """The commands of `ticks` ticks, the hand moved by each."""
        commands = []
        for _ in range(ticks):
            command = self.tick()
            commands.append(command)
            self.move_to(self.position + self.period * command[:3],
                         self.heading + self.period * command[3])
        return np.array(commands)
