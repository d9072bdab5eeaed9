"""Nothing lost on a bad disk, SIGTERM, and one study per folder.

A study or report whose disk fills (a small tmpfs, mounted when the tests run as root) says
so in one line, exit 4, leaves no temporary file and records no trial as failed; freed, the
same command ends with the summary of an uninterrupted study, byte for byte. SIGTERM stops
a study as Ctrl-C does. A study folder is locked while a study writes it: a second study
is refused, naming the first one's process, and the lock dies with that process."""

import errno
import json
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from pbp_drake.builder.run import TaskResult
from pbp_drake.cli import main
from pbp_drake.studies.atomic_files import WriteFailed, remove_leftovers, write_atomically
from pbp_drake.studies.comparison import run_method_comparison, run_method_matrix
from pbp_drake.studies.folders import LOCK_FILE, FolderLocked
from pbp_drake.scenarios import load_scenario_file

ROOT = pathlib.Path(__file__).resolve().parents[2]
# 6 s of simulated time: each trial ends at its time limit, before the target (about 17 s
# in these scenes), a third of a whole task; what the tests here prove (the files, their
# bytes, resuming, the processes) holds of any trial.
TASK = """
scenario:
  name: two_random_objects
  method: teleop
  control_period: 0.03
  duration: 6.0
  robot: !Hsr {}
  task:
    object_count: [2, 2]
  operator: !VirtualParticipant {}
  seed: 0
"""
METHODS = ["pbp_alternated", "teleop"]
PAGE = 4096  # a tmpfs gives every file whole pages


@pytest.fixture(scope="module")
def task_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("task") / "task.yaml"
    path.write_text(textwrap.dedent(TASK))
    return path


@pytest.fixture(scope="module")
def scenario(task_file):
    return load_scenario_file(task_file).scenario


def fake_run(resolved):
    """A TaskResult drawn from the seed, without simulating (module level: the workers
    import it)."""
    scenario = resolved.scenario
    rng = np.random.default_rng(scenario.seed)
    ticks = 5
    return TaskResult(
        success=bool(scenario.seed % 2), task_time=float(rng.uniform(5, 20)),
        intervention_ratio=float(rng.random()), switches=2,
        times=0.03 * np.arange(ticks), ee_positions=rng.normal(size=(ticks, 3)),
        headings=rng.normal(size=ticks), commands=rng.normal(size=(ticks, 7)),
        operator_active=rng.random(ticks) < 0.5, operator_commands=rng.normal(size=(ticks, 4)),
        selected_goals=rng.integers(0, 2, ticks), targets=rng.integers(0, 2, ticks),
        objects=rng.normal(size=(2, 3)), collision_ratio=0.0)


def _mount_tmpfs(folder, size):
    if os.geteuid() != 0:
        pytest.skip("mounting a small tmpfs needs root (the tests run as a user)")
    folder.mkdir(parents=True, exist_ok=True)
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs",
                              str(folder)], capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip()}")


def _resize(folder, size):
    subprocess.run(["mount", "-o", f"remount,size={size}", str(folder)], check=True)


@pytest.fixture
def small_disk(tmp_path):
    """A function mounting a tmpfs of the size given at tmp_path/disk; unmounted after."""
    folder = tmp_path / "disk"
    mounted = []

    def mount(size):
        _mount_tmpfs(folder, size)
        mounted.append(folder)
        return folder

    yield mount
    for path in mounted:
        subprocess.run(["umount", "-l", str(path)], check=False)


def _fill(disk):
    """Fills `disk` to its last byte; returns the filler file (removed: freed)."""
    filler = disk / "filler"
    with open(filler, "wb", buffering=0) as stream:
        try:
            while True:
                stream.write(b"\0" * PAGE)
        except OSError as error:
            assert error.errno == errno.ENOSPC
    return filler


def _leftovers(folder):
    return [p for p in folder.rglob("*") if p.suffix in (".tmp", ".running")]


def test_leftovers_beside_the_summary_go_once_their_writer_has_ended(tmp_path):
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    gone, own = (tmp_path / f".summary.json.{pid}.tmp" for pid in (ended.stdout.strip(),
                                                                     os.getpid()))
    running = tmp_path / f".results.md.{os.getppid()}.tmp"  # a report writing it now
    for path in (gone, own, running):
        path.write_text("half")
    remove_leftovers(tmp_path)
    assert [path.name for path in tmp_path.iterdir()] == [running.name]


