"""The blender: how the operator's command and the robot policy become the robot's command
(`Blender`, and `BlenderBase`, its part shared with the six-DoF `PoseBlender`)."""

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from pbp_drake.core.arbitration import (
    BLEND_LAWS, CONFIDENCE_WEIGHT, DEFAULT_ALPHA_MAX, DEFAULT_CONFIDENCE_HIGH,
    DEFAULT_CONFIDENCE_LOW, FIXED_WEIGHT, blend, check_alpha, confidence_alpha,
    validate_confidence_ramp, validate_mode)
from pbp_drake.systems.ports import PortGetters, checked_count, goal_index
from pbp_drake.systems.tick import checked_period


class BlenderBase(PortGetters, LeafSystem):
    """What `Blender` and `PoseBlender` share: the blending mode, the ramp of
    `confidence_alpha` (`confidence_range`, `alpha_max`) and the weight of `fixed_alpha`, a
    numeric parameter of the Context so that it can change during a run (`set_alpha`).

    A subclass declares its ports, among them `_selected_goal_port` and
    `_goal_probabilities_port`, which `alpha` reads, and names its modes' laws (`_laws`)
    and the goal estimator that feeds it (`_estimator_name`).
    """

    _laws = BLEND_LAWS
    _estimator_name = "GoalEstimator"

    def __init__(self, mode, goal_count, control_period, alpha, confidence_range, alpha_max):
        super().__init__()
        validate_mode(mode, alpha, self._laws)
        try:
            low, high = confidence_range
        except (TypeError, ValueError):
            raise ValueError(f"confidence_range must be a pair (confidence_low, "
                             f"confidence_high), got {confidence_range!r}") from None
        validate_confidence_ramp(low, high, alpha_max)
        self._mode = mode
        self._weight = self._laws[mode].weight
        self._confidence_range = (float(low), float(high))
        self._alpha_max = float(alpha_max)
        self._goal_count = checked_count(goal_count, "goal_count")
        self._period = checked_period(control_period)
        # A Context parameter, not a Python attribute: a live change (set_alpha) then
        # belongs to one Context and invalidates the cached output.
        self._alpha_index = (self.DeclareNumericParameter(BasicVector([float(alpha)]))
                             if self._weight == FIXED_WEIGHT else None)

    @property
    def mode(self):
        return self._mode

    @property
    def confidence_range(self):
        return self._confidence_range

    @property
    def alpha_max(self):
        return self._alpha_max

    def alpha(self, context):
        """The arbitration weight used in `context`: `alpha` for `fixed_alpha`, the ramp of
        the goal confidence for `confidence_alpha`, None for the other modes."""
        if self._alpha_index is not None:
            return float(context.get_numeric_parameter(self._alpha_index)[0])
        if self._weight != CONFIDENCE_WEIGHT:
            return None
        if not self._goal_probabilities_port.HasValue(context):
            raise RuntimeError(
                f"{type(self).__name__} in confidence_alpha mode needs its goal_probabilities "
                f"input port connected (e.g. to {self._estimator_name}'s goal_probabilities "
                f"output)")
        return confidence_alpha(self._goal_probabilities_port.Eval(context),
                                self._selected_goal(context), *self._confidence_range,
                                self._alpha_max)

    def set_alpha(self, context, alpha):
        """Sets the weight of `fixed_alpha` in this system's `context` (from the next
        evaluation of the output on). Raises ValueError outside [0, 1] or in another mode."""
        if self._alpha_index is None:
            raise ValueError(f"alpha is a weight of fixed_alpha; this blender is {self._mode}")
        check_alpha(self._mode, alpha)
        context.get_mutable_numeric_parameter(self._alpha_index).SetAtIndex(0, float(alpha))

    def _selected_goal(self, context):
        return goal_index(self._selected_goal_port, context, self._goal_count, unconnected=0)


class Blender(BlenderBase):
    """Mixes the operator into the selected policy reference by one of the blending laws.

    .. pydrake_system::

        name: Blender
        input_ports:
        - robot_state
        - references (optional)
        - policy_reference (optional)
        - selected_goal (optional)
        - operator_command
        - operator_active
        - goal_probabilities (optional)
        output_ports:
        - command

    The modes are `pbp_drake.core.arbitration.BLEND_MODES` (the laws: that module's
    docstring). `robot_state` must be the state sampled at the control tick; `references`
    holds K next states and `selected_goal` picks one (goal 0 when unconnected), unless
    `policy_reference` (`DmpBank.selected_reference`) is connected, which is then followed.
    The output is `[position (D), velocity (D)]`. A NaN or infinite operator command
    raises. `goal_probabilities` (K) is read only in `confidence_alpha` mode, where it must
    be connected.
    """

    def __init__(self, mode, dimension, goal_count, control_period, alpha=None, *,
                 confidence_range=(DEFAULT_CONFIDENCE_LOW, DEFAULT_CONFIDENCE_HIGH),
                 alpha_max=DEFAULT_ALPHA_MAX):
        super().__init__(mode, goal_count, control_period, alpha, confidence_range, alpha_max)
        self._dimension = checked_count(dimension, "dimension")
        d, k = self._dimension, self._goal_count
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", 2 * d)
        self._references_port = self.DeclareVectorInputPort("references", 2 * k * d)
        self._policy_reference_port = self.DeclareVectorInputPort("policy_reference", 2 * d)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._operator_command_port = self.DeclareVectorInputPort("operator_command", d)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._goal_probabilities_port = self.DeclareVectorInputPort("goal_probabilities", k)
        # A function of the inputs (and alpha) alone: not redone between control ticks.
        self._command_port = self.DeclareVectorOutputPort(
            "command", 2 * d, self._calc_command,
            prerequisites_of_calc={self.all_input_ports_ticket(),
                                   self.all_parameters_ticket()})

    def _calc_command(self, context, output):
        d, k = self._dimension, self._goal_count
        selected = self._selected_goal(context)
        # Computed (and the port checked) even while the operator is idle, when the law
        # plays P: a missing goal_probabilities connection fails at the first tick.
        alpha = self.alpha(context)
        if self._policy_reference_port.HasValue(context):
            reference = self._policy_reference_port.Eval(context).reshape(2, d)
        else:
            reference = self._references_port.Eval(context).reshape(2, k, d)[:, selected]
        position, velocity = blend(
            self._mode,
            self._robot_state_port.Eval(context)[:d],
            reference[0],
            reference[1],
            self._operator_command_port.Eval(context),
            self._operator_active_port.Eval(context)[0] > 0.5,
            self._period,
            alpha,
        )
        output.SetFromVector(np.concatenate([position, velocity]))
