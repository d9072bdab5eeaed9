"""How a command stops: SIGTERM (`kill`, a service manager, `timeout`) taken as Ctrl-C, with
its word and cleanup, and a file that cannot be written said in one line."""

import contextlib
import functools
import signal
import sys
import threading

from pbp_drake.cli_types import EXIT_TERMINATED, EXIT_WRITE_FAILED
from pbp_drake.studies.atomic_files import is_disk_failure, write_failure_line


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived: raised where the main thread runs, as Ctrl-C's KeyboardInterrupt
    is, so that the same handlers stop the command."""

    signal_number = signal.SIGTERM


@contextlib.contextmanager
def sigterm_as_interrupt():
    """While the block runs (in the main thread), SIGTERM raises Terminated; a second one,
    while the command stops, is ignored (kill -9 remains)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminate(signal_number, frame):
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        raise Terminated()

    previous = signal.signal(signal.SIGTERM, terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def stopping_cleanly(command, then="the same command resumes", sigterm=True):
    """`command(args)` that says a file it could not write (a full disk) in one line, exit
    4 (`then`: what the same command does when run again); with `sigterm`, it takes
    SIGTERM as Ctrl-C."""

    @functools.wraps(command)
    def stopping(args):
        with sigterm_as_interrupt() if sigterm else contextlib.nullcontext():
            try:
                return command(args)
            except Terminated:
                print("\npbp-drake: terminated (SIGTERM)", file=sys.stderr)
                return EXIT_TERMINATED
            except OSError as error:
                if not is_disk_failure(error):
                    raise
                on_a_bar = "\n" if sigterm and sys.stderr.isatty() else ""
                print(on_a_bar + write_failure_line(error, then), file=sys.stderr)
                return EXIT_WRITE_FAILED

    return stopping
