"""`pbp-drake run`'s numeric flags are checked when the line is parsed (exit 2, the flag
named), a flag the scenario cannot take and a port in use are refused in one line before
anything is built, and a keyboard or gamepad run that no browser joins stops, having run
and recorded nothing, instead of running unattended to its time limit."""

import argparse
import socket
import time

import pytest
from browser_page import free_port

from pbp_drake.cli import main
from pbp_drake.commands.scenario_flags import scenario_overrides

QUICK = "diagrams/toy_alt_vs_cont.yaml"
TASK = "diagrams/hsr_reach.yaml"
SESSION = ["--operator", "virtual", "--participant", "P1", "--headless", "--answers",
           "tiredness=3,ease=4"]


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
    ("--keep-page", "-1", "0 or more"),
    ("--token", "short", "16 to 128"),
    ("--token", "a" * 15 + "/", "only letters, digits"),
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


@pytest.mark.slow
def test_a_good_realtime_rate_passes(repo):
    assert main(["run", str(repo / QUICK), "--headless", "--realtime-rate", "0.5"]) == 0


@pytest.mark.slow
@pytest.mark.parametrize("argv", [
    ["--port", "0"], ["--wait-for-browser", "0"], ["--token", "a-script-chose_this-token"],
])
def test_good_page_flag_values_pass(repo, argv):
    assert main(["run", str(repo / QUICK), "--realtime-rate", "50", "--keep-page", "0",
                 *argv]) == 0


@pytest.mark.parametrize("argv, named", [
    (["--token", "a-script-chose_this-token"], "--token"),
    (["--keep-page", "0", "--port", "8123"], "--port, --keep-page"),
    (["--wait-for-browser", "3", "--start-on-connect"], "--start-on-connect, --wait-for-browser"),
])
def test_page_flags_with_headless_are_refused_in_one_line(repo, capsys, argv, named):
    assert main(["run", str(repo / QUICK), "--headless", *argv]) == 2
    err = capsys.readouterr().err
    assert err == f"pbp-drake: {named}: the page's flags; --headless has no page (drop them, " \
                  "or --headless)\n"


@pytest.mark.slow
def test_a_page_run_takes_a_free_port_and_prints_its_tokened_url(repo, capsys):
    port = free_port()
    assert main(["run", str(repo / QUICK), "--port", str(port), "--realtime-rate", "20",
                 "--token", "a-script-chose_this-token"]) == 0
    out = capsys.readouterr().out
    assert f"Meshcat: http://localhost:{port}/?token=a-script-chose_this-token" in out
    assert "listening for connections" not in out  # Drake's own line, of the private port


def test_a_port_in_use_is_refused_in_one_line_before_anything_is_built(repo, capsys):
    with socket.socket() as taken:
        taken.bind(("localhost", 0))
        taken.listen()
        port = taken.getsockname()[1]
        started = time.monotonic()
        code = main(["run", str(repo / TASK), "--port", str(port)])
        elapsed = time.monotonic() - started
    captured = capsys.readouterr()
    assert code == 2
    assert captured.err == f"pbp-drake: port {port} is in use (use --port 0 for a free one)\n"
    assert captured.out == ""  # no URL, no scene built, no run
    assert elapsed < 2.0, f"took {elapsed:.1f} s"


@pytest.mark.slow
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
    assert "(waiting up to 0.2 s); the task starts when Start is pressed" in captured.out
    assert captured.err.startswith("pbp-drake: no browser opened http://")
    assert "within 0.2 s (--wait-for-browser)" in captured.err
    assert "nothing was run or recorded" in captured.err
    assert "success" not in captured.out and "failure" not in captured.out
    assert not record.exists()


