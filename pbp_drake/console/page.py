"""The operator's console in a Meshcat page: lines of text and buttons and sliders in the
page's control panel.

Drake's Meshcat has no text primitive; what the control panel shows is the label of each
button and slider. So a line of text is a button whose label is the text (clicking it does
nothing), replaced (deleted and added again) when the text changes.
"""

import select
import sys
import time

#: The choices a person can make, and the label of the button that makes each.
CHOICE_BUTTONS = {"stop": "Stop", "restart": "Restart", "next": "Next scene"}
ALPHA_SLIDER = "Alpha (user 0 .. robot 1)"
RATE_SLIDER = "Real-time rate"
# The slider's range: slow enough to watch a takeover, at most what a laptop keeps up with.
RATE_RANGE = (0.1, 3.0, 0.1)


class Console:
    """The controls and status lines of a run in `meshcat`'s page.

    Use it from the thread that created `meshcat` (Meshcat raises from any other).

    Args:
        meshcat: the page's Meshcat.
        choices: which of "stop", "restart", "next" get a button (labels in
            `CHOICE_BUTTONS`: Stop, Restart, Next scene), in this order.
        alpha: with a number, an alpha slider (0..1, step 0.05) starting there; `alpha()`
            reads it.
        realtime_rate: with a positive number, a real-time-rate slider (`RATE_RANGE`,
            widened to hold the number) starting there; `realtime_rate()` reads it.

    The panel then shows, top to bottom: the choice buttons, the sliders, the title line
    (`show_title`), the status line (`show_status`) and the result line (`show_result`).
    Buttons added to the page by others (the keyboard operator's) stay above.

    Reading the person's choice:
        `choice()` returns at once: the choice whose button was clicked since the last
        choice returned (or since the console was made), else None; each click counts
        once. `wait_for_choice()` blocks until a button is clicked (or Enter is pressed in
        a terminal, or Ctrl-C: both "stop").

    `close()` removes every control this console added; a session that keeps one page for
    many runs makes one Console and calls `show_title` / `show_status` / `clear_result`
    between runs instead.
    """

    def __init__(self, meshcat, choices=("stop", "restart", "next"), alpha=None,
                 realtime_rate=None):
        unknown = set(choices) - set(CHOICE_BUTTONS)
        if unknown:
            raise ValueError(f"unknown choices {sorted(unknown)}; choose from "
                             f"{list(CHOICE_BUTTONS)}")
        self._meshcat = meshcat
        self._choices = tuple(choices)
        for choice in self._choices:
            meshcat.AddButton(CHOICE_BUTTONS[choice])
        # Clicks made before this console (a button of the same name earlier) do not count.
        self._seen = {choice: meshcat.GetButtonClicks(CHOICE_BUTTONS[choice])
                      for choice in self._choices}
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
        # Line name -> the label shown now, in the order the lines are shown.
        self._lines = {"title": None, "status": None, "result": None}

    @property
    def meshcat(self):
        return self._meshcat

    def show_title(self, text):
        """The first line, e.g. the method's name ("PBP-Alt")."""
        self._show("title", text)

    def show_status(self, text):
        """The live line under the title, e.g. `pbp_drake.console.text.status_text(...)`.
        Unchanged text sends nothing to the page."""
        self._show("status", text)

    def show_result(self, text):
        """The last line, e.g. `pbp_drake.console.text.result_text(...)`, shown as
        "Result: <text>"."""
        self._show("result", f"Result: {text}")

    def clear_result(self):
        self._show("result", None)

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

    def wait_for_choice(self, poll_period=0.05, stdin=None):
        """Blocks until a choice button is clicked and returns its choice. Ctrl-C, and a
        line (Enter) on `stdin` when given, return "stop"."""
        try:
            while (choice := self.choice()) is None:
                if stdin is not None and select.select([stdin], [], [], poll_period)[0]:
                    stdin.readline()
                    return "stop"
                if stdin is None:
                    time.sleep(poll_period)
            return choice
        except KeyboardInterrupt:
            print(file=sys.stderr)
            return "stop"

    def close(self):
        """Removes every button and slider this console added."""
        for choice in self._choices:
            self._meshcat.DeleteButton(CHOICE_BUTTONS[choice], strict=False)
        for name in self._sliders:
            self._meshcat.DeleteSlider(name, strict=False)
        for name in self._lines:
            self._show(name, None)

    def _slider(self, name):
        return self._meshcat.GetSliderValue(name) if name in self._sliders else None

    def _show(self, line, label):
        if self._lines[line] == label:
            return
        # The control panel lists controls in the order they were added: a changed line
        # goes back in, and so do the lines below it, to keep the order.
        names = list(self._lines)
        below = names[names.index(line):]
        for name in below:
            if self._lines[name] is not None:
                self._meshcat.DeleteButton(self._lines[name], strict=False)
        self._lines[line] = label
        for name in below:
            if self._lines[name] is not None:
                self._meshcat.AddButton(self._lines[name])
