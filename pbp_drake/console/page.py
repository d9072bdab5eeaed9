"""The operator's console in a Meshcat page: lines of text, buttons and sliders.

Drake's Meshcat has no text primitive: on a bare Meshcat a line of text is a button labelled
with the text (clicking it does nothing), replaced when the text changes. Behind the page
front (`PageFront`) the lines go to the front's own panel instead.
"""

import select
import sys
import time

from pbp_drake.console.front import LINES

#: The choices a person can make, and the label of the button that makes each.
CHOICE_BUTTONS = {"stop": "Stop", "restart": "Restart", "next": "Next scene",
                  "close": "Close"}
ALPHA_SLIDER = "Alpha (user 0 .. robot 1)"
RATE_SLIDER = "Real-time rate"
# The slider's range: slow enough to watch a takeover, at most what a laptop keeps up with.
RATE_RANGE = (0.1, 3.0, 0.1)


class Console:
    """The controls and status lines of a run in `meshcat`'s page, used from the thread
    that created `meshcat` (Meshcat raises from any other).

    Args:
        meshcat: the page's Meshcat.
        choices: which of `CHOICE_BUTTONS` ("stop", "restart", "next", "close") get a
            button, in this order.
        alpha: with a number, an alpha slider (0..1, step 0.05) starting there; `alpha()`
            reads it.
        realtime_rate: with a positive number, a real-time-rate slider (`RATE_RANGE`,
            widened to hold the number) starting there; `realtime_rate()` reads it.
        panel: where the lines go instead of button labels: an object with `show(**lines)`
            taking `title`, `status`, `result` and `time` (a `PageFront`), or None.

    The control panel shows, top to bottom (below buttons others added): the choice
    buttons, the sliders, then the lines of `show_title`, `show_status`, `show_result` and
    `show_notice`. `choice()` reads the person's choice at once, `wait_for_choice()` waits.
    """

    def __init__(self, meshcat, choices=("stop", "restart", "next"), alpha=None,
                 realtime_rate=None, panel=None):
        self._meshcat = meshcat
        self._panel = panel
        self._choices = ()
        self.set_choices(choices)
        self._sliders = []
        if alpha is not None:
            meshcat.AddSlider(ALPHA_SLIDER, 0.0, 1.0, 0.05, float(alpha))
            self._sliders.append(ALPHA_SLIDER)
        if realtime_rate is not None:
            low, high, step = RATE_RANGE
            rate = float(realtime_rate)
            # Widened to hold the rate asked for: the slider must not clip the command line.
            meshcat.AddSlider(RATE_SLIDER, min(low, rate), max(high, rate), step, rate)
            self._sliders.append(RATE_SLIDER)
        self._lines = dict.fromkeys(LINES)  # the labels shown

    @property
    def meshcat(self):
        return self._meshcat

    @property
    def panel(self):
        """The panel the lines go to (a `PageFront`), or None: button labels."""
        return self._panel

    def set_choices(self, choices):
        """Replaces the choice buttons by `choices` (see the class), in this order; clicks
        made before count for none of them."""
        unknown = set(choices) - set(CHOICE_BUTTONS)
        if unknown:
            raise ValueError(f"unknown choices {sorted(unknown)}; choose from "
                             f"{list(CHOICE_BUTTONS)}")
        for choice in self._choices:
            self._meshcat.DeleteButton(CHOICE_BUTTONS[choice], strict=False)
        self._choices = tuple(choices)
        for choice in self._choices:
            self._meshcat.AddButton(CHOICE_BUTTONS[choice])
        self._seen = {choice: self._meshcat.GetButtonClicks(CHOICE_BUTTONS[choice])
                      for choice in self._choices}

    def show_title(self, text):
        """The first line, e.g. the method's name ("PBP-Alt")."""
        self._show("title", text)

    def show_status(self, text, time=None):
        """The live line under the title, e.g. `status_text(...)`, of simulated `time`
        (seconds; the panel passes it on to the page)."""
        if self._panel is not None:
            self._panel.show(status=text, time=time)
        self._show("status", text)

    def show_result(self, text):
        """The line under the status, e.g. `result_text(...)`, as "Result: <text>"."""
        self._show("result", f"Result: {text}")

    def clear_result(self):
        self._show("result", None)

    def show_notice(self, text):
        """A line under the result for what the person must know (no gamepad); None
        hides it."""
        self._show("notice", text)

    def remove_controls(self):
        """Removes the choice buttons and the sliders, keeping the lines."""
        self.set_choices(())
        for name in self._sliders:
            self._meshcat.DeleteSlider(name, strict=False)
        self._sliders = []

    def lines(self):
        """The labels of the shown lines, top to bottom (what the page shows)."""
        return [label for label in self._lines.values() if label is not None]

    def alpha(self):
        """The alpha slider's value, or None without one."""
        return self._slider(ALPHA_SLIDER)

    def realtime_rate(self):
        """The real-time-rate slider's value, or None without one."""
        return self._slider(RATE_SLIDER)

    def choice(self):
        """"stop", "restart" or "next" when its button was clicked since the last choice
        returned, else None (the first of `choices` wins when several were)."""
        for choice in self._choices:
            clicks = self._meshcat.GetButtonClicks(CHOICE_BUTTONS[choice])
            if clicks > self._seen[choice]:
                self._seen = {c: self._meshcat.GetButtonClicks(CHOICE_BUTTONS[c])
                              for c in self._choices}
                return choice
        return None

    def wait_for_start(self, label, poll_period=0.05, stdin=None):
        """Shows a Start button labelled `label` after the choices and blocks until it is
        clicked ("start"), or until a choice button is clicked (its choice: "stop",
        "restart", "next"), Enter is pressed on `stdin` or Ctrl-C ("stop"). The button is
        gone on return."""
        self._meshcat.AddButton(label)
        try:
            while not self._meshcat.GetButtonClicks(label):
                if (choice := self.choice()) is not None:
                    return choice
                if _entered(stdin, poll_period):
                    return "stop"
            return "start"
        except KeyboardInterrupt:
            print(file=sys.stderr)
            return "stop"
        finally:
            self._meshcat.DeleteButton(label, strict=False)

    def wait_for_choice(self, poll_period=0.05, stdin=None, timeout=None, until=None):
        """Blocks until a choice button is clicked and returns its choice. Ctrl-C, and a
        line (Enter) on `stdin` when given, return "stop". After `timeout` seconds, or as
        soon as `until()` is true (e.g. the page was closed), returns None."""
        deadline = None if timeout is None else time.monotonic() + timeout
        try:
            while (choice := self.choice()) is None:
                if ((deadline is not None and time.monotonic() >= deadline)
                        or (until is not None and until())):
                    return None
                if _entered(stdin, poll_period):
                    return "stop"
            return choice
        except KeyboardInterrupt:
            print(file=sys.stderr)
            return "stop"

    def close(self):
        """Removes every button and slider this console added, and its lines."""
        self.remove_controls()
        for name in self._lines:
            self._show(name, None)

    def _slider(self, name):
        return self._meshcat.GetSliderValue(name) if name in self._sliders else None

    def _show(self, line, label):
        if self._lines[line] == label:
            return
        if self._panel is not None:
            self._lines[line] = label
            if line != "status":  # show_status passes the status on with its time
                self._panel.show(**{line: label})
            return
        # Controls show in the order they were added: the lines below a changed one go back
        # in after it.
        names = list(self._lines)
        below = names[names.index(line):]
        for name in below:
            if self._lines[name] is not None:
                self._meshcat.DeleteButton(self._lines[name], strict=False)
        self._lines[line] = label
        for name in below:
            if self._lines[name] is not None:
                self._meshcat.AddButton(self._lines[name])


def _entered(stdin, period):
    """Waits `period` seconds for a line (Enter) on `stdin`; True when one came (read)."""
    if stdin is None:
        time.sleep(period)
        return False
    if select.select([stdin], [], [], period)[0]:
        stdin.readline()
        return True
    return False