def test_a_device_is_written_into_never_replaced_by_a_file(tmp_path):
    # `report --markdown /dev/null` (or /dev/stdout) renamed a regular file over the device.
    null, full = tmp_path / "null.md", tmp_path / "full.md"
    null.symlink_to(os.devnull)
    full.symlink_to("/dev/full")
    write_atomically(null, "# results\n")
    with pytest.raises(WriteFailed, match="no space left on device"):
        write_atomically(full, "# results\n")
    assert null.is_char_device() and full.is_char_device()
    assert sorted(path.name for path in tmp_path.iterdir()) == ["full.md", "null.md"]


@pytest.mark.timeout(60)
def test_a_pipe_is_written_into_when_read_and_else_left_alone(tmp_path):
    # A pipe read by a process (/dev/stdout into `| less`) got a regular file in its place;
    # one that none reads (its open would wait for a reader) was replaced by a file.
    read, unread = tmp_path / "read.md", tmp_path / "unread.md"
    os.mkfifo(read)
    os.mkfifo(unread)
    reader = os.open(read, os.O_RDONLY | os.O_NONBLOCK)
    try:
        write_atomically(read, "# results\n")
        assert os.read(reader, 100) == b"# results\n" and read.is_fifo()
    finally:
        os.close(reader)
    with pytest.raises(WriteFailed) as refused:
        write_atomically(unread, "# results\n")
    assert str(refused.value) == (f"cannot write {unread}: not a regular file (a block "
                                  "device, a socket or a pipe no process reads)")
    assert refused.value.remedy == "give a regular file" and unread.is_fifo()
    assert sorted(path.name for path in tmp_path.iterdir()) == ["read.md", "unread.md"]


def test_a_link_is_written_through_not_replaced_by_a_file(tmp_path):
    # `--markdown /dev/stdout > FILE` renamed a regular file over /dev/stdout (as root).
    target, link = tmp_path / "results.md", tmp_path / "link.md"
    target.write_text("old")
    link.symlink_to(target)
    write_atomically(link, "# results\n")
    assert link.is_symlink() and target.read_text() == "# results\n"
    assert sorted(path.name for path in tmp_path.iterdir()) == ["link.md", "results.md"]


# A command that prints a line, writes a file whole at /dev/stdout, then prints another.
_PRINTS_AROUND_STDOUT = ("from pbp_drake.studies.atomic_files import write_atomically; "
                         "print('before'); write_atomically('/dev/stdout', '# results\\n'); "
                         "print('after')")


@pytest.mark.parametrize("into", ["a file", "a pipe"])
def test_the_commands_own_stdout_gets_the_file_between_its_lines(tmp_path, into):
    # `report --markdown /dev/stdout > FILE` renamed a new file over FILE, where the report's
    # later lines were lost; into a pipe it failed: `cannot write /proc/N/fd/pipe:[M]`.
    command = [sys.executable, "-c", _PRINTS_AROUND_STDOUT]
    if into == "a file":
        with open(tmp_path / "out.md", "w") as stream:
            subprocess.run(command, stdout=stream, check=True)
        printed = (tmp_path / "out.md").read_text()
    else:
        printed = subprocess.run(command, capture_output=True, text=True, check=True).stdout
    assert printed == "before\n# results\nafter\n"
    assert [path.name for path in tmp_path.iterdir()] == (["out.md"] if into == "a file"
                                                          else [])


@pytest.mark.timeout(60)
def test_a_closed_stdout_is_a_broken_pipe_as_for_the_commands_prints():
    # `--markdown /dev/stdout | head -1`: the CLI ends quietly on a BrokenPipeError, as when
    # a print meets the closed pipe; a WriteFailed said "make the folder writable".
    writer = subprocess.Popen([sys.executable, "-c", (
        "import sys; from pbp_drake.studies.atomic_files import write_atomically\n"
        "try:\n    write_atomically('/dev/stdout', 'x' * 200_000)\n"
        "except BrokenPipeError:\n    sys.exit(7)")], stdout=subprocess.PIPE)
    writer.stdout.close()
    assert writer.wait() == 7


def test_a_file_where_a_folder_belongs_is_named_as_what_to_move(tmp_path):
    # A study resumed into a folder whose `trials` was a file: "make the folder writable".
    (tmp_path / "trials").write_text("not a folder")
    with pytest.raises(WriteFailed) as failed:
        write_atomically(tmp_path / "trials" / "teleop" / "seed_1.json", "{}")
    assert failed.value.remedy == (f"move the file {tmp_path / 'trials'} away (a folder "
                                   "belongs there)")


