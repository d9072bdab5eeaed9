"""`run --record`, `run --output` and `study --output` are checked before anything is built or
simulated: a bad path is a user error (`pbp-drake: ...`, exit 2) that names the path, fast,
and an existing file that is not a replay is only overwritten with --force."""

import os
import time

import pytest

from pbp_drake.cli import main
from pbp_drake.output_paths import REPLAY_MARKER, is_replay, mark_replay

QUICK = "diagrams/toy_alt_vs_cont.yaml"  # about a second headless
FAST = 0.5  # seconds: far less than building and simulating the scenario


def refused(argv, capsys, path):
    """Runs the CLI, asserting it refuses with exit 2, fast, naming `path`, no traceback."""
    started = time.monotonic()
    code = main(argv)
    elapsed = time.monotonic() - started
    err = capsys.readouterr().err
    assert code == 2
    assert elapsed < FAST, f"took {elapsed:.2f} s: something ran before the check"
    assert err.startswith("pbp-drake: ") and str(path) in err
    assert "Traceback" not in err
    return err


def test_record_into_a_folder_is_refused(tmp_path, repo, capsys):
    err = refused(["run", str(repo / QUICK), "--headless", "--record", str(tmp_path)],
                  capsys, tmp_path)
    assert "is a folder" in err


def test_record_under_a_file_is_refused(tmp_path, repo, capsys):
    blocker = tmp_path / "notes.txt"
    blocker.write_text("not a folder")
    record = blocker / "replay.html"
    err = refused(["run", str(repo / QUICK), "--headless", "--record", str(record)],
                  capsys, record)
    assert str(blocker) in err and "is a file" in err
    assert blocker.read_text() == "not a folder"


@pytest.mark.slow
def test_record_over_a_file_that_is_not_a_replay_needs_force(tmp_path, repo, capsys):
    record = tmp_path / "thesis.html"
    record.write_text("<html>three years of work</html>")
    stamp = record.stat().st_mtime_ns
    err = refused(["run", str(repo / QUICK), "--headless", "--record", str(record)],
                  capsys, record)
    assert "--force" in err
    assert record.read_text() == "<html>three years of work</html>"
    assert record.stat().st_mtime_ns == stamp
    assert main(["run", str(repo / QUICK), "--headless", "--record", str(record),
                 "--force"]) == 0
    assert is_replay(record) and record.stat().st_size > 10_000
    assert f"Replay saved to {record}" in capsys.readouterr().out


@pytest.mark.slow
def test_record_writes_a_replay_and_overwrites_its_own(tmp_path, repo, capsys):
    record = tmp_path / "new" / "folder" / "replay.html"
    assert main(["run", str(repo / QUICK), "--headless", "--record", str(record)]) == 0
    assert is_replay(record) and "<script src=" not in record.read_text()
    record.write_text(mark_replay("<!DOCTYPE html>\n<html>an older replay</html>"))
    # A replay of a previous run is replaced without --force.
    assert main(["run", str(repo / QUICK), "--headless", "--record", str(record)]) == 0
    assert "an older replay" not in record.read_text() and is_replay(record)


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0,
                    reason="permissions do not bind root")
def test_record_into_a_read_only_folder_is_refused(tmp_path, repo, capsys):
    folder = tmp_path / "locked"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        record = folder / "replay.html"
        err = refused(["run", str(repo / QUICK), "--headless", "--record", str(record)],
                      capsys, record)
        assert "not writable" in err
    finally:
        folder.chmod(0o700)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes")
@pytest.mark.timeout(60)
@pytest.mark.parametrize("flag", ["--record", "--log"])
def test_an_output_that_is_a_pipe_is_refused_without_reading_it(flag, tmp_path, repo,
                                                                capsys):
    # Reading a pipe's first line waits for a writer (a device's, such as /dev/zero's, never
    # ends): an output that is not a regular file is never read, and needs --force.
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    err = refused(["run", str(repo / "diagrams" / "hsr_reach.yaml"), "--headless",
                   "--operator", "virtual", flag, str(pipe)], capsys, pipe)
    assert "is not a regular file (a device or a pipe); add --force" in err


@pytest.mark.parametrize("argv", [
    ["run", "{long}.yaml"], ["run", "{hsr}", "--log", "{long}.csv"],
    ["run", "{hsr}", "--record", "{long}.html"], ["study", "{hsr}", "--output", "{long}"],
    ["report", "{long}"], ["compare", "{long}", "{long}"],
    ["teach", "{hsr}", "--from", "{long}.csv", "--output", "{tmp}/primitive.json"],
    ["teach", "{hsr}", "--output", "{long}.json"], ["draw", "{hsr}", "--output", "{long}.svg"],
])
def test_a_name_too_long_for_the_file_system_is_one_line(argv, tmp_path, repo, capsys):
    # pathlib's exists and is_dir raise ENAMETOOLONG (a 300-character name): a traceback.
    long = tmp_path / ("l" * 300)
    words = {"long": long, "hsr": repo / "diagrams" / "hsr_reach.yaml", "tmp": tmp_path}
    err = refused([word.format(**words) for word in argv], capsys, long)
    assert err.endswith(": the name is too long (a file or folder name is at most 255 bytes, "
                        "a path 4,096)\n") and err.count("\n") == 1


