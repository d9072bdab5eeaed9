"""Tuning and evaluation seeds of a `study: !MethodComparison`: seeds from `tuning_seed` up
to `evaluation_seed` are the only scenes the virtual participant may be calibrated on;
from `evaluation_seed` on, scenes no tuning has seen. The seeds a study ran are labelled
by the split they fall in, in study.json, summary.json and results.md
(docs/tasks/studies.md, "Seeds: evaluation and tuning").
"""

from pbp_drake.scenarios import ScenarioError
from pbp_drake.scenarios.schema import STUDY_SPLITS as SPLITS

#: What each label tells a reader of the results.
SPLIT_NOTES = {
    "tuning": "tuning seeds: the virtual participant may have been calibrated on these scenes",
    "evaluation": "evaluation seeds: no tuning of the virtual participant has seen these scenes",
    "mixed": "seeds from both the tuning and the evaluation split",
    "unlabelled": "seeds below the study's tuning seeds, in no split",
    "practice": "a participant's practice runs (`run --practice`), never counted in a report",
}


def first_seed(study, split):
    """The first seed of `split` ("tuning" or "evaluation") of a MethodComparison."""
    if split not in SPLITS:
        raise ValueError(f"split must be one of {', '.join(SPLITS)}, got {split!r}")
    return study.tuning_seed if split == "tuning" else study.evaluation_seed


def split_of(study, seed, trials):
    """The label of seeds `seed .. seed + trials - 1` under a MethodComparison's splits:
    "tuning", "evaluation", "mixed" (they straddle `evaluation_seed`) or "unlabelled"
    (some lie below `tuning_seed`)."""
    last = seed + trials - 1
    if seed < study.tuning_seed:
        return "unlabelled"
    if last < study.evaluation_seed:
        return "tuning"
    return "evaluation" if seed >= study.evaluation_seed else "mixed"


def check_within_split(study, split, seed, trials, whose):
    """ScenarioError unless seeds `seed .. seed + trials - 1` all lie in `split` of a
    MethodComparison: tuning runs that reach the evaluation seeds show a tuning the scenes
    kept for judging it (and an evaluation split's seeds below them are tuning scenes).
    `whose` names where the split was asked for ("--split tuning")."""
    label = split_of(study, seed, trials)
    if label == split:
        return
    last = seed + trials - 1
    seeds = (f"{study.tuning_seed} to {study.evaluation_seed - 1}" if split == "tuning"
             else f"from {study.evaluation_seed} on")
    raise ScenarioError(
        f"{whose}: seeds {seed} to {last} are not all {split} seeds ({seeds}) but {label}: "
        "give --seed and --trials within them, or --seed without --split to run these "
        f"seeds, labelled {label}")


def seeds_line(summary):
    """One line for results: the seeds a summary covers and their split ("" without seeds)."""
    seeds = summary.get("seeds")
    if not seeds:
        return ""
    split = summary.get("split")
    note = SPLIT_NOTES.get(split, "no split recorded")
    return f"Seeds {seeds[0]} to {seeds[1]}: {note}."
