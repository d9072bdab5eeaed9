"""The interaction metrics against values worked out on paper from their definitions, on a
hand-made task of twelve ticks of 0.1 s: three targets (switches at 0, 0.4 and 0.8 s), ticks
that name no goal (-1), silent stretches, a command the hand goes against, a tick where the
hand stands still; fed whole and in chunks."""

import math

import numpy as np
import pytest

from pbp_drake.core.interaction_metrics import (
    InteractionMeter, idle_ratio, interaction_metrics)

PERIOD = 0.1
TIMES = PERIOD * np.arange(12)
TARGETS = np.array([0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2])
# Target 0 named from tick 2 (0.2 s after its switch at 0 s); target 1 named at tick 5,
# lost at tick 6 (-1: nothing shown), named again from tick 7 (0.3 s after 0.4 s); target
# 2 named at ticks 8 to 10 but not on the last tick: never named to the end.
PREDICTED = np.array([-1, 1, 0, 0, 0, 1, -1, 1, 2, 2, 2, 1])
ACTIVE = np.array([1, 1, 1, 0, 0, 0, 1, 1, 0, 0, 1, 1], bool)
# m/s. Silent ticks command nothing; tick 7 only turns; tick 6 pushes against the hand.
COMMAND = np.array([[0.3, 0.4, 0], [0.5, 0, 0], [0, 1, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0],
                    [-1, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0.2], [1, 0, 0]],
                   float)
YAW_RATE = np.array([0, 0, 0, 0, 0, 0, 0, 0.5, 0, 0, -1.0, 0])  # rad/s
# The hand's velocity over each tick (m/s); the last tick's motion is not in the series.
HAND_VELOCITY = np.array([[0.4, 0.3, 0], [0.1, 0, 0], [0, 0, 0], [0.2, 0, 0], [0.2, 0, 0],
                          [0.2, 0, 0], [0.2, 0, 0], [0.2, 0, 0], [0, 0, 0], [0, 0, 0],
                          [0, 0.3, 0.3]], float)
HAND = np.vstack([np.zeros(3), np.cumsum(HAND_VELOCITY * PERIOD, axis=0)])


def _metrics(predicted=PREDICTED, turn=YAW_RATE):
    return interaction_metrics(TIMES, PERIOD, COMMAND, turn, ACTIVE, HAND, predicted,
                               TARGETS)


def test_the_input_integrals_sum_the_command_norms_while_the_operator_acts():
    metrics = _metrics()
    # (0.5 + 0.5 + 1 + 1 + 0 + 0.2 + 1) m/s over 0.1 s each.
    assert metrics.input_integral == pytest.approx(0.42, abs=1e-12)
    # |0.5| + |-1.0| rad/s over 0.1 s each.
    assert metrics.turn_input_integral == pytest.approx(0.15, abs=1e-12)


def test_the_turn_of_an_angular_velocity_is_its_norm():
    angular = np.zeros((12, 3))
    angular[7] = [0.3, 0.4, 0.0]  # 0.5 rad/s
    angular[10] = [0.0, 0.0, -1.0]
    assert _metrics(turn=angular).turn_input_integral == pytest.approx(0.15, abs=1e-12)


def test_agreement_is_the_mean_cosine_over_the_acting_ticks_that_move():
    # Ticks 0 (cos 0.96), 1 (1), 6 (-1: the hand goes against the push) and 10 (1/sqrt 2);
    # tick 2 (the hand still), 7 (no translation), 11 (the last) and the silent ticks out.
    expected = (0.96 + 1.0 - 1.0 + 1.0 / math.sqrt(2.0)) / 4
    assert _metrics().agreement == pytest.approx(expected, abs=1e-12)


def test_prediction_accuracy_counts_a_tick_that_names_nothing_as_wrong():
    # Ticks 2, 3, 5, 7, 8, 9, 10 name their target: 7 of 12.
    assert _metrics().prediction_accuracy == pytest.approx(7 / 12, abs=1e-12)