def test_a_file_whose_name_is_near_the_longest_is_written(tmp_path):
    # Its temporary file's name (`.NAME.PID.tmp`) passed 255 bytes: WriteFailed, once the
    # run whose replay it was had ended.
    path = tmp_path / ("é" * 120 + "r.html")  # 252 bytes
    write_atomically(path, "replay")
    assert path.read_text() == "replay" and len(list(tmp_path.iterdir())) == 1


def _trial_records(folder):
    return [json.loads(p.read_text()) for p in (folder / "trials").glob("*/seed_*.json")]


@pytest.mark.slow
@pytest.mark.parametrize("jobs", [1, 2])
def test_a_full_disk_stops_the_study_and_freed_it_ends_as_an_uninterrupted_one(
        scenario, tmp_path, small_disk, jobs):
    whole = tmp_path / "whole"
    run_method_comparison(scenario, METHODS, 6, 5, whole, run=fake_run)
    # study.json, the lock and a few trials (two one-page files each) fit; twelve do not.
    disk = small_disk(16 * PAGE)
    folder = disk / "study"
    with pytest.raises(WriteFailed) as stopped:
        run_method_comparison(scenario, METHODS, 6, 5, folder, jobs=jobs, run=fake_run)
    assert stopped.value.errno == errno.ENOSPC
    assert str(stopped.value).startswith(f"cannot write {folder}")
    assert "no space left on device" in str(stopped.value)
    written = _trial_records(folder)
    assert 0 < len(written) < 12
    assert all(record["error"] is None for record in written)  # the disk is no trial's fault
    assert _leftovers(folder) == []

    _resize(disk, "8m")
    ran = []
    summary = run_method_comparison(scenario, METHODS, 6, 5, folder, jobs=jobs, run=fake_run,
                                    progress=lambda done, *_: ran.append(done))
    assert len(ran) == 12 - len(written)
    assert summary["methods"]["teleop"]["errors"] == 0
    assert (folder / "summary.json").read_bytes() == (whole / "summary.json").read_bytes()
    assert _leftovers(folder) == []


@pytest.mark.slow
def test_a_full_disk_stops_a_matrix_and_freed_it_ends_as_an_uninterrupted_one(
        scenario, tmp_path, small_disk):
    pilots = ["attentive", "noisy"]
    whole = tmp_path / "whole"
    run_method_matrix(scenario, METHODS, pilots, 3, 5, whole, run=fake_run)
    disk = small_disk(20 * PAGE)
    folder = disk / "matrix"
    with pytest.raises(WriteFailed, match="no space left on device"):
        run_method_matrix(scenario, METHODS, pilots, 3, 5, folder, run=fake_run)
    written = [r for pilot in pilots for r in _trial_records(folder / "pilots" / pilot)]
    assert 0 < len(written) < 12 and all(record["error"] is None for record in written)
    assert _leftovers(folder) == []
    _resize(disk, "8m")
    run_method_matrix(scenario, METHODS, pilots, 3, 5, folder, run=fake_run)
    assert (folder / "summary.json").read_bytes() == (whole / "summary.json").read_bytes()


@pytest.mark.slow
def test_report_on_a_full_disk_says_so_in_one_line_and_leaves_nothing_half_written(
        scenario, tmp_path, small_disk, capsys):
    disk = small_disk("1m")
    folder = disk / "study"
    run_method_comparison(scenario, METHODS, 3, 5, folder, run=fake_run)
    expected = (folder / "summary.json").read_bytes()
    for name in ("summary.json", "results.md", "trials.json", "fig7a_intervention.png"):
        (folder / name).unlink()
    capsys.readouterr()
    filler = _fill(disk)
    assert main(["report", str(folder)]) == 4
    err = capsys.readouterr().err
    assert err.splitlines() == [
        f"pbp-drake: cannot write {folder / 'summary.json'}: no space left on device; nothing "
        "is left half-written: free some space, then the same command resumes."]
    assert not (folder / "summary.json").exists() and _leftovers(folder) == []

    filler.unlink()
    assert main(["report", str(folder)]) == 0
    assert (folder / "summary.json").read_bytes() == expected


