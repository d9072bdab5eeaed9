"""Exclusive control of a Meshcat page: a person's operator reads its browser only while
exactly that one browser is connected.

Drake's Meshcat accepts a websocket from any origin. The command line puts its page front
(`pbp_drake.console.front.PageFront`) before it, which lets in only a browser holding the
run's secret URL; this guard is the second line, and the only one for a diagram on a bare
Meshcat. It cannot tell the person's page from another; what it can see is the number of
connections. With more than one, it pauses the simulation where it stands (inside the
operator's sampling, so no simulated time passes and the robot does not move), says so in
the terminal and in the page, and waits until one connection is left. The operator then
drops every input that arrived meanwhile.

What it cannot stop alone (the front does): a page that connects while no browser is (it is
then "the" browser), and one that connects, presses and leaves between two control ticks.
"""

import sys
import time

#: The label of the notice added to the page's controls while the run is paused.
PAUSED_NOTICE = "Paused: {count} browsers are connected. Close all pages but one"


class BrowserGuard:
    """Waits while more than one browser is connected to `meshcat`.

    `wait_while_shared()` is called by an operator each time it reads its browser: it
    returns at once (False) with at most one connection; otherwise it announces the pause
    (`announce`, the terminal by default, and a button in the page carrying the notice),
    polls every `poll_period` seconds until at most one connection is left, announces the
    end of the pause, calls `after_pause` if set (see `reset_pacing_after_pauses`) and
    returns True: the caller must then drop what the browser sent meanwhile.
    `pauses` counts the pauses so far. Use from the thread that created Meshcat.
    """

    def __init__(self, meshcat, poll_period=0.05, announce=None):
        self._meshcat = meshcat
        self._poll_period = float(poll_period)
        self._announce = announce or _to_stderr
        self.after_pause = None
        self.pauses = 0

    def wait_while_shared(self):
        count = self._meshcat.GetNumActiveConnections()
        if count <= 1:
            return False
        self.pauses += 1
        notice = PAUSED_NOTICE.format(count=count)
        self._announce(f"{notice}: the robot waits, and input sent meanwhile is dropped "
                       "(every page open on this run's URL counts).")
        self._meshcat.AddButton(notice)
        while self._meshcat.GetNumActiveConnections() > 1:
            time.sleep(self._poll_period)
        self._meshcat.DeleteButton(notice, strict=False)
        self._announce("One browser is connected again: the robot goes on.")
        if self.after_pause is not None:
            self.after_pause()
        return True


def _to_stderr(message):
    print(f"pbp-drake: {message}", file=sys.stderr, flush=True)


def reset_pacing_after_pauses(diagram, simulator):
    """Makes every guarded operator in `diagram` restart `simulator`'s real-time pacing
    after a pause: without it, a simulator with a target real-time rate would run flat out
    after a pause until simulated time caught up with the wall clock, and the robot would
    rush through the seconds the pause lasted."""
    for system in _leaf_systems(diagram):
        guard = getattr(system, "browser_guard", None)
        if isinstance(guard, BrowserGuard):
            guard.after_pause = simulator.ResetStatistics


def _leaf_systems(system):
    if not hasattr(system, "GetSystems"):
        return [system]
    return [leaf for child in system.GetSystems() for leaf in _leaf_systems(child)]
