"""`pbp-drake compare A B`: two studies of the same seeds, trial by trial, as a user who
changed a setting compares the two runs. The folders are written without simulating (a
real study.json of the shipped scenario, trial files of a few ticks)."""

import json

import numpy as np
import pytest

from pbp_drake.cli import main
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.studies.paired import paired_comparison
from pbp_drake.studies.trial_files import (
    scenario_hash, time_series_columns, trial_paths, trial_record, write_study,
    write_trial_files)

METHODS = ("pbp_alternated", "teleop")
TRIALS = 6
# Task times of the six seeds: a trial-to-trial SD of 2.0 s (SE 0.82 s).
TASK_TIMES = np.array([14.0, 17.0, 15.5, 19.0, 16.0, 13.5])


def _csv(ticks=3):
    columns = time_series_columns(False)
    integers = {"operator_active", "selected_goal", "target"}
    row = ",".join("0" if name in integers else "0.5" for name in columns)
    return ",".join(columns) + "\n" + "".join(row + "\n" for _ in range(ticks))


def _study(folder, scenario_path, shift=0.0, failed_seed=None, methods=METHODS,
           trials=TRIALS):
    """A finished reach study of `methods` whose task times are TASK_TIMES + `shift` (the
    trial of `failed_seed` missed its target), of the first `trials` seeds."""
    scenario = load_scenario_file(scenario_path).scenario
    digest = scenario_hash(scenario)
    write_study(folder, scenario, digest, methods, trials, 0, "tuning")
    for method in methods:
        for trial in range(trials):
            record = trial_record(scenario.name, digest, method, trial, trial)
            record.update(success=trial != failed_seed,
                          task_time=float(TASK_TIMES[trial] + shift),
                          intervention_ratio=0.1 * trial, switches=2, collision_ratio=0.0,
                          peak_hand_speed=0.2, peak_command_acceleration=1.0, ticks=3,
                          objects=[[1.6, 0.0, 0.7]], targets=[0])
            write_trial_files(folder, record, _csv())
    return folder


def _row(rows, metric, method="teleop"):
    (row,) = [r for r in rows if (r.metric, r.method) == (metric, method)]
    return row


@pytest.mark.slow
def test_pairs_the_trials_by_seed_against_the_first_studys_noise(tmp_path, repo):
    scenario = repo / "diagrams" / "hsr_reach.yaml"
    a = _study(tmp_path / "a", scenario)
    b = _study(tmp_path / "b", scenario, shift=1.5, failed_seed=2)
    rows = paired_comparison(a, b)
    task_time = _row(rows, "task_time")
    # Seed 2 missed in B: task time pairs only the trials both finished.
    assert task_time.pairs == TRIALS - 1
    assert task_time.difference == pytest.approx(1.5)
    assert task_time.low == pytest.approx(1.5) and task_time.high == pytest.approx(1.5)
    kept = np.delete(TASK_TIMES, 2)
    assert task_time.sd_a == pytest.approx(kept.std(ddof=1))
    assert task_time.se_a == pytest.approx(kept.std(ddof=1) / np.sqrt(TRIALS - 1))
    assert task_time.within_sd and not task_time.within_se  # SD 2.2 s, SE 1.0 s
    success = _row(rows, "success")
    assert success.pairs == TRIALS and success.difference == pytest.approx(-1 / TRIALS)
    # The reach task measures no collisions: no such rows.
    assert not [r for r in rows if r.metric.startswith("collision")]


@pytest.mark.slow
def test_exit_code_says_whether_a_metric_moved_beyond_its_noise(tmp_path, repo, capsys):
    scenario = repo / "diagrams" / "hsr_reach.yaml"
    a = _study(tmp_path / "a", scenario)
    assert main(["compare", str(a), str(_study(tmp_path / "near", scenario, 0.5))]) == 0
    out = capsys.readouterr().out
    assert "| task_time | teleop | 6 | 15.83 | +0.5 [+0.5, +0.5] |" in out
    assert "All 12 rows within A's trial-to-trial SD." in out
    assert main(["compare", str(a), str(_study(tmp_path / "far", scenario, 3.0))]) == 1
    out = capsys.readouterr().out
    assert "| task_time | teleop | 6 | 15.83 | +3 [+3, +3] | 2.02 | 0.823 | **no** |" in out
    assert "2 of 12 rows moved by more than A's trial-to-trial SD." in out


