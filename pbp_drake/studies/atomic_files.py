"""Writing a study's files whole or not at all: each goes to a temporary file beside it
(`.NAME.PID.tmp`), flushed, then renamed over its name. A write that fails (no space, a
quota, a read-only or failing disk) removes its temporary file and raises WriteFailed: the
study stops with nothing half-written, the failure is never a trial's result, and the
same command resumes it (docs/tasks/studies.md, "The folder").
"""

import contextlib
import errno
import json
import os
import pathlib
import shutil
import sys
import tempfile

from pbp_drake.scenarios.bounds import is_special_file

# The errors that mean the disk, not the study, failed; what the person can do about each.
DISK_ERRORS = {
    errno.ENOSPC: "free some space",
    errno.EDQUOT: "free some space or raise the disk quota",
    errno.EFBIG: "free some space or raise the file size limit",
    errno.EROFS: "make the file system writable",
    errno.EIO: "check the disk",
}


#: The largest study file read back (bytes): a trial's JSON with 100,000 goals is near 6 MB,
#: a trial's CSV about 9 KB a simulated second.
MOST_READ_BYTES = 64 << 20
#: The longest file name (bytes) of the usual file systems (ext4, btrfs, XFS, tmpfs: NAME_MAX).
MOST_NAME_BYTES = 255


class WriteFailed(OSError):
    """A file could not be written (OSError's `filename`, `errno`, `strerror`)."""

    def __str__(self):
        reason = (self.strerror or "failed").rstrip(".")
        where = "a file" if self.filename is None else self.filename
        return f"cannot write {where}: {reason[:1].lower()}{reason[1:]}"

    @property
    def remedy(self):
        """What the person can do before running the same command again."""
        if self.errno == errno.EINVAL:  # `writing`'s refusal of a special file
            return "give a regular file"
        if self.errno == errno.ENOTDIR and self.filename is not None:
            # os.path's tests, which never raise: this runs while a failure is reported.
            in_the_way = next((folder for folder in reversed(pathlib.Path(self.filename).parents)
                               if os.path.exists(folder) and not os.path.isdir(folder)), None)
            if in_the_way is not None:
                return f"move the file {in_the_way} away (a folder belongs there)"
        return DISK_ERRORS.get(self.errno, "make the folder writable")


def write_failed(error, path):
    """`error`, an OSError met while writing `path`, as a WriteFailed naming `path`."""
    if isinstance(error, WriteFailed):
        return error
    return WriteFailed(error.errno, error.strerror or str(error),
                       None if path is None else str(path))


def write_failure_line(error, then="the same command resumes"):
    """The one line a command prints for a disk failure: the file, the reason, what to do,
    `then` what the same command does."""
    error = write_failed(error, error.filename)
    return f"pbp-drake: {error}; nothing is left half-written: {error.remedy}, then {then}."


def is_disk_failure(error):
    """Whether `error` says the disk failed (see DISK_ERRORS), not the code that met it."""
    return isinstance(error, WriteFailed) or (isinstance(error, OSError)
                                              and error.errno in DISK_ERRORS)


