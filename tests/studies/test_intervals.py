"""The 95 % intervals below a results table, against SciPy's own: Wilson's score interval
of a success rate (`scipy.stats.binomtest`) and Student's t interval of a mean from the
trials' values (`scipy.stats.t.interval`), the summary holding only their mean and
population standard deviation."""

import numpy as np
import pytest
import scipy.stats

from pbp_drake.studies.intervals import confidence_table, mean_interval, wilson_interval


@pytest.mark.parametrize("successes, trials", [(30, 30), (27, 30), (0, 10), (1, 1), (5, 9)])
def test_the_success_interval_is_wilsons(successes, trials):
    expected = scipy.stats.binomtest(successes, trials).proportion_ci(0.95, method="wilson")
    np.testing.assert_allclose(wilson_interval(successes, trials),
                               (expected.low, expected.high), atol=1e-12)


def test_the_mean_interval_is_students_t_from_the_population_std():
    values = np.random.default_rng(0).normal(16.0, 3.0, 30)
    expected = scipy.stats.t.interval(0.95, len(values) - 1, loc=values.mean(),
                                      scale=scipy.stats.sem(values))
    np.testing.assert_allclose(mean_interval(values.mean(), values.std(), len(values)),
                               expected, atol=1e-12)


def test_a_ratios_interval_stays_within_zero_and_one_and_one_trial_has_none():
    assert mean_interval(0.01, 0.05, 30, within=(0.0, 1.0))[0] == 0.0
    assert mean_interval(0.99, 0.05, 30, within=(0.0, 1.0))[1] == 1.0
    assert mean_interval(0.5, 0.0, 1) is None


def test_the_table_has_a_row_per_method_and_a_column_per_metric_it_holds():
    entry = {"trials": 30, "errors": 0, "success_rate": 0.9,
             "intervention_ratio": {"mean": 0.5, "std": 0.1},
             "task_time": {"mean": 12.0, "std": 2.0}}
    clipped = dict(entry, posterior_clipped_ratio={"mean": 0.05, "std": 0.08})
    lines = confidence_table({"methods": {"teleop": entry, "hop": clipped}})
    assert lines[2] == ("| method | success | intervention ratio | task time (s) | "
                        "posterior at its clip |")
    assert lines[4].startswith("| Teleop | [74, 97] % | ") and lines[4].endswith(" | - |")
    assert lines[5].startswith("| HOP | [74, 97] % | ")
