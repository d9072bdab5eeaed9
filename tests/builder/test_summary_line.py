"""The terminal's one-line result of a run counts its target switches as a person writes
them: "1 target switch", "0 target switches", "3 target switches"; where the run measured
them, it ends with the interaction metrics."""

import numpy as np
import pytest

from pbp_drake.builder.run import TaskResult


def _result(switches, ticks=4, **metrics):
    return TaskResult(
        success=False, task_time=60.0, intervention_ratio=0.25, switches=switches,
        times=np.arange(ticks) * 0.03, ee_positions=np.zeros((ticks, 3)),
        headings=np.zeros(ticks), commands=np.zeros((ticks, 7)),
        operator_active=np.zeros(ticks, bool), operator_commands=np.zeros((ticks, 4)),
        selected_goals=np.zeros(ticks, int), targets=np.zeros(ticks, int),
        objects=np.zeros((2, 3)), peak_hand_speed=0.2, peak_command_acceleration=1.0,
        **metrics)


@pytest.mark.parametrize("switches, words", [
    (0, "0 target switches"), (1, "1 target switch"), (3, "3 target switches")])
def test_the_result_line_counts_target_switches_in_the_right_number(switches, words):
    line = _result(switches).summary_line()
    assert line == (f"FAILED in 60.00 s, intervention ratio 0.250, {words}, peak hand speed "
                    "0.200 m/s, peak command acceleration 1.00 m/s^2")


INTERACTION = dict(input_integral=0.42, turn_input_integral=0.15, idle_ratio=0.75,
                   agreement=-0.25)


def test_the_result_line_ends_with_the_interaction_metrics():
    line = _result(2, **INTERACTION, prediction_accuracy=0.5, time_to_prediction=[0.2, None,
                   0.3], mean_time_to_prediction=0.25, unpredicted_switches=1).summary_line()
    assert line.endswith(", input 0.420 m and 0.150 rad, idle ratio 0.750, agreement -0.250, "
                         "prediction accuracy 0.500, time to prediction 0.25 s (1 switch "
                         "never named)")


def test_a_method_that_names_no_goal_says_so():
    line = _result(2, **INTERACTION).summary_line()
    assert line.endswith(", agreement -0.250, no goal named")
