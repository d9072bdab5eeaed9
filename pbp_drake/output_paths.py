"""Checks of the command line's output paths, made before anything is built or simulated:
`run --record FILE.html`, `run --log FILE.csv`, `run --output DIR` and `study --output DIR`. A path that cannot be
written is a user error (a ScenarioError: `pbp-drake: ...`, exit 2), not a lost run."""

import os
import pathlib

from pbp_drake.builder.time_series import time_series_header
from pbp_drake.scenarios import ScenarioError

# Written into every replay just after its doctype: an existing file that holds it is a
# replay of a previous `pbp-drake run --record`, and may be overwritten without --force.
REPLAY_MARKER = "<!-- pbp-drake replay (pbp-drake run --record) -->"
_MARKER_WINDOW = 4096  # bytes read from the top of an existing file to find the marker


class OutputPathError(ScenarioError):
    """An output path that cannot, or may not, be written."""


def mark_replay(html):
    """The replay `html` (Meshcat's StaticHtml) with REPLAY_MARKER after its doctype."""
    head, newline, rest = html.partition("\n")
    if head.lower().startswith("<!doctype") and newline:
        return f"{head}\n{REPLAY_MARKER}\n{rest}"
    return f"{REPLAY_MARKER}\n{html}"


def is_replay(path):
    """Whether the file at `path` is a replay written by `pbp-drake run --record`."""
    try:
        with open(path, "rb") as stream:
            head = stream.read(_MARKER_WINDOW)
    except OSError:
        return False
    return REPLAY_MARKER.encode() in head


def check_record_path(path, force=False):
    """Raises OutputPathError unless `path` can take a replay: not a folder, its folder
    exists or can be made and is writable, and an existing file there is a previous replay
    (or `force` is set)."""
    _check_output_file(path, "--record", "replay.html", is_replay, "a replay", force)


def check_log_path(path, force=False):
    """Raises OutputPathError unless `path` can take a run's per-tick CSV: not a folder, its
    folder exists or can be made and is writable, and an existing file there is a previous
    time series CSV (its header is the trial CSV's) or `force` is set."""
    _check_output_file(path, "--log", "run.csv", _is_time_series, "a time series", force)


def _check_output_file(path, flag, example, is_ours, kind, force):
    """The checks both output files share: `path` is not a folder (`example` names a file
    in it), an existing file there is one `is_ours` recognises (`kind`, written by
    pbp-drake) or `force` is set, and it or its folder is writable."""
    file = pathlib.Path(path)
    if file.is_dir():
        raise OutputPathError(f"{flag} {file}: is a folder; give a file, e.g. "
                              f"{file / example}")
    if file.exists() or file.is_symlink():
        if not force and not is_ours(file):
            raise OutputPathError(f"{flag} {file}: the file exists and is not {kind} "
                                  f"written by pbp-drake; add --force to overwrite it")
        if not os.access(file, os.W_OK):
            raise OutputPathError(f"{flag} {file}: the file is not writable")
        return
    _check_can_create(file.parent, f"{flag} {file}")


def _is_time_series(path):
    try:
        with open(path, newline="") as stream:
            head = stream.readline()
    except (OSError, UnicodeDecodeError):
        return False
    # The reach tasks' (with or without in_collision) and the grasping task's.
    return head in (time_series_header(False), time_series_header(True),
                    time_series_header(False, has_grasp=True))


def check_output_folder(path, option="--output"):
    """Raises OutputPathError unless `path` is a writable folder or can be made one."""
    output = pathlib.Path(path)
    if output.exists() and not output.is_dir():
        raise OutputPathError(f"{option} {output}: is a file, not a folder; give a folder "
                              f"for the results")
    if output.is_dir():
        if not os.access(output, os.W_OK | os.X_OK):
            raise OutputPathError(f"{option} {output}: the folder is not writable")
        return
    _check_can_create(output, f"{option} {output}")


def _check_can_create(folder, what):
    """Raises OutputPathError unless `folder` is, or can be made, a writable folder: its
    nearest existing ancestor must be a writable folder."""
    folder = pathlib.Path(os.path.abspath(folder))
    ancestor = folder
    while not ancestor.exists():
        if ancestor.parent == ancestor:
            break
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise OutputPathError(f"{what}: {ancestor} is a file, so its folder cannot be made")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        where = "its folder" if ancestor == folder else f"{ancestor}"
        raise OutputPathError(f"{what}: {where} is not writable")
