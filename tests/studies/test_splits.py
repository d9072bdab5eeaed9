"""Tuning and evaluation seeds: which split a study's seeds fall in, and how results say so."""

import pytest

from pbp_drake.scenarios import MethodComparison, ScenarioError
from pbp_drake.studies.report import results_table
from pbp_drake.studies.splits import check_within_split, first_seed, seeds_line, split_of

STUDY = MethodComparison(trials=30, tuning_seed=0, evaluation_seed=10_000)


def test_each_split_starts_at_its_own_seed():
    assert first_seed(STUDY, "tuning") == 0
    assert first_seed(STUDY, "evaluation") == 10_000
    with pytest.raises(ValueError, match="tuning, evaluation"):
        first_seed(STUDY, "test")


@pytest.mark.parametrize("seed, trials, split", [
    (0, 30, "tuning"), (9_970, 30, "tuning"), (9_971, 30, "mixed"), (10_000, 30, "evaluation"),
    (123_456, 1, "evaluation")])
def test_seeds_are_labelled_by_the_split_they_fall_in(seed, trials, split):
    assert split_of(STUDY, seed, trials) == split


@pytest.mark.parametrize("split, seed, trials, label", [
    ("tuning", 9_990, 11, "mixed"), ("tuning", 10_000, 1, "evaluation"),
    ("evaluation", 9_999, 2, "mixed"), ("evaluation", 0, 1, "tuning")])
def test_seeds_asked_of_a_split_must_lie_in_it(split, seed, trials, label):
    check_within_split(STUDY, split, 9_970 if split == "tuning" else 10_000, 30, "--split")
    with pytest.raises(ScenarioError, match=f"^--split {split}: seeds {seed} to "
                       f"{seed + trials - 1} are not all {split} seeds .* but {label}: "):
        check_within_split(STUDY, split, seed, trials, f"--split {split}")


def test_seeds_below_the_tuning_seeds_are_in_no_split():
    assert split_of(MethodComparison(tuning_seed=100), 50, 10) == "unlabelled"


def test_the_results_table_opens_with_the_seeds_and_their_split():
    summary = {"seeds": [10_000, 10_029], "split": "evaluation", "methods": {},
               "measures_collisions": False}
    table = results_table(summary)
    assert table.startswith("Seeds 10000 to 10029: evaluation seeds: no tuning of the "
                            "virtual participant has seen these scenes.\n")
    # A folder written before splits were recorded says nothing of them.
    assert seeds_line({"methods": {}}) == ""
    assert results_table({"methods": {}, "measures_collisions": False}).startswith(
        "| method |")