@contextlib.contextmanager
def writing(path):
    """Yields the temporary path to write `path` through, then flushes and renames it to
    `path`. Any error removes it; an OSError is raised as WriteFailed naming `path`. A
    character device (e.g. /dev/null, or /dev/stdout: a link to one) or a pipe a process
    reads is written into, as a shell's `>` does: a rename would put a regular file in its
    place (of /dev/stdout itself, as root). A block device, a socket or a pipe that none
    reads (its open would wait for a reader) is neither written nor replaced: WriteFailed.
    A symbolic link is written through, to the file it leads to. This process's own stdout
    or stderr (`--markdown /dev/stdout`, into a pipe or a shell's `> FILE`) is written
    through its descriptor, after what the command printed before: a new open would have
    truncated FILE, a rename detached it."""
    path = pathlib.Path(path)
    stream = _own_stream(path)
    if stream is not None:
        yield from _through_descriptor(stream, path)
        return
    if path.is_symlink() and path.exists():  # the file it leads to, not a file over the link
        path = pathlib.Path(os.path.realpath(path))
    reader = _pipe_with_reader(path)
    if path.is_char_device() or reader is not None:
        try:
            # The pipe through the descriptor held open: its reader sees no end between opens.
            yield path if reader is None else pathlib.Path(f"/dev/fd/{reader}")
        except OSError as error:
            raise write_failed(error, path) from error
        finally:
            if reader is not None:
                os.close(reader)
        return
    if is_special_file(path):
        raise WriteFailed(errno.EINVAL, "not a regular file (a block device, a socket or a "
                          "pipe no process reads)", str(path))
    temporary = _temporary(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        yield temporary
        descriptor = os.open(temporary, os.O_RDONLY)
        try:
            os.fsync(descriptor)
        finally:
            os.close(descriptor)
        os.replace(temporary, path)
    except BaseException as error:
        with contextlib.suppress(OSError):
            temporary.unlink(missing_ok=True)
        if isinstance(error, OSError):
            raise write_failed(error, path) from error
        raise


def _own_stream(path):
    """1 or 2 when `path` is the file, pipe or terminal this process's stdout or stderr
    writes to; else None."""
    try:
        target = os.stat(path)
    except OSError:
        return None
    for descriptor in (1, 2):
        with contextlib.suppress(OSError):
            if os.path.samestat(target, os.fstat(descriptor)):
                return descriptor
    return None


def _through_descriptor(descriptor, path):
    """`writing`'s steps for this process's stdout or stderr (`descriptor`): the text goes
    to a temporary file, then through the descriptor after Python's own buffered lines."""
    try:
        with tempfile.TemporaryDirectory(prefix="pbp-drake-") as folder:
            temporary = pathlib.Path(folder) / path.name
            yield temporary
            sys.stdout.flush()
            sys.stderr.flush()
            with open(temporary, "rb") as source, os.fdopen(
                    os.dup(descriptor), "wb") as destination:
                shutil.copyfileobj(source, destination)
    except BrokenPipeError:  # its reader has gone (`| head`): as for the command's prints
        raise
    except OSError as error:
        raise write_failed(error, path) from error


def _pipe_with_reader(path):
    """A descriptor open for writing (blocking) on the named pipe at `path` when a process
    reads it; None for anything else, a pipe without a reader too."""
    if not path.is_fifo():
        return None
    try:
        descriptor = os.open(path, os.O_WRONLY | os.O_NONBLOCK)  # ENXIO: no reader
    except OSError:
        return None
    os.set_blocking(descriptor, True)
    return descriptor


def read_text(path, most=MOST_READ_BYTES):
    """The UTF-8 text of the study file at `path` (as Path.read_text). Raises OSError naming
    it, without reading it, for a device or a pipe (/dev/zero never ends, a pipe's open waits
    for a writer), and having read no more than `most` bytes for a larger file."""
    if is_special_file(path):
        raise OSError(errno.EINVAL, "a device or a pipe, not a regular file", str(path))
    with open(path, "rb") as stream:
        data = stream.read(most + 1)
    if len(data) > most:
        raise OSError(errno.EINVAL, f"holds more than {most:,} bytes", str(path))
    return data.decode()


def read_json(path):
    """`(value, None)` of the JSON study file at `path` (`read_text`), else `(None, what is
    wrong)`: "missing", "unreadable (WHY)" or "truncated or invalid JSON (WHY)"."""
    try:
        return json.loads(read_text(path)), None
    except FileNotFoundError:
        return None, "missing"
    except OSError as error:
        return None, f"unreadable ({error.strerror})"
    except ValueError as error:
        return None, f"truncated or invalid JSON ({error})"


def _temporary(path):
    """`.NAME.PID.tmp` beside `path`, NAME cut short where the whole would pass the 255 bytes
    a file system takes in a name (a 250-byte name given to `run --record` was refused only
    once the run had ended)."""
    tail = f".{os.getpid()}.tmp"
    name = os.fsencode(path.name)[:MOST_NAME_BYTES - 1 - len(tail)]
    return path.with_name(f".{os.fsdecode(name)}{tail}")


def write_atomically(path, text):
    """Writes `text` to `path` whole or not at all (see `writing`)."""
    with writing(path) as temporary, open(temporary, "w", newline="") as stream:
        stream.write(text)


def save_figure(figure, path, **options):
    """`figure.savefig(path, **options)` whole or not at all (see `writing`)."""
    path = pathlib.Path(path)
    with writing(path) as temporary:
        figure.savefig(temporary, format=path.suffix.lstrip("."), **options)


def remove_leftovers(folder):
    """Removes what a stopped study left in `folder`: its trials' temporary files and running
    markers, and the temporary files beside its summary whose process has ended (a
    `report` may be writing its own)."""
    folder = pathlib.Path(folder)
    leftovers = [*folder.glob("trials/*/*.running"), *folder.glob("trials/*/.*.tmp"),
                 *(path for path in folder.glob(".*.tmp") if not _writer_alive(path))]
    for leftover in leftovers:
        with contextlib.suppress(OSError):
            leftover.unlink(missing_ok=True)


def _writer_alive(temporary):
    """Whether the process that writes `temporary` (its name's PID) still runs."""
    pid = temporary.name.rsplit(".", 2)[-2]
    return pid.isdigit() and int(pid) != os.getpid() and process_alive(int(pid))


def process_alive(pid):
    """Whether process `pid` still runs (another user's too)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
