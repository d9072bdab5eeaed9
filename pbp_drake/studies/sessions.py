"""A person's session of a user study: every method once, in a counterbalanced order, saved
in the study runner's format (one folder per participant; `pbp-drake report` reads it)."""

import hashlib
import re

from pbp_drake.studies.comparison import run_method_comparison

DEFAULT_SESSION_METHODS = ("pbp_alternated", "pbp_continuous", "teleop")


def participant_number(participant):
    """The number that places a participant in the counterbalancing: the ID's last digits
    (P07 -> 7), else a stable hash of the ID."""
    if not participant or not re.fullmatch(r"[A-Za-z0-9_.-]+", participant):
        raise ValueError(f"participant ID {participant!r} must be letters, digits, '_', '.' or "
                         "'-' (it names a folder)")
    digits = re.search(r"(\d+)$", participant)
    if digits:
        return int(digits.group(1))
    return int(hashlib.sha256(participant.encode()).hexdigest()[:8], 16)


def session_order(methods, participant):
    """The methods rotated by the participant's number: a cyclic Latin square, so that over
    every `len(methods)` consecutive participants each method comes once in each place."""
    methods = list(methods)
    shift = participant_number(participant) % len(methods)
    return methods[shift:] + methods[:shift]


def run_session(scenario, participant, methods, output, run, progress=None):
    """Runs `run(scenario)` (one task, e.g. driven from the browser) for each method in the
    participant's order, all on the scenario's seed, and saves each as a trial under
    `output`. Returns the summary of the session."""
    order = session_order(methods, participant)
    return run_method_comparison(scenario, order, 1, scenario.seed, output, progress=progress,
                                 run=run)
