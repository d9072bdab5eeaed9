"""Base of every operator system: a command sampled into discrete state each control tick."""

import math

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.arbitration import validate_command
from pbp_drake.core.coordinates import is_real
from pbp_drake.systems.ports import PortGetters, checked_count
from pbp_drake.systems.tick import SENSE_OFFSET, checked_period


def operator_speed(speed, nominal_speed):
    """The speed (m/s) an HSR operator moves the hand at: `speed`, or where that is 0 (its
    parameters' default) the task's nominal speed, the speed of its DMPs."""
    chosen = speed or nominal_speed
    if not (is_real(chosen) and math.isfinite(chosen) and chosen > 0):
        raise ValueError(f"the operator's speed must be positive: got speed {speed!r} and "
                         f"nominal_speed {nominal_speed!r} (speed 0 takes nominal_speed)")
    return float(chosen)


class SampledOperator(PortGetters, LeafSystem):
    """An operator whose command is sampled at the control ticks and held in between.

    .. pydrake_system::

        name: SampledOperator
        output_ports:
        - operator_command
        - operator_active

    Subclasses implement `_sample(context) -> (command (D,), active)`, may declare input
    ports first, and call `_declare_operator_outputs()` once (`delay_ticks` > 0: each
    sample reaches the outputs that many ticks later, through a queue in discrete state).
    It samples at the sense stage of each tick (or at `offset`). `operator_command` is a
    velocity (D; named `command_name`); `operator_active` is 1 while the operator acts.
    """

    def __init__(self, dimension, control_period, command_name="operator_command"):
        super().__init__()
        self._dimension = checked_count(dimension, "dimension")
        self._period = checked_period(control_period)
        self._command_name = command_name

    def _declare_operator_outputs(self, delay_ticks=0, offset=SENSE_OFFSET):
        d = self._dimension
        self._sample_index = self.DeclareDiscreteState(d + 1)
        self._delay_ticks = int(delay_ticks)
        if self._delay_ticks < 0:
            raise ValueError(f"delay_ticks must not be negative, got {delay_ticks}")
        if self._delay_ticks > 0:
            # The samples taken but not yet sent, oldest first; before the start: idle.
            self._queue_index = self.DeclareDiscreteState(self._delay_ticks * (d + 1))
        # Both outputs depend on the held sample alone (no direct feedthrough), so an
        # operator may watch systems that depend on its own output.
        held = {self.discrete_state_ticket(self._sample_index)}
        self._command_port = self.DeclareVectorOutputPort(
            self._command_name, d,
            lambda context, output: output.SetFromVector(self._held(context)[:d]),
            prerequisites_of_calc=held)
        self.DeclareVectorOutputPort(
            "operator_active", 1,
            lambda context, output: output.SetFromVector(self._held(context)[d:]),
            prerequisites_of_calc=held)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, offset, self._update)

    def get_operator_command_output_port(self):
        return self._command_port

    def _held(self, context):
        """The sample the outputs hold: what the robot gets."""
        return context.get_discrete_state(self._sample_index).value()

    def _latest(self, context):
        """The newest sample taken (the held one unless samples are delayed)."""
        if self._delay_ticks == 0:
            return self._held(context)
        return context.get_discrete_state(self._queue_index).value()[-(self._dimension + 1):]

    def _update(self, context, discrete_state):
        command, active = self._sample(context)
        self._store_sample(discrete_state, command, active)

    def _store_sample(self, discrete_state, command, active):
        """Writes one sample; subclasses that override `_update` call this."""
        command = self._validate(np.asarray(command, float).reshape(self._dimension))
        sample = np.append(command, 1.0 if active else 0.0)
        if self._delay_ticks > 0:
            queue = np.append(discrete_state.get_vector(self._queue_index).value(), sample)
            sample, queue = queue[:self._dimension + 1], queue[self._dimension + 1:]
            discrete_state.set_value(self._queue_index, queue)
        discrete_state.set_value(self._sample_index, sample)

    def _validate(self, command):
        """The command checked (NaN or infinite refused by name), as a float array."""
        return validate_command(command, self._command_name)
