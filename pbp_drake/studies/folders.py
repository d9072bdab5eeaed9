"""Which study an output folder holds: a method comparison (study.json, trials/) or a 2-D
study (its summary.json), so that one kind is never written into the other's folder; and
its lock, so that one study at a time writes it."""

import contextlib
import fcntl
import os
import pathlib
import sys

from pbp_drake.studies.atomic_files import read_json, write_failed
from pbp_drake.studies.trial_files import (
    METHOD_COMPARISON, Damage, StudyFolderError, content_differences, name_damaged,
    scenario_content)

TOY_STUDIES = ("alpha_study", "alt_vs_cont")
#: The kind of a folder of every method under every pilot (`studies.matrix`).
MATRIX = "method_matrix"
# How check_folder's refusals name the kinds it checks: (the kind, what one study is).
_KIND_WORDS = {METHOD_COMPARISON: ("a method comparison", "study"),
               MATRIX: ("a matrix of methods and pilots", "matrix")}


def check_folder(output, scenario, digest, participant_condition=None, quiet=False,
                 kind=METHOD_COMPARISON):
    """Raises StudyFolderError when `output` holds a study of another kind than `kind` or of
    another scenario (naming another `participant_condition`); names a damaged study.json
    unless `quiet` (it is written again). Returns the readable study.json, or None."""
    held = folder_kind(output)
    what, one = _KIND_WORDS[kind]
    if held is not None and held != kind:
        raise StudyFolderError(f"{output} holds a study of kind {held!r}, not {what}: "
                               "choose another --output folder")
    study_path = pathlib.Path(output) / "study.json"
    if not study_path.is_file():
        return None
    study, problem = read_json(study_path)
    if problem is None and not isinstance(study, dict):
        problem = f"holds a {type(study).__name__}"
    if problem is not None:
        if not quiet:
            name_damaged([Damage(str(study_path), f"{problem}; written again")])
        return None
    if study.get("scenario_hash") != digest:
        recorded = study.get("participant_condition")
        condition = ("" if recorded == participant_condition else
                     f"; it was run with --participant-condition {recorded}" if recorded else
                     "; it was run without --participant-condition")
        differences = content_differences(study.get("scenario_content"),
                                          scenario_content(scenario))
        raise StudyFolderError(
            f"{output} holds a {one} of another scenario ({study.get('scenario')!r}, hash "
            f"{study.get('scenario_hash')}; this one is {scenario.name!r}, hash {digest}"
            f"{condition}{differences}): choose another --output folder")
    return study


def folder_kind(output):
    """Which study a folder holds: "method_comparison" (a study.json or trials/), the kind a
    study.json or summary.json names, or None (no study, or unreadable files)."""
    output = pathlib.Path(output)
    for name in ("study.json", "summary.json"):
        data, _ = read_json(output / name)
        if isinstance(data, dict) and isinstance(data.get("study"), str):
            return data["study"]
    return METHOD_COMPARISON if (output / "trials").is_dir() else None


# ---------------------------------------------------------------------------------------------
# The lock

LOCK_FILE = ".study.lock"


class FolderLocked(StudyFolderError):
    """Another process holds the study folder's lock: it is writing the folder."""


@contextlib.contextmanager
def study_lock(output):
    """Holds `output`'s lock (an flock on its LOCK_FILE, which holds the holder's process
    id) while the block runs. Raises FolderLocked, naming the holder, when another process
    holds it. On a file system without locks the block runs unlocked, after a line on stderr."""
    output = pathlib.Path(output)
    path = output / LOCK_FILE
    try:
        output.mkdir(parents=True, exist_ok=True)
        descriptor = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
    except OSError as error:
        raise write_failed(error, path) from error
    try:
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FolderLocked(
                f"{output} is being written by another study ({_holder(descriptor, path)}): "
                "wait for it to end, or stop it, and run this command again; give another "
                "--output to run both at once") from None
        except OSError as error:
            print(f"pbp-drake: cannot lock {path} ({error.strerror}): run one study at a "
                  "time on this folder", file=sys.stderr, flush=True)
            yield
            return
        try:
            os.ftruncate(descriptor, 0)
            os.pwrite(descriptor, f"{os.getpid()}\n".encode(), 0)
        except OSError:
            pass  # a full disk: the holder is then found through /proc/locks
        yield
    finally:
        os.close(descriptor)


def _holder(descriptor, path):
    """"process PID" of the lock's holder, from the lock file, else from /proc/locks."""
    text = os.pread(descriptor, 32, 0).decode(errors="replace").strip()
    if text.isdigit():
        return f"process {text}"
    inode = os.fstat(descriptor).st_ino
    try:
        lines = pathlib.Path("/proc/locks").read_text().splitlines()
    except OSError:
        lines = []
    for line in lines:
        fields = line.split()
        # `1: FLOCK  ADVISORY  WRITE 1234 00:2a:5678 0 EOF`: the pid, then MAJOR:MINOR:INODE.
        if len(fields) > 5 and fields[1] == "FLOCK" and fields[5].rsplit(":", 1)[-1] == str(
                inode) and fields[4].isdigit():
            return f"process {fields[4]}"
    return f"its process id is not in {path}"