@pytest.mark.parametrize("which", ["first", "second"])
def test_a_damaged_trial_file_is_named_and_its_pair_left_out(tmp_path, repo, capsys, which):
    # A damaged file in either folder left its trial out in silence, exit 0.
    scenario = repo / "diagrams" / "hsr_reach.yaml"
    folders = [_study(tmp_path / "a", scenario), _study(tmp_path / "b", scenario)]
    damaged = folders[which == "second"] / "trials" / "teleop" / "seed_3.json"
    damaged.write_text("{bad")
    assert main(["compare", *map(str, folders)]) == 1
    printed = capsys.readouterr()
    assert "| task_time | teleop | 5 |" in printed.out and "All 12 rows within" in printed.out
    assert printed.err.startswith(f"pbp-drake: damaged: {damaged}: truncated or invalid JSON")
    assert printed.err.endswith("pbp-drake: 1 damaged or foreign file skipped (listed above);"
                                " their trials are left out of the pairs\n")


def test_a_method_only_one_study_ran_is_named_as_not_compared(tmp_path, repo, capsys):
    scenario = repo / "diagrams" / "hsr_reach.yaml"
    a = _study(tmp_path / "a", scenario)
    b = _study(tmp_path / "b", scenario, methods=("teleop", "hop"))
    assert main(["compare", str(a), str(b)]) == 0
    assert capsys.readouterr().out.endswith(
        "All 6 rows within A's trial-to-trial SD. pbp_alternated: only in A, not compared. "
        "hop: only in B, not compared.\n")


@pytest.mark.slow
def test_a_method_both_ran_on_no_common_seed_is_named_as_not_compared(tmp_path, repo,
                                                                      capsys):
    # Every teleop trial of B failed: teleop was left out of the table without a word.
    scenario = repo / "diagrams" / "hsr_reach.yaml"
    a, b = _study(tmp_path / "a", scenario), _study(tmp_path / "b", scenario)
    for path in b.glob("trials/teleop/seed_*.json"):
        path.write_text(json.dumps({**json.loads(path.read_text()),
                                    "error": "RuntimeError: the solver failed"}))
    assert main(["compare", str(a), str(b)]) == 0
    out = capsys.readouterr().out
    assert "| teleop |" not in out
    assert out.endswith("All 6 rows within A's trial-to-trial SD. teleop: no seed both ran "
                        "without an error, not compared.\n")


@pytest.mark.slow
def test_a_difference_of_the_last_bit_is_not_a_move(tmp_path, repo, capsys):
    # A constant metric (SD 0) computed as 1.0000000000000002 once in B "moved" (exit 1).
    scenario = repo / "diagrams" / "hsr_reach.yaml"
    a, b = _study(tmp_path / "a", scenario), _study(tmp_path / "b", scenario)
    path = trial_paths(b, "teleop", 3)[0]
    path.write_text(json.dumps({**json.loads(path.read_text()),
                                "peak_command_acceleration": 1.0000000000000002}))
    assert main(["compare", str(a), str(b)]) == 0
    out = capsys.readouterr().out
    assert "| peak_command_acceleration | teleop | 6 | 1 | +3.7e-17 " in out
    assert "**no**" not in out and "All 12 rows within A's trial-to-trial SD." in out


@pytest.mark.slow
def test_a_metric_of_one_pair_is_shown_not_judged(tmp_path, repo, capsys):
    # One trial's SD is unknown: it read as 0, so any difference "moved" (exit 1).
    scenario = repo / "diagrams" / "hsr_reach.yaml"
    a = _study(tmp_path / "a", scenario, trials=1)
    assert main(["compare", str(a), str(_study(tmp_path / "b", scenario, 3.0, trials=1))]) == 0
    out = capsys.readouterr().out
    assert "| task_time | teleop | 1 | 14 | +3 | - | - | not judged (one pair) |" in out
    assert "**no**" not in out and "inf" not in out
    assert out.endswith("No row has two pairs: nothing is judged; run both studies with more "
                        "trials.\n")
    # Beside rows of more pairs, those of one are counted apart.
    a, b = _study(tmp_path / "a6", scenario), _study(tmp_path / "b6", scenario, 3.0)
    for seed in range(1, TRIALS):
        for path in trial_paths(b, "pbp_alternated", seed):
            path.unlink()
    assert main(["compare", str(a), str(b)]) == 1
    out = capsys.readouterr().out
    assert "| task_time | pbp_alternated | 1 | 14 | +3 | - | - | not judged (one pair) |" in out
    assert "1 of 6 rows moved by more than A's trial-to-trial SD. 6 rows of a single pair not " \
           "judged (one trial has no SD)." in out


def test_refuses_folders_that_share_no_trial(tmp_path, repo, capsys):
    a = _study(tmp_path / "a", repo / "diagrams" / "hsr_reach.yaml")
    other = tmp_path / "empty"
    other.mkdir()
    assert main(["compare", str(a), str(other)]) == 2
    assert "pbp-drake:" in capsys.readouterr().err
    # Both studies on disk, but no seed of B ran without an error.
    failed = _study(tmp_path / "failed", repo / "diagrams" / "hsr_reach.yaml")
    for path in failed.glob("trials/*/seed_*.json"):
        path.write_text(json.dumps({**json.loads(path.read_text()),
                                    "error": "RuntimeError: the solver failed"}))
    assert main(["compare", str(a), str(failed)]) == 2
    assert capsys.readouterr().err == (f"pbp-drake: {a} and {failed} share no method and seed "
                                       "that both ran without an error\n")