@pytest.mark.slow
@pytest.mark.parametrize("command", [["session"], ["run"]])  # `run --participant`: its alias
def test_a_session_that_no_browser_joins_stops_and_saves_nothing(repo, tmp_path, capsys,
                                                                 command):
    output = tmp_path / "P1"
    code = main([*command, str(repo / TASK), "--operator", "keyboard", "--participant", "P1",
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


@pytest.mark.parametrize("argv, message", [
    (["run", TASK, "--no-meshcat", "--method", "teleop", "--alpha", "0.5"],
     "--alpha sets the weight of fixed_alpha; the method is teleop"),
    (["run", QUICK, "--no-meshcat", "--operator", "none"],
     "--operator chooses who drives the tasks; this scenario uses the 2-D toy robot"),
    # The 2-D scenes of docs/tasks/two-d.md: its operator a field the task's cannot fill.
    (["run", "diagrams/toy_alpha_study.yaml", "--no-meshcat", "--operator", "none"],
     "--operator chooses who drives the tasks; this scenario uses the 2-D toy robot"),
    (["run", "diagrams/toy_alpha_study.yaml", "--headless", "--operator", "virtual"],
     "--operator chooses who drives the tasks; this scenario uses the 2-D toy robot"),
    # A 2-D scene draws nothing from a seed.
    (["run", QUICK, "--headless", "--seed", "3"],
     "with --seed 3: scenario: unknown key 'seed' (a robot task's field: "),
    (["run", "diagrams/arm_reach.yaml", "--headless", "--camera", "robot"],
     "--camera robot looks from the HSR's head; this scenario has no HSR"),
    (["run", TASK, "--no-meshcat", "--record", "{tmp}/run.html"],
     "--record and --camera robot need the page: drop --no-meshcat"),
    (["run", QUICK, "--no-meshcat", "--log", "{tmp}/run.csv"],
     "--log streams an HSR task's per-tick rows; this scenario uses the 2-D toy robot"),
    (["driver-sim", TASK, "--duration", "0"], "--duration must be positive, got 0"),
    (["run", TASK, "--no-meshcat", "--scene", "scene_1"],
     "--scene 'scene_1': this file's study has no scenes; --scene picks one of a 2-D alpha "
     "study's (e.g. diagrams/toy_alpha_study.yaml)"),
    (["run", QUICK, "--no-meshcat", "--scene", "scene_1"], "this file's study has no scenes"),
    # --goals outside the reaching task: named, not the field it sets.
    (["run", QUICK, "--no-meshcat", "--goals", "10"],
     "--goals places a reaching task's objects; this scenario uses the 2-D toy robot"),
    (["study", "diagrams/hsr_obstacles.yaml", "--goals", "10", "--output", "{tmp}/study"],
     "--goals places a reaching task's objects; this scenario's task is !DynamicObstacles"),
    # --hand-trail where nothing draws it: taken, and nothing drawn.
    (["run", QUICK, "--headless", "--hand-trail"],
     "--hand-trail draws a reaching or obstacle task's hand path; this scenario uses the 2-D "
     "toy robot"),
    (["run", "diagrams/hsr_grasp.yaml", "--headless", "--hand-trail"],
     "--hand-trail draws a reaching or obstacle task's hand path; the grasping task draws "
     "none"),
    (["run", TASK, "--no-meshcat", "--hand-trail"],
     "--hand-trail draws the hand's path in the page: drop --no-meshcat"),
    # A value that was taken in silence for another: the file's objects, alpha or methods,
    # no replay or log, the two files written over each other.
    (["run", TASK, "--no-meshcat", "--operator", "virtual", "--goals", "0"],
     "--goals must be positive, got 0"),
    (["run", TASK, "--no-meshcat", "--method", "fixed_alpha="],
     "method 'fixed_alpha=': alpha must be a number in [0, 1]"),
    (["run", TASK, "--headless", "--operator", "virtual", "--record", ""],
     "--record: the path is empty; give a file, e.g. replay.html"),
    (["run", TASK, "--no-meshcat", "--operator", "virtual", "--log", ""],
     "--log: the path is empty; give a file, e.g. run.csv"),
    (["run", TASK, "--headless", "--operator", "virtual", "--record", "{tmp}/run.html",
      "--log", "{tmp}/run.html"], "--record and --log both name {tmp}/run.html"),
    (["session", TASK, *SESSION, "--output", ""],
     "--output: the path is empty; give a folder for the results"),
    (["session", TASK, *SESSION, "--output", "{tmp}/P1", "--methods", ""],
     "--methods '' names no method; give them comma-separated"),
    (["session", TASK, *SESSION, "--output", "{tmp}/P1", "--methods", ","],
     "--methods ',' names no method"),
    (["session", TASK, *SESSION, "--output", "{tmp}/P1", "--methods", "teleop,teleop"],
     "--methods teleop,teleop names a method twice"),
    (["driver-sim", TASK], "the scenario's robot needs hardware: !Arm's {driver: panda}"),
    (["run", TASK, "--no-meshcat", "--pilot", "lagy"],
     "--pilot: pilot 'lagy' is unknown; choose one of attentive, noisy, laggy, proportional, "
     "population (did you mean 'laggy'?)"),
    (["run", TASK, "--no-meshcat", "--operator", "keyboard", "--pilot", "noisy"],
     "--pilot: pilot 'noisy' stands in for the virtual participant: scenario.operator is "
     "!Keyboard"),
])
def test_a_flag_the_scenario_cannot_take_is_refused_in_one_line(repo, tmp_path, capsys, argv,
                                                                 message, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a default output folder would be made here
    argv = [str(repo / arg) if arg.endswith(".yaml") else arg.format(tmp=tmp_path)
            for arg in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("pbp-drake: ") and message.replace("{tmp}", str(tmp_path)) in err
    assert len(err.strip().splitlines()) == 1 and not any(tmp_path.iterdir())


def test_method_with_its_weight_sets_the_alpha_too():
    args = argparse.Namespace(method="fixed_alpha=0.3", operator=None, seed=None, duration=None,
                              alpha=None, hardware=False, driver_sim=False, settings=[],
                              scenario_text=None)
    overrides = scenario_overrides(args)
    assert overrides.settings == ("method=fixed_alpha", "alpha=0.3")
    assert overrides.typed == ("--method fixed_alpha=0.3",) * 2


def test_a_session_is_its_own_command_and_run_keeps_to_one_run(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["session", TASK])
    assert exit_info.value.code == 2
    assert "the following arguments are required: --participant" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    run_help = capsys.readouterr().out
    assert "--participant" not in run_help and "--answers" not in run_help
    assert "--set FIELD=VALUE" in run_help and "the page:" in run_help
    assert "(--record still saves a replay)" in " ".join(run_help.split())  # however wrapped
    with pytest.raises(SystemExit):
        main(["session", "--help"])
    assert "--record" not in capsys.readouterr().out  # a session has none


@pytest.mark.slow  # a whole session of two methods: 2 s
def test_a_session_with_fixed_answers_waits_for_no_browser(repo, tmp_path, capsys):
    # The virtual participant and --answers need no page: the session runs at once, even
    # with a page served and a long --wait-for-browser.
    started = time.monotonic()
    code = main(["session", str(repo / TASK), "--operator", "virtual", "--participant", "P01",
                 "--methods", "teleop", "--answers", "tiredness=3,ease=4", "--duration", "20",
                 "--realtime-rate", "20", "--wait-for-browser", "60", "--port", "0",
                 "--output", str(tmp_path / "P01")])
    elapsed = time.monotonic() - started
    out = capsys.readouterr().out
    assert code == 0, out
    assert elapsed < 30.0, f"took {elapsed:.1f} s"
    assert "Session saved in" in out and "Open http" not in out
