"""The registry of surrogate pilots: the operators a study runs every method under
(`pbp-drake study --pilots ...`, docs/concepts/pilots.md), by name. ``attentive`` is the
scenario's own virtual participant; each other pilot is a tagged operator config of the
schema, its defaults based on that participant (`with_pilot`).
"""

import copy
import dataclasses

from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.choices import unknown_choice
from pbp_drake.scenarios.schema import (
    LaggyPilot, NoisyPilot, ParticipantPopulation, ProportionalPilot, ScenarioError,
    VirtualParticipant)

#: The scenario's own participant, unchanged.
ATTENTIVE = "attentive"


#: Pilot name -> its config with its defaults, from the scenario's participant
#: (`VirtualParticipantParams`).
PILOTS = {
    "noisy": lambda participant: NoisyPilot(participant=participant),
    "laggy": lambda participant: LaggyPilot(participant=participant),
    # HOP's user moves at the participant's speed (0: the task's operator speed).
    "proportional": lambda participant: ProportionalPilot(max_speed=participant.speed),
    "population": lambda participant: ParticipantPopulation(participant=participant),
}
#: The names `pbp-drake study --pilots` takes, `attentive` first.
PILOT_NAMES = (ATTENTIVE, *PILOTS)


def participant_params(participant):
    """A plain `VirtualParticipantParams` copy of `participant` (a `!VirtualParticipant`
    config or the params themselves): what a pilot's `participant:` field holds."""
    return VirtualParticipantParams(**{
        field.name: copy.deepcopy(getattr(participant, field.name))
        for field in dataclasses.fields(VirtualParticipantParams)})


def check_pilot_name(name, field="pilot"):
    """Raises ScenarioError unless `name` is one of PILOT_NAMES (with did-you-mean)."""
    if name not in PILOT_NAMES:
        raise ScenarioError(unknown_choice(field, name, PILOT_NAMES))


def with_pilot(scenario, name):
    """A copy of `scenario` whose operator is the pilot `name` with its defaults, based on
    the scenario's own `!VirtualParticipant` params; `attentive` returns `scenario`
    itself. Raises ScenarioError for an unknown name (did-you-mean) or a scenario whose
    operator is not the virtual participant."""
    check_pilot_name(name)
    if name == ATTENTIVE:
        return scenario
    operator = scenario.operator
    if not isinstance(operator, VirtualParticipant):
        raise ScenarioError(
            f"pilot {name!r} stands in for the virtual participant: scenario.operator is "
            f"!{type(operator).__name__}; expected !VirtualParticipant")
    config = PILOTS[name](participant_params(operator))
    return dataclasses.replace(scenario, operator=config)
