"""A person's session of a user study: every method once, in a counterbalanced order, saved
as a study's trials in the participant's folder, with the paper's questionnaire after each
method (`questionnaire.json`) and optional practice runs (`practice/`, never counted). A
session that stops resumes with the same command, rewriting no saved run or answer
(docs/user-study.md, "Files and resuming").
"""

import hashlib
import pathlib
import re

from pbp_drake.studies.comparison import run_method_comparison
from pbp_drake.studies.folders import check_folder
from pbp_drake.studies.questionnaire import QUESTIONS, read_answers, save_answer
from pbp_drake.studies.trial_files import read_trial, scenario_hash

DEFAULT_SESSION_METHODS = ("pbp_alternated", "pbp_continuous", "teleop")
# Practice runs use other scenes than the recorded ones (seed + this), so that practice does
# not rehearse the very scene that is measured.
PRACTICE_SEED_OFFSET = 1000
PRACTICE_FOLDER = "practice"


def participant_number(participant):
    """The number that places a participant in the counterbalancing: the ID's last digits
    (P07 -> 7), else a stable hash of the ID. Raises ValueError for an ID that cannot name
    a folder."""
    if participant and ("/" in participant or "\\" in participant):
        raise ValueError(f"participant ID {participant!r} holds a path separator; the ID "
                         "names the participant's folder, so it must be a plain name such "
                         "as P07")
    if (not participant or not re.fullmatch(r"[A-Za-z0-9_.-]+", participant)
            or set(participant) == {"."}):
        raise ValueError(f"participant ID {participant!r} must be letters, digits, '_', '.' or "
                         "'-', and not only dots (it names a folder)")
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


def run_session(scenario, participant, methods, output, run, page, practice=False):
    """Runs `run(scenario)` for each method in the participant's order, on the scenario's
    seed, saving each as a trial under `output`. `page` (console.questionnaire's Meshcat
    page or FixedAnswers) shows each method's Start and asks the questionnaire once its
    trial is saved. `practice`: first one run of each method on other scenes, under
    `output/practice` (skipped once recorded runs exist). Returns the session's summary."""
    order = session_order(methods, participant)
    output = pathlib.Path(output)
    digest = scenario_hash(scenario)
    # Before any run: a folder of another scenario, or a damaged questionnaire, stops here.
    check_folder(output, scenario, digest)
    read_answers(output)
    practice_folder = output / PRACTICE_FOLDER
    practice_seed = scenario.seed + PRACTICE_SEED_OFFSET

    def unsaved(folder, seed):
        return [m for m in order if read_trial(folder, m, seed, digest) is None]

    def start_next(folder, seed, practising):
        # Start is shown between trials, not inside `run`: the trial's wall_time is then
        # the run's, not the person's pause before it.
        waiting = unsaved(folder, seed)
        if waiting:
            page.start(waiting[0], order.index(waiting[0]) + 1, len(order), practising)

    def ask_unanswered():
        # Every saved method without all its answers, in order: the run just saved, and,
        # on resuming, one whose questions were cut short.
        waiting = unsaved(output, scenario.seed)
        for position, method in enumerate(order, start=1):
            if method in waiting:
                continue
            answered = read_answers(output).get(method, {})
            missing = [q for q in QUESTIONS if q not in answered]
            for question in missing:
                save_answer(output, method, question, page.answer(method, question))
            if missing and position < len(order) and order[position] in waiting:
                page.next(position + 1, len(order))

    def after_practice_run(done, total, record, elapsed):
        start_next(practice_folder, practice_seed, True)

    def after_run(done, total, record, elapsed):
        ask_unanswered()
        start_next(output, scenario.seed, False)

    if practice and len(unsaved(output, scenario.seed)) == len(order):
        start_next(practice_folder, practice_seed, True)
        run_method_comparison(scenario, order, 1, practice_seed, practice_folder,
                              progress=after_practice_run, split="practice", run=run)
    ask_unanswered()
    start_next(output, scenario.seed, False)
    return run_method_comparison(scenario, order, 1, scenario.seed, output,
                                 progress=after_run, run=run)