@pytest.mark.slow
def test_report_on_a_read_only_disk_names_the_file_and_what_to_do(scenario, small_disk,
                                                                  capsys):
    disk = small_disk("1m")
    folder = disk / "study"
    run_method_comparison(scenario, METHODS, 2, 5, folder, run=fake_run)
    before = {path: path.read_bytes() for path in folder.rglob("*") if path.is_file()}
    capsys.readouterr()
    subprocess.run(["mount", "-o", "remount,ro", str(disk)], check=True)
    assert main(["report", str(folder)]) == 4
    assert capsys.readouterr().err.splitlines() == [
        f"pbp-drake: cannot write {folder / 'summary.json'}: read-only file system; nothing "
        "is left half-written: make the file system writable, then the same command resumes."]
    assert {path: path.read_bytes() for path in folder.rglob("*") if path.is_file()} == before


def _hold_lock(folder, write_pid=True):
    """A process holding `folder`'s study lock (as `study_lock`, or a bare flock that
    writes no process id) until it is killed; returns it once it holds the lock."""
    code = ("import fcntl, os, pathlib, sys\n"
            "from pbp_drake.studies.folders import study_lock\n"
            f"folder = pathlib.Path({str(folder)!r})\n"
            + ("with study_lock(folder):\n    print('held', flush=True)\n    sys.stdin.read()\n"
               if write_pid else
               "folder.mkdir(parents=True, exist_ok=True)\n"
               f"fd = os.open(folder / {LOCK_FILE!r}, os.O_RDWR | os.O_CREAT)\n"
               "fcntl.flock(fd, fcntl.LOCK_EX)\n"
               "print('held', flush=True)\nsys.stdin.read()\n"))
    holder = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True,
                              env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert holder.stdout.readline() == "held\n"
    return holder


@pytest.mark.slow
@pytest.mark.parametrize("write_pid", [True, False], ids=["pid in the file", "in /proc/locks"])
def test_a_locked_folder_is_refused_naming_the_holder_and_freed_when_it_dies(
        scenario, tmp_path, write_pid):
    folder = tmp_path / "study"
    holder = _hold_lock(folder, write_pid)
    try:
        with pytest.raises(FolderLocked, match=f"being written by another study "
                                               rf"\(process {holder.pid}\)"):
            run_method_comparison(scenario, METHODS, 2, 5, folder, run=fake_run)
        assert sorted(p.name for p in folder.iterdir()) == [LOCK_FILE]  # nothing written
    finally:
        holder.kill()  # kill -9: the lock goes with the process
        holder.wait()
    summary = run_method_comparison(scenario, METHODS, 2, 5, folder, run=fake_run)
    assert summary["methods"]["teleop"]["trials"] == 2


@pytest.mark.slow
@pytest.mark.parametrize("pilots", [None, "attentive,noisy"])
def test_the_command_refuses_a_locked_folder_with_exit_2(task_file, tmp_path, capsys, pilots):
    folder = tmp_path / "study"
    holder = _hold_lock(folder)
    try:
        args = ["study", str(task_file), "--methods", "teleop", "--trials", "2",
                "--output", str(folder)] + (["--pilots", pilots] if pilots else [])
        assert main(args) == 2
    finally:
        holder.kill()
        holder.wait()
    assert (f"pbp-drake: {folder} is being written by another study (process {holder.pid})"
            in capsys.readouterr().err)
    assert sorted(p.name for p in folder.iterdir()) == [LOCK_FILE]


# ---------------------------------------------------------------------------------------------
# The command, with real trials


def study_command(task_file, output, jobs=2):
    return [sys.executable, "-m", "pbp_drake", "study", str(task_file), "--methods", "teleop",
            "--trials", "4", "--jobs", str(jobs), "--output", str(output)]


ENV = dict(os.environ, PYTHONPATH=str(ROOT))


