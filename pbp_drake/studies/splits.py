"""Tuning and evaluation seeds: which part of the seeded scenes a method study shows.

A scenario's `study: !MethodComparison` names two splits. Seeds from `tuning_seed` up to
`evaluation_seed` are the tuning split: the only scenes on which the virtual participant's
parameters may be calibrated (on teleop). Seeds from `evaluation_seed` on are the
evaluation split: scenes no tuning has seen, on which every method is judged and results
are published. `pbp-drake study` runs the split the file names (`--split` chooses another,
`--seed` any first seed); the seeds it ran are labelled by the split they fall in, and that
label goes into study.json, summary.json and results.md.
"""

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


def seeds_line(summary):
    """One line for results: the seeds a summary covers and their split (none for a study
    folder written before splits were recorded)."""
    seeds = summary.get("seeds")
    if not seeds:
        return ""
    split = summary.get("split")
    note = SPLIT_NOTES.get(split, "no split recorded")
    return f"Seeds {seeds[0]} to {seeds[1]}: {note}."
