"""An operator that replays a time series of commands (open-loop input, e.g. Fig. 4)."""

import numpy as np

from pbp_drake.systems.operators.sampled_operator import SampledOperator


class ScriptedOperator(SampledOperator):
    """Plays back commands `(T, D)` given at `times` `(T,)`, held until the next sample.

    .. pydrake_system::

        name: ScriptedOperator
        output_ports:
        - operator_command
        - operator_active

    Before the first time and after the last, the command is the first/last sample. The
    operator counts as active whenever its command is nonzero.
    """

    def __init__(self, times, commands, control_period):
        times, commands = checked_script(times, commands)
        super().__init__(commands.shape[1], control_period)
        self._times = times
        self._commands = commands
        self._declare_operator_outputs()

    def _sample(self, context):
        index = max(0, int(np.searchsorted(self._times, context.get_time(), side="right")) - 1)
        command = self._commands[index]
        return command, bool(np.any(command != 0.0))


def checked_script(times, commands):
    """`times` `(T,)` and `commands` `(T, D)` (`(T,)`: D = 1) as float arrays; ValueError
    naming `times` or `commands` unless they can be played back."""
    times = np.asarray(times, dtype=float).reshape(-1)
    commands = np.asarray(commands, dtype=float)
    if commands.ndim == 1:
        commands = commands[:, np.newaxis]
    if times.size == 0 or commands.shape[0] != times.size:
        raise ValueError(f"commands: {commands.shape[0]} for {times.size} times; expected one "
                         "command per time")
    if not np.isfinite(commands).all():
        raise ValueError("commands contain NaN or infinite values")
    if not np.isfinite(times).all() or (np.diff(times) <= 0).any():
        raise ValueError(f"times {times.tolist()} do not increase; expected finite times (s) "
                         "that increase strictly, each command held from its time until the "
                         "next")
    return times, commands
