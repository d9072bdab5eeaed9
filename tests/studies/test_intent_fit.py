"""The intent filter's fit (`pbp_drake.studies.intent_fit`): its score is the mean log
probability of the participant's target, each source is fitted alone on what it tells, a
folder's teleop trials are replayed and fitted, and a folder without teleop trials is one
line, exit 2."""

import numpy as np
import pytest

from pbp_drake.core.intent_filter import IntentFeatures, IntentFilterSettings
from pbp_drake.studies import intent_fit
from pbp_drake.studies.trial_files import time_series_columns, trial_record, write_trial_files

GOALS = 5


def replay(ticks, moves_at_target, headings_at_target, rng):
    """A replay whose target is goal 0 throughout: the motion (and the heading) favour it by
    the given amounts, with noise on every goal."""
    moves = rng.uniform(-0.5, 0.5, (ticks, GOALS))
    headings = rng.uniform(-0.5, 0.5, (ticks, GOALS))
    moves[:, 0] += moves_at_target
    headings[:, 0] += headings_at_target
    return intent_fit.Replay(IntentFeatures(moves, headings, np.zeros((ticks, GOALS)),
                                            np.ones(ticks, bool)),
                             np.zeros(ticks, int), 0.03)


def test_the_score_is_the_mean_log_probability_of_the_target():
    flat = replay(50, 0.0, 0.0, np.random.default_rng(0))
    uniform = IntentFilterSettings(move_rate=0.0, heading_weight=0.0, turn_rate=0.0)
    assert intent_fit.scores([flat], [uniform])[0] == pytest.approx(-np.log(GOALS))


@pytest.mark.slow
def test_a_source_that_names_the_target_gets_weight_and_one_that_does_not_gets_none():
    rng = np.random.default_rng(1)
    replays = [replay(200, 0.8, 0.0, rng) for _ in range(3)]
    fitted, score = intent_fit.fit(replays)
    assert fitted.move_rate > 0.0
    assert fitted.heading_weight == 0.0  # the heading is noise here
    assert score > -np.log(GOALS)


def test_a_folder_without_teleop_trials_is_one_line_and_exit_2(tmp_path, capsys):
    assert intent_fit.main([str(tmp_path)]) == 2
    assert capsys.readouterr().err.strip().startswith(
        f"intent_fit: no teleop trials under {tmp_path}")
    assert intent_fit.main([str(tmp_path / "missing")]) == 2
    assert "no such folder" in capsys.readouterr().err


def teleop_study(folder, ticks=40):
    """A study folder of one teleop trial written without simulating: the hand moves along
    +x towards the first of two objects, the operator acting for its first 30 ticks."""
    columns = time_series_columns(False)
    lines = [",".join(columns)]
    for tick in range(ticks):
        values = dict.fromkeys(columns, 0)
        values.update(time=0.03 * tick, ee_x=0.5 + 0.009 * tick, ee_z=0.7,
                      operator_active=int(tick < 30), operator_vx=0.3)
        lines.append(",".join(str(values[name]) for name in columns))
    record = trial_record("fake", "abc", "teleop", 0, 0)
    record.update(success=True, task_time=1.2, intervention_ratio=1.0, switches=0,
                  collision_ratio=0.0, ticks=ticks, objects=[[1.6, 0.0, 0.7], [0.5, 1.0, 0.7]],
                  targets=[0])
    write_trial_files(folder, record, "\n".join(lines) + "\n")
    return folder


def test_the_fit_of_a_folder_prints_each_round_and_the_settings(tmp_path, capsys):
    assert intent_fit.main([str(teleop_study(tmp_path))]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "1 teleop trials, 40 ticks"
    assert lines[1].startswith("move_rate alone: round 1 move_rate: 0: -0.6931, 1: ")
    assert "(uniform: -0.6931; the shipped defaults: " in lines[-2]
    fitted = dict(item.split(": ") for item in lines[-1][len("intent_filter: {"):-1].split(
        ", "))
    assert list(fitted) == list(intent_fit.GRIDS)
    # The hand moves and heads towards the target and never turns.
    assert float(fitted["move_rate"]) > 0 and float(fitted["heading_weight"]) > 0
    assert fitted["turn_rate"] == "0"
