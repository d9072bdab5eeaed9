"""A person's session of a user study: every method once, in a counterbalanced order, saved
as a study's trials in the participant's folder, with the paper's questionnaire after each
method (`questionnaire.json`) and optional practice runs (`practice/`, never counted). A
session that stops resumes with the same command, rewriting no saved run or answer
(docs/user-study.md, "Files and resuming").
"""

import hashlib
import pathlib
import re
import typing

from pbp_drake.studies.comparison import run_method_comparison
from pbp_drake.studies.folders import check_folder
from pbp_drake.studies.questionnaire import read_answers, save_answer, unanswered
from pbp_drake.studies.trial_files import StudyFolderError, read_trial, scenario_hash

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


def session_folder(participant, output=None):
    """A session's folder: `output`, else outputs/participants/ID."""
    return pathlib.Path(output or pathlib.Path("outputs", "participants", participant))


class SessionOnDisk(typing.NamedTuple):
    """What a participant's folder already holds, each in the session's order: the methods
    whose run is saved, those whose every question is answered, and the practice runs."""

    saved: list
    answered: list
    practised: list


def session_on_disk(scenario, order, output):
    """The SessionOnDisk of the session of `order` on `scenario` in `output`."""
    output = pathlib.Path(output)
    digest = scenario_hash(scenario)
    answers = read_answers(output)
    practice_seed = scenario.seed + PRACTICE_SEED_OFFSET
    return SessionOnDisk(
        [m for m in order if read_trial(output, m, scenario.seed, digest) is not None],
        [m for m in order if not unanswered(answers, m)],
        [m for m in order
         if read_trial(output / PRACTICE_FOLDER, m, practice_seed, digest) is not None])


def check_session_folder(scenario, participant, methods, output):
    """Raises StudyFolderError (QuestionnaireError for a damaged questionnaire.json) when
    `output` cannot take `participant`'s session of `methods`: it holds a study of another
    scenario, another participant's session, this participant's session begun with other
    methods (so in another order) or on another seed, or complete; or a folder beside it
    has a name that differs from its own only in case. Returns the folder's
    SessionOnDisk."""
    output = pathlib.Path(output)
    order = session_order(methods, participant)
    _check_case_twins(output)
    recorded = [check_folder(folder, scenario, scenario_hash(scenario), quiet=True)
                for folder in (output, output / PRACTICE_FOLDER)]
    on_disk = session_on_disk(scenario, order, output)
    # Any run on disk, on whichever seed: one of another seed is not in `on_disk`.
    begun = bool(read_answers(output)) or any(
        any((folder / "trials").glob("*/seed_*.json"))
        for folder in (output, output / PRACTICE_FOLDER))
    seeds = (scenario.seed, scenario.seed + PRACTICE_SEED_OFFSET)
    for folder, study, seed in zip((output, output / PRACTICE_FOLDER), recorded, seeds):
        if study is None:
            continue
        held = study.get("participant")
        if held is not None and held != participant:
            raise StudyFolderError(
                f"{folder} holds the session of participant {held}, not {participant}: "
                f"resume it with --participant {held}, or give {participant} a folder of "
                "their own (--output)")
        if begun and study.get("methods") != order:
            # Without a recorded participant (older folders) the ID too may be the mistake.
            hint = (f" (--methods {_methods_given(study.get('methods'), held)})" if held
                    else " (and --participant)")
            whose = f"{held}'s" if held else "a"
            raise StudyFolderError(
                f"{folder} holds {whose} session begun with "
                f"the methods in the order {', '.join(map(str, study.get('methods') or []))}"
                f"; this one's order is {', '.join(order)}: resume it with the --methods it "
                f"began with{hint}, or start the participant in a new folder (--output)")
        if begun and study.get("seed") != seed:
            # The scene is the seed, outside the scenario's hash: another one would run
            # every method again for the same person, beside answers given on the first.
            first = study.get("seed")
            if folder.name == PRACTICE_FOLDER and isinstance(first, int):
                first -= PRACTICE_SEED_OFFSET
            raise StudyFolderError(
                f"{folder} holds a session on the scene of --seed {first}; this one's is "
                f"--seed {scenario.seed}: resume it with --seed {first}, or start the "
                "participant in a new folder (--output)")
    if on_disk.saved == order and on_disk.answered == order:
        raise StudyFolderError(
            f"{output} holds {participant}'s complete session ({', '.join(order)}, each run "
            f"and answered): nothing to run. A new participant needs their own --participant "
            "ID and folder; `pbp-drake report` reads this one")
    return on_disk


def _methods_given(order, participant):
    """The --methods that give `participant` the recorded `order`, comma-separated."""
    order = list(map(str, order))
    shift = participant_number(participant) % len(order)
    # session_order rotates the methods left by `shift`: this rotates the order back.
    return ",".join(order[-shift:] + order[:-shift])


def _check_case_twins(output):
    """Refuses a session folder beside one whose name differs only in case (P07, p07): one
    folder on a case-insensitive disk, and most likely one participant mistyped."""
    parent = output.parent
    twins = sorted(p.name for p in (parent.iterdir() if parent.is_dir() else [])
                   if p.is_dir() and p.name != output.name
                   and p.name.casefold() == output.name.casefold())
    if twins:
        raise StudyFolderError(
            f"{parent / twins[0]} is beside {output}, their names differing only in case: "
            "one folder on a case-insensitive disk, and most likely one participant's ID "
            f"mistyped. Resume with the ID of {twins[0]}, or give the participant an ID that "
            "differs by more than case")


def resume_text(participant, order, on_disk, practice):
    """A line saying what a resumed session keeps and what comes next, or None for a session
    that has saved nothing yet."""
    if not on_disk.saved and not on_disk.practised:
        return None
    parts = []
    if on_disk.saved:
        parts.append(f"{', '.join(on_disk.saved)} saved, not run again")
    if practice and on_disk.saved:
        parts.append("no practice (recorded runs exist)")
    elif on_disk.practised and not on_disk.saved:
        left = [m for m in order if m not in on_disk.practised]
        parts.append(f"practice of {', '.join(on_disk.practised)} saved"
                     + (f"; practice of {', '.join(left)} comes first" if practice and left
                        else ""))
    unanswered = [m for m in on_disk.saved if m not in on_disk.answered]
    if unanswered:
        parts.append(f"first the questions of {', '.join(unanswered)}")
    waiting = [m for m in order if m not in on_disk.saved]
    if waiting:
        parts.append(f"next: {waiting[0]}, method {order.index(waiting[0]) + 1} of "
                     f"{len(order)}, from its start")
    return f"Resuming {participant}'s session: " + "; ".join(parts) + "."


def run_session(scenario, participant, methods, output, run, page, practice=False):
    """Runs `run(scenario)` for each method in the participant's order, on the scenario's
    seed, saving each as a trial under `output`. `page` (console.questionnaire's Meshcat
    page or FixedAnswers) shows each method's Start and asks the questionnaire once its
    trial is saved. `practice`: first one run of each method on other scenes, under
    `output/practice` (skipped once recorded runs exist). Returns the session's summary."""
    order = session_order(methods, participant)
    output = pathlib.Path(output)
    digest = scenario_hash(scenario)
    # Before any run: a folder that cannot take the session stops here.
    check_session_folder(scenario, participant, methods, output)
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
            missing = unanswered(read_answers(output), method)
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
                              progress=after_practice_run, split="practice", run=run,
                              participant=participant)
    ask_unanswered()
    start_next(output, scenario.seed, False)
    return run_method_comparison(scenario, order, 1, scenario.seed, output,
                                 progress=after_run, run=run, participant=participant)
