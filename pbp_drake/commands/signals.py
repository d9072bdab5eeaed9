"""SIGTERM taken as Ctrl-C: a command that is asked to end (`kill PID`, a service manager,
`timeout`) stops the way it stops on Ctrl-C, with its word and its cleanup, instead of
dying at once (leaving worker processes and temporary files)."""

import contextlib
import signal
import threading


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
