"""The operator system of a surrogate pilot (`pbp_drake.scenarios.pilots`) in any task: the
noisy and laggy pilots are the task's virtual participant with a filter after it
(`PilotOperator`), the population's is the participant drawn for the trial's seed, and
HOP's simulated user is a `ProportionalOperator`. None reads the scenario's method (the
keys reach them through the `forward_key` port).
"""

import dataclasses

from pbp_drake.core.pilot_population import drawn_participant
from pbp_drake.scenarios import (
    LaggyPilot, NoisyPilot, ProportionalPilot, VirtualParticipant)
from pbp_drake.systems.operators.pilot_filters import (
    LaggyFilter, NoisyFilter, PilotOperator, ProportionalOperator)
from pbp_drake.systems.operators.sampled_operator import operator_speed


def make_pilot(resolved, make_participant, make_keys, obstacle_count=0):
    """The operator system of the resolved scenario's pilot config.

    `make_participant(resolved)` builds the task's virtual participant for a resolved
    scenario whose operator is one; `make_keys(speed, rotation_speed)` the task's keys
    (`ReachKeys` or `GraspKeys`) at those speeds; `obstacle_count` is how many obstacles
    the participant watches (its `obstacle_positions` port)."""
    scenario = resolved.scenario
    config = scenario.operator
    period, seed, nominal_speed = scenario.control_period, scenario.seed, resolved.nominal_speed

    def participant(params):
        """The task's virtual participant of `params` (`VirtualParticipantParams`)."""
        virtual = VirtualParticipant(**{field.name: getattr(params, field.name)
                                        for field in dataclasses.fields(params)})
        return make_participant(dataclasses.replace(
            resolved, scenario=dataclasses.replace(scenario, operator=virtual)))

    def keys(params):
        return make_keys(operator_speed(params.speed, nominal_speed), params.rotation_speed)

    if isinstance(config, NoisyPilot):
        return PilotOperator(participant(config.participant), NoisyFilter(
            keys(config.participant), period, seed, config.eps))
    if isinstance(config, LaggyPilot):
        return PilotOperator(participant(config.participant), LaggyFilter(
            keys(config.participant), period, seed, config.p))
    if isinstance(config, ProportionalPilot):
        # Its keys' layout only: it moves at `max_speed` (0: the task's operator speed).
        return ProportionalOperator(
            make_keys(nominal_speed, 0.0), period, config,
            operator_speed(config.max_speed, nominal_speed), obstacle_count)
    # The last of PILOT_CONFIGS (`ParticipantPopulation`): the callers pass no other config.
    base = config.participant
    return participant(drawn_participant(
        config, seed, operator_speed(base.speed, nominal_speed)))
