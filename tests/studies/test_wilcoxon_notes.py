"""A user study's Wilcoxon rows where there is nothing to test say why in plain words (too
few participants, every difference zero), never SciPy's message; where there is something,
the row is SciPy's test."""

import pytest
import scipy.stats

from pbp_drake.studies.participant_report import wilcoxon_rows

METHODS = ["pbp_alternated", "teleop"]


def _row(first, second, source="answer"):
    (row,) = wilcoxon_rows({"pbp_alternated": first, "teleop": second}, METHODS, source)
    return row


@pytest.mark.parametrize("first, second, note", [
    # One participant, different answers: SciPy would give a meaningless p = 1.
    ({"P01": 4}, {"P01": 1}, "a test needs at least 2 participants who answered both; 1 did"),
    # One participant, the same answer: SciPy refuses ("two or more observations").
    ({"P01": 3}, {"P01": 3}, "a test needs at least 2 participants who answered both; 1 did"),
    ({"P01": 3}, {"P02": 3}, "a test needs at least 2 participants who answered both; none did"),
    # One difference not zero: SciPy drops the others and gives a meaningless p = 1.
    ({"P01": 3, "P02": 4}, {"P01": 3, "P02": 1},
     "a test needs at least 2 participants whose values for the two differ; 1 of the 2 who "
     "answered both does"),
    ({"P01": 3, "P02": 4, "P03": 5, "P04": 2, "P05": 0},
     {"P01": 3, "P02": 4, "P03": 5, "P04": 2, "P05": 5},
     "a test needs at least 2 participants whose values for the two differ; 1 of the 5 who "
     "answered both does"),
    # Every difference zero: SciPy warns and gives p = 1.
    ({"P01": 3, "P02": 4, "P03": 5}, {"P01": 3, "P02": 4, "P03": 5},
     "nothing to test: each of the 3 participants who answered both has the same value for "
     "both"),
])
def test_nothing_to_test_is_said_in_plain_words(first, second, note):
    row = _row(first, second)
    assert (row["p"], row["statistic"], row["note"]) == (None, None, note)
    assert row["n"] == len(set(first) & set(second))


def test_a_trial_measure_says_who_ran_both():
    row = _row({"P01": 0.3}, {"P01": 1.0}, source="trial")
    assert row["note"] == "a test needs at least 2 participants who ran both; 1 did"


def test_a_value_that_is_not_a_number_gives_no_p_value():
    # A trial file may hold NaN (JSON as Python reads it); SciPy then gives p = NaN.
    row = _row({"P01": float("nan"), "P02": 1.0, "P03": 3.0},
               {"P01": 0.5, "P02": 2.0, "P03": 1.0}, source="trial")
    assert (row["n"], row["p"], row["statistic"]) == (3, None, None)
    assert row["note"] == "the test gave no p-value (a value is not a number)"


def test_participants_who_differ_get_scipys_test():
    first, second = {"P01": 4, "P02": 5, "P03": 3}, {"P01": 1, "P02": 2, "P03": 3}
    row = _row(first, second)
    expected = scipy.stats.wilcoxon([4, 5, 3], [1, 2, 3])
    assert (row["n"], row["note"]) == (3, "")
    assert row["statistic"] == pytest.approx(float(expected.statistic))
    assert row["p"] == pytest.approx(float(expected.pvalue))
