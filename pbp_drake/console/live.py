"""A run, live: the simulation advanced in short slices of simulated time, and between two
slices (on the thread that made Meshcat) the console's status, the person's choices, the
sliders, the following camera and the terminal's progress line. Slices, not a Simulator
monitor: a monitor runs at every plant step and sees a const Context, where the alpha
slider must write a parameter.
"""

import math
import sys
import time

from pbp_drake.builder.build import find_system
from pbp_drake.builder.run import advance_to
from pbp_drake.console.text import progress_text, status_text
from pbp_drake.systems.operators.browser_guard import warn
from pbp_drake.systems.operators.browser_input import BrowserOperator
from pbp_drake.systems.ports import TaskStatus

# Simulated seconds between two looks at the page: a smooth camera, a click felt at once.
SLICE_SECONDS = 0.05
# Wall seconds between two status lines: the page redraws its panel at each.
STATUS_PERIOD = 0.25
#: What the page and the terminal say while a gamepad run's page has seen no pad.
NO_GAMEPAD = ("No gamepad in the page: connect one and press any of its buttons (a browser "
              "shows a pad to the page only after a press); until then it drives nothing.")
GAMEPAD_FOUND = "Gamepad found: it drives now."
#: What the terminal says while a person's run stands still for want of a page in view.
NO_PAGE = ("Paused at {time:.1f} s: no page is open and in view, so nobody drives; reopen "
           "{url} or bring its tab back to go on (Ctrl-C stops the run).")
PAGE_BACK = "A page is in view again: the run goes on."
# A reload leaves no page for a moment: the run stands still at once, and says so only when
# no page is back after this many seconds.
NO_PAGE_QUIET = 2.0
# Wall seconds between two looks at a page that has gone.
NO_PAGE_POLL = 0.05


def closed_for(pages, seconds):
    """A test that is true once `pages()` (a `PageFront`'s `pages` or `pages_present`) has
    counted none for `seconds` on end, from the first call that finds none."""
    since = None

    def closed():
        nonlocal since
        if pages():
            since = None
            return False
        if since is None:
            since = time.monotonic()
        return time.monotonic() - since >= seconds
    return closed


class Progress:
    """The terminal's progress line: rewritten in place every quarter second when `stream`
    is a terminal, a new line every 5 s otherwise (a log file, a pipe)."""

    def __init__(self, duration, stream=None):
        self._stream = stream or sys.stdout
        self._duration = float(duration)
        self._tty = self._stream.isatty()
        self._period = 0.25 if self._tty else 5.0
        self._last = time.monotonic()  # the first line one period in, not at t = 0
        self._width = 0

    def show(self, now, realtime_factor, force=False):
        wall = time.monotonic()
        if not force and wall - self._last < self._period:
            return
        self._last = wall
        text = progress_text(now, self._duration, realtime_factor)
        if self._tty:
            self._stream.write("\r" + text.ljust(self._width))
            self._width = len(text)
        else:
            self._stream.write(text + "\n")
        self._stream.flush()

    def finish(self):
        """Clears a terminal's progress line, so that the next line starts clean."""
        if self._tty and self._width:
            self._stream.write("\r" + " " * self._width + "\r")
            self._stream.flush()
            self._width = 0