@pytest.fixture(scope="module")
def uninterrupted(task_file, tmp_path_factory):
    """The study run whole, on a disk with room."""
    folder = tmp_path_factory.mktemp("uninterrupted") / "study"
    subprocess.run(study_command(task_file, folder), env=ENV, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return folder


def _wait_for(condition, process, what, timeout=120):
    deadline = time.monotonic() + timeout
    while not condition():
        assert process.poll() is None, f"the study ended before {what}"
        assert time.monotonic() < deadline, f"no {what} within {timeout} s"
        time.sleep(0.05)


def _group(pgid):
    """The live processes of process group `pgid` (by /proc)."""
    found = []
    for entry in pathlib.Path("/proc").iterdir():
        try:
            text = (entry / "stat").read_text()
        except (OSError, ValueError):
            continue
        fields = text[text.rindex(")") + 2:].split()
        if fields[0] != "Z" and int(fields[2]) == pgid:
            found.append(int(entry.name))
    return found


@pytest.mark.slow
def test_a_study_on_a_small_disk_gives_one_line_and_resumes_to_the_same_bytes(
        task_file, uninterrupted, small_disk):
    trial_bytes = sum(p.stat().st_size for p in (uninterrupted / "trials").rglob("seed_*"))
    disk = small_disk(trial_bytes // 2 + 16 * PAGE)  # room for about half of the trials
    folder = disk / "study"
    stopped = subprocess.run(study_command(task_file, folder), env=ENV, capture_output=True,
                             text=True)
    assert stopped.returncode == 4
    last = stopped.stderr.splitlines()[-1]
    assert last.startswith(f"pbp-drake: cannot write {folder}")
    assert last.endswith("no space left on device; nothing is left half-written: free some "
                         "space, then the same command resumes.")
    assert "Traceback" not in stopped.stderr and stopped.stderr.count("pbp-drake:") == 1
    assert _leftovers(folder) == []
    assert all(record["error"] is None for record in _trial_records(folder))

    _resize(disk, "16m")
    resumed = subprocess.run(study_command(task_file, folder), env=ENV, capture_output=True,
                             text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert (folder / "summary.json").read_bytes() == (uninterrupted / "summary.json").read_bytes()


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigterm_stops_a_study_as_ctrl_c_and_the_same_command_resumes(
        task_file, uninterrupted, tmp_path):
    folder = tmp_path / "study"
    study = subprocess.Popen(study_command(task_file, folder), env=ENV, text=True,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             start_new_session=True)  # its own process group: all it starts
    running = lambda: list((folder / "trials").glob("*/*.running"))  # noqa: E731
    _wait_for(lambda: len(running()) == 2, study, "two trials running")
    workers = [int(path.read_text()) for path in running()]
    assert len(_group(study.pid)) >= 4  # the study, the fork server, the tracker, workers
    study.send_signal(signal.SIGTERM)
    _, err = study.communicate(timeout=60)  # until every process holding stderr has ended
    assert study.returncode == 143
    assert (f"Terminated (SIGTERM): the finished trials are in {folder / 'trials'}; the same "
            "command resumes the study.") in err
    assert "leaked semaphore" not in err and "Traceback" not in err
    deadline = time.monotonic() + 10
    while _group(study.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _group(study.pid) == [], "processes of the study outlived it"
    assert not any(pathlib.Path(f"/proc/{pid}").exists() for pid in workers)
    assert _leftovers(folder) == []

    resumed = subprocess.run(study_command(task_file, folder), env=ENV, capture_output=True,
                             text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert (folder / "summary.json").read_bytes() == (uninterrupted / "summary.json").read_bytes()


@pytest.mark.slow
def test_a_second_study_on_a_folder_being_written_is_refused_with_the_first_ones_pid(
        task_file, uninterrupted, tmp_path):
    folder = tmp_path / "study"
    first = subprocess.Popen(study_command(task_file, folder, jobs=1), env=ENV,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _wait_for(lambda: list((folder / "trials").glob("*/*.running")), first, "a trial running")
    # Stopped (SIGSTOP), the first study holds its folder however short its trials are.
    first.send_signal(signal.SIGSTOP)
    second = subprocess.run(study_command(task_file, folder), env=ENV, capture_output=True,
                            text=True)
    assert second.returncode == 2
    assert (f"pbp-drake: {folder} is being written by another study (process {first.pid})"
            in second.stderr)
    first.kill()  # kill -9 (a stopped process too): its lock goes with it
    first.wait()
    resumed = subprocess.run(study_command(task_file, folder), env=ENV, capture_output=True,
                             text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert (folder / "summary.json").read_bytes() == (uninterrupted / "summary.json").read_bytes()


@pytest.mark.slow
def test_a_replay_on_a_full_disk_is_one_line_and_no_half_written_file(small_disk, capsys):
    disk = small_disk("1m")
    record = disk / "replay.html"
    _fill(disk)
    capsys.readouterr()
    assert main(["run", str(ROOT / "diagrams" / "toy_alpha_study.yaml"), "--scene",
                 "scene_1", "--method", "pbp_alternated", "--headless", "--record",
                 str(record)]) == 4
    assert capsys.readouterr().err.splitlines() == [
        f"pbp-drake: cannot write {record}: no space left on device; nothing is left "
        "half-written: free some space, then run the same command again."]
    assert not record.exists() and _leftovers(disk) == []