def test_time_to_prediction_is_from_each_switch_to_the_named_target_kept_to_the_next():
    metrics = _metrics()
    assert metrics.time_to_prediction == pytest.approx((0.2, 0.3, None), abs=1e-12)
    assert metrics.mean_time_to_prediction == pytest.approx(0.25, abs=1e-12)
    assert metrics.unpredicted_switches == 1
    fields = metrics.fields()
    assert fields["time_to_prediction"] == pytest.approx([0.2, 0.3, None], abs=1e-12)
    assert fields["unpredicted_switches"] == 1


def test_a_target_named_at_its_switch_takes_no_time():
    always = TARGETS.copy()
    metrics = _metrics(predicted=always)
    assert metrics.time_to_prediction == (0.0, 0.0, 0.0)
    assert metrics.prediction_accuracy == 1.0 and metrics.unpredicted_switches == 0


def test_a_method_that_names_nothing_has_no_prediction_metrics():
    metrics = _metrics(predicted=np.full(12, -1))
    assert metrics.prediction_accuracy is None
    assert metrics.time_to_prediction is None
    assert metrics.mean_time_to_prediction is None and metrics.unpredicted_switches is None
    # The operator's metrics do not depend on what the method shows.
    assert metrics.agreement == _metrics().agreement
    assert metrics.input_integral == _metrics().input_integral


def test_no_acting_tick_that_moves_has_no_agreement():
    silent = interaction_metrics(TIMES, PERIOD, COMMAND, YAW_RATE, np.zeros(12, bool), HAND,
                                 PREDICTED, TARGETS)
    assert silent.agreement is None
    assert silent.input_integral == 0.0 and silent.turn_input_integral == 0.0


@pytest.mark.parametrize("cuts", [(1,), (4, 9), (3, 5, 6, 8, 11), tuple(range(1, 12)),
                                  (4, 4, 9)])  # (4, 4): an empty chunk
def test_chunks_give_what_the_whole_series_gives(cuts):
    meter = InteractionMeter(PERIOD)
    bounds = [0, *cuts, 12]
    for begin, end in zip(bounds, bounds[1:]):
        meter.add(TIMES[begin:end], COMMAND[begin:end], YAW_RATE[begin:end],
                  ACTIVE[begin:end], HAND[begin:end], PREDICTED[begin:end],
                  TARGETS[begin:end])
    chunked, whole = meter.metrics(), _metrics()
    assert chunked.time_to_prediction == pytest.approx(whole.time_to_prediction, abs=1e-12)
    for name in ("input_integral", "turn_input_integral", "agreement", "prediction_accuracy"):
        assert getattr(chunked, name) == pytest.approx(getattr(whole, name), abs=1e-12), name


def test_the_idle_ratio_is_the_share_of_the_intervention_ratios_ticks_without_input():
    # 3 ticks with input of the task monitor's 12: 9 without.
    assert idle_ratio(3 / 12) == pytest.approx(9 / 12, abs=1e-15)
    assert idle_ratio(None) is None


@pytest.mark.parametrize("period", [0.0, -0.1, math.nan])
def test_a_control_period_that_is_not_positive_is_refused(period):
    # 0 made the hand's velocity infinite and -0.1 the input negative, without a word.
    with pytest.raises(ValueError, match="control_period must be finite and positive"):
        interaction_metrics(TIMES, period, COMMAND, YAW_RATE, ACTIVE, HAND, PREDICTED,
                            TARGETS)


@pytest.mark.parametrize("index, name", [
    (2, "operator_velocity"), (3, "operator_turn"), (4, "operator_active"),
    (5, "hand_positions"), (6, "predicted_goals"), (7, "targets")])
def test_a_series_of_another_length_is_refused_naming_it(index, name):
    arguments = [TIMES, PERIOD, COMMAND, YAW_RATE, ACTIVE, HAND, PREDICTED, TARGETS]
    arguments[index] = arguments[index][:-1]
    with pytest.raises(ValueError,
                       match=rf"{name} has 11 rows; expected one per tick of times \(12\)"):
        interaction_metrics(*arguments)


def test_a_nan_in_a_series_is_refused_rather_than_made_the_metric():
    command = COMMAND.copy()
    command[0, 0] = math.nan  # an acting tick: it made the input integral NaN
    with pytest.raises(ValueError, match="operator_velocity holds NaN or infinite values"):
        interaction_metrics(TIMES, PERIOD, command, YAW_RATE, ACTIVE, HAND, PREDICTED,
                            TARGETS)
