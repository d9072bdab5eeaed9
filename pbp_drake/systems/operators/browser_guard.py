"""Exclusive control of a Meshcat page: a person's operator reads its browser only while
exactly that one browser is connected (docs/getting-started.md, "Who can drive").

Behind the page front (`pbp_drake.console.front`, which `register_front`s) it counts the
front's pages that have sent a frame, else Meshcat's connections. It cannot stop alone a
page that connects while no browser is, or one that connects, presses and leaves between
two control ticks.
"""

import sys
import time

#: The label of the notice added to the page's controls while the run is paused.
PAUSED_NOTICE = "Paused: {count} browsers are connected. Close all pages but one"

# Meshcat's port -> the page front before it (what `BrowserGuard._pages` counts).
_FRONTS = {}


def register_front(meshcat_port, front):
    """Tells the guards of the Meshcat on `meshcat_port` that `front` serves its pages."""
    _FRONTS[meshcat_port] = front


def unregister_front(meshcat_port, front):
    if _FRONTS.get(meshcat_port) is front:
        del _FRONTS[meshcat_port]


class BrowserGuard:
    """Waits while more than one browser is connected to `meshcat`.

    `wait_while_shared()` is called by an operator each time it reads its browser: it
    returns False at once with at most one page; with more it waits up to `settle` seconds
    for them to go, else announces the pause (`announce`, the terminal by default, and a
    button in the page) and polls every `poll_period` seconds until at most one is left,
    then calls `after_pause` if set and returns True: the caller must drop what the browser
    sent meanwhile. With an intruder it returns True at once. `pauses` counts the pauses.
    Use from the thread that created Meshcat.
    """

    def __init__(self, meshcat, poll_period=0.05, announce=None, settle=0.2):
        self._meshcat = meshcat
        self._poll_period = float(poll_period)
        self._settle = float(settle)
        self._announce = announce or warn
        self._intruded = False
        self.after_pause = None
        self.pauses = 0

    def _pages(self):
        """(pages, intruders): the front's pages heard from and the connections to Meshcat
        that are not the front's; without a front, Meshcat's connections and none."""
        connections = self._meshcat.GetNumActiveConnections()
        front = _FRONTS.get(self._meshcat.port())
        if front is None:
            return connections, 0
        return front.pages_heard(), max(0, connections - front.own_connections())

    def wait_while_shared(self):
        count, intruders = self._pages()
        if intruders:
            if not self._intruded:
                self._announce("A connection to Meshcat that the page front did not open: "
                               "every click and key is ignored while it stays; the run "
                               "goes on.")
            self._intruded = True
            return True
        if self._intruded:
            self._announce("The connection the page front did not open is gone: the "
                           "page's clicks and keys count again.")
            self._intruded = False
        if count <= 1:
            return False
        settled = time.monotonic() + self._settle
        while time.monotonic() < settled:  # a page closed as it connected: no pause
            time.sleep(min(self._poll_period, self._settle))
            if self._pages()[0] <= 1:
                if self.after_pause is not None:
                    self.after_pause()  # the settling's wall time is not to be caught up
                return True
        self.pauses += 1
        notice = PAUSED_NOTICE.format(count=count)
        self._announce(f"{notice}: the robot waits, and input sent meanwhile is dropped "
                       "(every page open on this run's URL counts).")
        self._meshcat.AddButton(notice)
        while self._pages()[0] > 1:
            time.sleep(self._poll_period)
        self._meshcat.DeleteButton(notice, strict=False)
        self._announce("One browser is connected again: the robot goes on.")
        if self.after_pause is not None:
            self.after_pause()
        return True


def warn(message):
    """Says `message` on stderr as the command line's own words ("pbp-drake: ...")."""
    print(f"pbp-drake: {message}", file=sys.stderr, flush=True)


def reset_pacing_after_pauses(diagram, simulator):
    """Makes every guarded operator in `diagram` restart `simulator`'s real-time pacing
    after a pause, so that the robot does not rush through the seconds the pause lasted."""
    for system in _leaf_systems(diagram):
        guard = getattr(system, "browser_guard", None)
        if isinstance(guard, BrowserGuard):
            guard.after_pause = simulator.ResetStatistics


def _leaf_systems(system):
    if not hasattr(system, "GetSystems"):
        return [system]
    return [leaf for child in system.GetSystems() for leaf in _leaf_systems(child)]