def test_the_command_lines_help_names_it(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--help"])
    assert exit_info.value.code == 0
    assert "compare two studies of the same seeds" in capsys.readouterr().out


def _methods_study(folder, scenario_path, times):
    """One finished reach study whose methods took `times[method]` (per seed) to succeed."""
    scenario = load_scenario_file(scenario_path).scenario
    digest = scenario_hash(scenario)
    write_study(folder, scenario, digest, tuple(times), TRIALS, 0, "evaluation")
    for method, method_times in times.items():
        for trial in range(TRIALS):
            record = trial_record(scenario.name, digest, method, trial, trial)
            record.update(success=True, task_time=float(method_times[trial]),
                          intervention_ratio=0.5, switches=1, collision_ratio=0.0,
                          peak_hand_speed=0.2, peak_command_acceleration=1.0, ticks=3,
                          objects=[[1.6, 0.0, 0.7]], targets=[0])
            write_trial_files(folder, record, _csv())
    return folder


@pytest.mark.slow
def test_report_pairs_every_method_with_one_of_its_study(tmp_path, repo, capsys):
    # Teleop two seconds slower on every seed, HOP one faster: the seed-to-seed spread
    # (2.0 s SD) cancels in the pairs.
    folder = _methods_study(tmp_path / "study", repo / "diagrams" / "hsr_reach.yaml", {
        "pbp_alternated": TASK_TIMES, "teleop": TASK_TIMES + 2.0, "hop": TASK_TIMES - 1.0})
    markdown = tmp_path / "table.md"
    assert main(["report", str(folder), "--paired-with", "pbp_alternated",
                 "--markdown", str(markdown)]) == 0
    out = capsys.readouterr().out
    text = markdown.read_text()
    assert "Each method against PBP-Alt, paired by seed" in out and text.count(
        "Each method against PBP-Alt") == 1
    assert "| task_time | Teleop | 6 | 15.83 | +2 [+2, +2] |" in text
    assert "| task_time | HOP | 6 | 15.83 | -1 [-1, -1] |" in text
    assert "PBP-Alt | 6" not in text.split("Each method against")[1]  # not against itself
    # A reference the study did not run: one line, exit 2.
    assert main(["report", str(folder), "--paired-with", "pbp_continuous"]) == 2
    assert "--paired-with: the study ran pbp_alternated, teleop, hop, not pbp_continuous" in (
        capsys.readouterr().err)


@pytest.mark.slow
def test_report_names_a_method_it_could_not_pair_with_the_reference(tmp_path, repo, capsys):
    # Every HOP trial failed with an error: HOP was left out of the paired table in silence.
    folder = _methods_study(tmp_path / "study", repo / "diagrams" / "hsr_reach.yaml", {
        "pbp_alternated": TASK_TIMES, "teleop": TASK_TIMES + 2.0, "hop": TASK_TIMES - 1.0})
    for path in folder.glob("trials/hop/seed_*.json"):
        path.write_text(json.dumps({**json.loads(path.read_text()),
                                    "error": "RuntimeError: the solver failed"}))
    markdown = tmp_path / "table.md"
    main(["report", str(folder), "--paired-with", "pbp_alternated", "--markdown", str(markdown)])
    paired = markdown.read_text().split("Each method against PBP-Alt")[1]
    assert "| task_time | Teleop | 6 | 15.83 | +2 [+2, +2] |" in paired and "HOP |" not in paired
    assert paired.endswith("\nHOP: no seed it and PBP-Alt both ran without an error, not "
                         "compared.\n")
    assert "HOP: no seed it and PBP-Alt both ran" in capsys.readouterr().out


@pytest.mark.slow
def test_report_refuses_a_reference_it_did_not_run_before_rewriting_the_folder(
        tmp_path, repo, capsys):
    folder = _methods_study(tmp_path / "study", repo / "diagrams" / "hsr_reach.yaml", {
        "pbp_alternated": TASK_TIMES, "teleop": TASK_TIMES + 2.0})
    assert main(["report", str(folder), "--paired-with", "pbp_continuous"]) == 2
    captured = capsys.readouterr()
    assert captured.err == ("pbp-drake: --paired-with: the study ran pbp_alternated, teleop, "
                            "not pbp_continuous\n")
    assert captured.out == ""  # no table, no "wrote": the bad flag is refused first
    assert not (folder / "summary.json").exists() and not (folder / "results.md").exists()
