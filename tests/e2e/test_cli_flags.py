"""`pbp-drake run`'s numeric flags are checked when the line is parsed (exit 2, the flag
named), and a keyboard or gamepad run that no browser joins stops, having run and recorded
nothing, instead of running unattended to its time limit."""

import time

import pytest

from pbp_drake.cli import main

QUICK = "diagrams/toy_alt_vs_cont.yaml"
TASK = "diagrams/hsr_reach.yaml"


@pytest.mark.parametrize("flag, value, message", [
    ("--port", "70000", "0..65535"),
    ("--port", "-1", "0..65535"),
    ("--port", "80.5", "0..65535"),
    ("--realtime-rate", "0", "--headless runs as fast as possible"),
    ("--realtime-rate", "-1", "positive"),
    ("--realtime-rate", "nan", "finite"),
    ("--realtime-rate", "inf", "finite"),
    ("--realtime-rate", "fast", "not a number"),
    ("--wait-for-browser", "nan", "finite"),
    ("--wait-for-browser", "-0.5", "0 or more"),
])
def test_a_bad_flag_value_is_refused_when_parsed(repo, capsys, flag, value, message):
    started = time.monotonic()
    with pytest.raises(SystemExit) as exit_info:
        main(["run", str(repo / QUICK), "--headless", f"{flag}={value}"])
    assert exit_info.value.code == 2
    assert time.monotonic() - started < 0.5  # nothing was loaded, built or run
    err = capsys.readouterr().err
    assert f"argument {flag}: " in err and message in err
    assert "Traceback" not in err


@pytest.mark.parametrize("argv", [
    ["--port", "0"], ["--port", "65535"], ["--realtime-rate", "0.5"],
    ["--wait-for-browser", "0"],
])
def test_good_flag_values_pass(repo, argv):
    assert main(["run", str(repo / QUICK), "--headless", *argv]) == 0


@pytest.mark.parametrize("operator", ["keyboard", "gamepad"])
def test_a_person_run_that_no_browser_joins_stops_and_records_nothing(repo, tmp_path, capsys,
                                                                       operator):
    record = tmp_path / "replay.html"
    started = time.monotonic()
    code = main(["run", str(repo / TASK), "--operator", operator, "--wait-for-browser", "0.2",
                 "--record", str(record)])
    elapsed = time.monotonic() - started
    captured = capsys.readouterr()
    assert code == 2
    assert elapsed < 5.0, f"took {elapsed:.1f} s"
    assert "the task starts when it connects (waiting up to 0.2 s)" in captured.out
    assert captured.err.startswith("pbp-drake: no browser opened http://")
    assert "within 0.2 s (--wait-for-browser)" in captured.err
    assert "nothing was run or recorded" in captured.err
    assert "success" not in captured.out and "failure" not in captured.out
    assert not record.exists()


def test_a_session_that_no_browser_joins_stops_and_saves_nothing(repo, tmp_path, capsys):
    output = tmp_path / "P1"
    code = main(["run", str(repo / TASK), "--operator", "keyboard", "--participant", "P1",
                 "--output", str(output), "--wait-for-browser", "0.2"])
    err = capsys.readouterr().err
    assert code == 2
    assert "no browser opened" in err and "nothing was run or recorded" in err
    assert not any(output.rglob("*")) if output.exists() else True


@pytest.mark.parametrize("argv, named", [
    (["--participant", "P01"], "--participant"),
    (["--methods", "teleop", "--answers", "tiredness=1,ease=2"], "--methods, --answers"),
])
def test_session_flags_on_a_2d_scene_are_refused(repo, capsys, argv, named):
    assert main(["run", str(repo / QUICK), "--no-meshcat", *argv]) == 2
    err = capsys.readouterr().err
    assert f"{named}: user-study sessions run the HSR tasks" in err