class LiveRun:
    """Drives `console` (a `pbp_drake.console.Console`, or None) and `progress` (a
    `Progress`, or None) from the simulation of `diagram`, a task of `duration` seconds.

    Pass `advance` as the `advance` argument of `run_task`, `run_task_streamed` or
    `simulate`: after each slice of `SLICE_SECONDS` it shows the status (`status`), moves
    `camera` (a `RobotCamera`, or None) and applies the alpha slider to the `blender`
    (fixed_alpha) and the real-time-rate slider to the simulator. A click on a choice
    button ends the run there: `advance` returns True, and `choice` holds "stop",
    "restart" or "next".

    With `start_label`, the first `advance` shows a Start button of that label, once the
    page has the scene, and waits for it (`Console.wait_for_start`); a choice button
    clicked meanwhile ends the run after its first slice, `choice` the one clicked (Enter
    on `stdin`: "stop"); the keys of the diagram's "operator" pressed meanwhile are
    forgotten (`BrowserOperator.forget_keys`). With `gamepad`, a page that
    has seen no gamepad is told so (`NO_GAMEPAD`, in the notice line and on stderr).

    With `page` (the run's `PageFront`: `pages_present()` and `url`) and a person at the
    diagram's "operator" (a `BrowserOperator`), the run stands still between two slices
    while no page is present (closed, hidden or silent: its clock stopped, its state kept),
    says so on stderr (`NO_PAGE`) when none is back within `NO_PAGE_QUIET` seconds, and
    goes on when one is, the gone page's keys and pad forgotten
    (`BrowserOperator.forget_input`). Ctrl-C meanwhile raises KeyboardInterrupt, as during
    the run.
    """

    def __init__(self, diagram, duration, console=None, progress=None, camera=None,
                 start_label=None, stdin=None, gamepad=False, page=None):
        self._console = console
        self._page = page
        self._gamepad = gamepad
        self._pad_seen = None  # not looked yet
        self._start_label = start_label
        self._stdin = stdin
        self._progress = progress
        self._camera = camera
        self._duration = float(duration)
        self._monitor = (diagram.GetSubsystemByName("task_monitor")
                         if diagram.HasSubsystemNamed("task_monitor") else None)
        operator = (diagram.GetSubsystemByName("operator")
                    if diagram.HasSubsystemNamed("operator") else None)
        self._browser = operator if isinstance(operator, BrowserOperator) else None
        has_alpha = console is not None and console.alpha() is not None
        self._blender = find_system(diagram, "blender") if has_alpha else None
        # None: the sliders' values are applied at the start (a restarted run keeps them).
        self._alpha = self._rate = None
        self._last_status = -math.inf
        self.choice = None

    def advance(self, simulator, end_time):
        """Advances `simulator` to `end_time`; True when the run ended before it (the
        task's termination event, or a choice of the person's)."""
        context = simulator.get_context()
        if self._console is not None:
            self._check_gamepad()
            if self._start_label is not None and not self._wait_for_start(simulator):
                # One slice, not none: the task's logs then hold a tick to report.
                advance_to(simulator, min(end_time, SLICE_SECONDS))
                return True
            self._apply_sliders(simulator)
        while (now := context.get_time()) < end_time:
            self._wait_for_a_page(simulator)
            step = min((math.floor(now / SLICE_SECONDS + 1e-9) + 1) * SLICE_SECONDS, end_time)
            ended = advance_to(simulator, step)
            self._update(simulator)
            if ended or self.choice is not None:
                break
        # The last word, whatever the rate limits: the page and terminal end where the run did.
        if self._console is not None:
            self._console.show_status(self.status(context), context.get_time())
        if self._progress is not None:
            self._progress.show(context.get_time(), simulator.get_actual_realtime_rate(),
                                force=True)
            self._progress.finish()
        return context.get_time() < end_time

    def status(self, root_context):
        """The status line at `root_context`'s time (`status_text`), with the target
        switches and intervention ratio of the diagram's `task_monitor` when it has one."""
        if self._monitor is None:
            return status_text(self._duration, root_context.get_time())
        status = TaskStatus(self._monitor.get_task_status_output_port().Eval(
            self._monitor.GetMyContextFromRoot(root_context)))
        return status_text(self._duration, root_context.get_time(), int(status.stage),
                           float(status.intervention_ratio))

    def _update(self, simulator):
        context = simulator.get_context()
        if self._progress is not None:
            self._progress.show(context.get_time(), simulator.get_actual_realtime_rate())
        if self._camera is not None:
            self._camera.update(context)
        if self._console is None:
            return
        self.choice = self._console.choice()
        self._apply_sliders(simulator)
        self._check_gamepad()
        # A panel sends the page only its latest state: every slice's. Button labels are
        # messages the page handles in turn: a few a second.
        if (self._console.panel is not None
                or time.monotonic() - self._last_status >= STATUS_PERIOD):
            self._last_status = time.monotonic()
            self._console.show_status(self.status(context), context.get_time())

    def _wait_for_start(self, simulator):
        """Shows Start and waits for it; False when the person chose another button (Stop,
        Restart, Next scene) instead, `choice` then that one."""
        label, self._start_label = self._start_label, None
        self._console.show_status(self.status(simulator.get_context())
                                  + " · press Start when ready",
                                  simulator.get_context().get_time())
        if (choice := self._console.wait_for_start(label, stdin=self._stdin)) != "start":
            self.choice = choice
            return False
        if self._browser is not None:  # a key tried while the page waited moves nothing
            self._browser.forget_keys(simulator.get_mutable_context())
        simulator.ResetStatistics()  # else the run would rush through the wait
        return True

    def _wait_for_a_page(self, simulator):
        """Holds a person's run while it has no page (see the class); True when it did."""
        if self._page is None or self._browser is None or self._page.pages_present():
            return False
        said = False
        quiet_too_long = closed_for(self._page.pages_present, NO_PAGE_QUIET)
        while not self._page.pages_present():
            if not said and quiet_too_long():
                if self._progress is not None:
                    self._progress.finish()  # the line said on a line of its own
                warn(NO_PAGE.format(time=simulator.get_context().get_time(),
                                    url=self._page.url))
                said = True
            time.sleep(NO_PAGE_POLL)
        if said:
            warn(PAGE_BACK)
        # What the gone page held (a key, a tilted stick) drives nothing after it.
        self._browser.forget_input(simulator.get_mutable_context())
        simulator.ResetStatistics()  # else the run would rush through the pause
        return True

    def _check_gamepad(self):
        """Says when a gamepad run's page has no pad, or has one again."""
        if not self._gamepad:
            return
        seen = self._console.meshcat.GetGamepad().index is not None
        if seen == self._pad_seen:
            return
        if self._pad_seen is not None or not seen:  # at the start, only a missing pad is news
            print(GAMEPAD_FOUND if seen else NO_GAMEPAD, file=sys.stderr, flush=True)
        self._pad_seen = seen
        self._console.show_notice(None if seen else NO_GAMEPAD)

    def _apply_sliders(self, simulator):
        if (alpha := self._console.alpha()) != self._alpha:
            self._alpha = alpha
            self._blender.set_alpha(self._blender.GetMyMutableContextFromRoot(
                simulator.get_mutable_context()), alpha)
        if (rate := self._console.realtime_rate()) != self._rate:
            self._rate = rate
            simulator.set_target_realtime_rate(rate)
            simulator.ResetStatistics()  # else the pacing would catch up on the past