@pytest.mark.parametrize("force", [[], ["--force"]])
@pytest.mark.parametrize("flag", ["--record", "--log"])
def test_an_output_that_is_a_link_to_nothing_is_named_so(flag, force, tmp_path, repo, capsys):
    # It was "the file exists and is not ...", and with --force "the file is not writable".
    dangling, loop = tmp_path / "dangling", tmp_path / "loop"
    dangling.symlink_to(tmp_path / "missing")
    loop.symlink_to(tmp_path / "back")
    (tmp_path / "back").symlink_to(loop)
    for link, target in ((dangling, tmp_path / "missing"), (loop, tmp_path / "back")):
        err = refused(["run", str(repo / QUICK), "--headless", flag, str(link), *force],
                      capsys, link)
        assert err == (f"pbp-drake: {flag} {link}: is a symbolic link to nothing (its target "
                       f"{target} is missing, or the links loop); give another path\n")


def test_study_output_that_is_a_file_is_refused(tmp_path, repo, capsys):
    output = tmp_path / "summary.txt"
    output.write_text("keep me")
    err = refused(["study", str(repo / QUICK), "--output", str(output)], capsys, output)
    assert "is a file" in err
    assert output.read_text() == "keep me"


def test_study_output_under_a_file_is_refused(tmp_path, repo, capsys):
    blocker = tmp_path / "summary.txt"
    blocker.write_text("keep me")
    output = blocker / "study"
    refused(["study", str(repo / "diagrams/hsr_reach.yaml"), "--trials", "1", "--output",
             str(output)], capsys, output)
    assert blocker.read_text() == "keep me"


@pytest.mark.parametrize("command", [["study", "--trials", "1"],
                                     ["session", "--participant", "P01", "--headless"]])
def test_an_output_folder_that_is_a_link_to_nothing_is_named_so(command, tmp_path, repo,
                                                                capsys):
    # Its folder could not be made: "cannot write .../.study.lock: file exists", exit 4.
    output = tmp_path / "study"
    output.symlink_to(tmp_path / "missing")
    err = refused([command[0], str(repo / "diagrams/hsr_reach.yaml"), *command[1:],
                   "--output", str(output)], capsys, output)
    assert err == (f"pbp-drake: --output {output}: is a symbolic link to nothing (its target "
                   f"{tmp_path / 'missing'} is missing, or the links loop); give another "
                   "folder\n")


def test_session_output_that_is_a_file_is_refused(tmp_path, repo, capsys):
    output = tmp_path / "P01"
    output.write_text("keep me")
    refused(["run", str(repo / "diagrams/hsr_reach.yaml"), "--operator", "virtual",
             "--headless", "--participant", "P01", "--output", str(output)], capsys, output)
    assert output.read_text() == "keep me"


def test_the_replay_marker_follows_the_doctype():
    html = mark_replay("<!DOCTYPE html>\n<html></html>")
    assert html.splitlines()[:2] == ["<!DOCTYPE html>", REPLAY_MARKER]
    assert mark_replay("<html></html>").startswith(REPLAY_MARKER)


def test_a_log_that_passed_its_check_but_cannot_be_opened_is_one_line(tmp_path, repo,
                                                                       monkeypatch, capsys):
    # As on a file system where the check's answer is wrong (/proc, as root): the open fails.
    log = str(tmp_path / "run.csv")

    def cannot_open(resolved, log_path, **options):
        raise FileNotFoundError(2, "No such file or directory", log_path)

    monkeypatch.setattr("pbp_drake.commands.task_runs.run_task_streamed", cannot_open)
    code = main(["run", str(repo / "diagrams" / "hsr_reach.yaml"), "--headless", "--operator",
                 "virtual", "--log", log])
    err = capsys.readouterr().err
    assert code == 4
    assert err.strip().splitlines() == [
        f"pbp-drake: cannot write {log}: no such file or directory; nothing is left "
        "half-written: make the folder writable, then run the same command again."]


def test_a_log_whose_write_fails_names_the_log(tmp_path, repo, monkeypatch, capsys):
    # A write's OSError names no file (as /dev/full's with --force): "cannot write a file".
    log = str(tmp_path / "run.csv")

    def disk_full(resolved, log_path, **options):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("pbp_drake.commands.task_runs.run_task_streamed", disk_full)
    code = main(["run", str(repo / "diagrams" / "hsr_reach.yaml"), "--headless", "--operator",
                 "virtual", "--log", log])
    assert code == 4
    assert capsys.readouterr().err.strip().splitlines() == [
        f"pbp-drake: cannot write {log}: no space left on device; nothing is left "
        "half-written: free some space, then run the same command again."]
