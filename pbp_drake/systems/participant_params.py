"""Where `VirtualParticipantParams` used to live: it is pure data, shared by the reach and
the grasp participants, and now lives in `pbp_drake.core.participant_params`."""

from pbp_drake.core.participant_params import VirtualParticipantParams

__all__ = ["VirtualParticipantParams"]
