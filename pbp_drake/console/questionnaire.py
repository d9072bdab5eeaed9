"""The pages of a user-study session in the Meshcat control panel (`MeshcatSessionPage`):
before each method a Start button that names it, after it the paper's two questions as six
buttons each, then a Next button; `FixedAnswers` answers them without a browser
(`--answers`). `studies.sessions.run_session` calls their `start`, `answer` and `next`.
"""

import time

from pbp_drake.console.text import method_name
from pbp_drake.studies.questionnaire import QUESTIONS, SCALE, end_label

POLL_PERIOD = 0.05  # s between looks at the buttons: a click feels immediate


def start_label(method, position, total, practice=False):
    """The Start button of a method: which method, which of how many, practice or not."""
    if practice:
        return f"Start practice {position} of {total}: {method_name(method)} (not recorded)"
    return f"Start method {position} of {total}: {method_name(method)}"


def answer_labels(question):
    """The six buttons of a question, `{label: value}`: "0 = very tired: How tired did you
    feel?", "1: How tired did you feel?", ... "5 = not tired at all: ...": the value first,
    which a label cut short still shows, and the two ends named."""
    text = QUESTIONS[question].text
    labels = {}
    for value in SCALE:
        end = end_label(question, value)
        labels[f"{value} = {end}: {text}" if end else f"{value}: {text}"] = value
    return labels


def next_label(position, total):
    """The Next button after a method's questions, naming the method it leads to."""
    return f"Next: on to method {position} of {total}"


class MeshcatSessionPage:
    """The session's pages in a Meshcat's control panel, polled from the thread that made
    the Meshcat (a person clicks; nothing times out, Ctrl-C in the terminal stops the
    session, which the same command resumes). Each page's buttons are deleted before the
    next page shows, so a click meant for one page cannot answer another. With
    `start_in_run`, Start is pressed inside the run, once its scene is in the page: `start`
    keeps the label for the run's `LiveRun` (`take_start_label`)."""

    def __init__(self, meshcat, start_in_run=False):
        self._meshcat = meshcat
        self._start_in_run = start_in_run
        self._label = None

    def start(self, method, position, total, practice=False):
        """Shows the Start button of `method` and returns when it is clicked (keeps its
        label with `start_in_run`)."""
        label = start_label(method, position, total, practice)
        if self._start_in_run:
            self._label = label
        else:
            self._wait_for_click([label])

    def take_start_label(self):
        """The label `start` kept (once), or None."""
        label, self._label = self._label, None
        return label

    def answer(self, method, question):
        """Shows `question`'s six answers (about `method`, just run) and returns the value
        clicked."""
        labels = answer_labels(question)
        return labels[self._wait_for_click(list(labels))]

    def next(self, position, total):
        """Shows the Next button that leads to method `position` and returns when clicked."""
        self._wait_for_click([next_label(position, total)])

    def _wait_for_click(self, names):
        # A button's click count starts at zero when it is added: only this page's count.
        for name in names:
            self._meshcat.AddButton(name)
        try:
            while True:
                for name in names:
                    if self._meshcat.GetButtonClicks(name) > 0:
                        return name
                time.sleep(POLL_PERIOD)
        finally:
            for name in names:
                self._meshcat.DeleteButton(name, strict=False)


class FixedAnswers:
    """The session's pages answered by themselves: Start and Next go on at once, each
    question gets its answer from `answers` (`{method: {question: value}}`, see
    `studies.questionnaire.parse_answers`). `asked` lists the `(method, question)` asked, in
    order."""

    def __init__(self, answers):
        self.answers = answers
        self.asked = []

    def start(self, method, position, total, practice=False):
        """Nothing to wait for."""

    def answer(self, method, question):
        """The fixed answer."""
        self.asked.append((method, question))
        return self.answers[method][question]

    def next(self, position, total):
        """Nothing to wait for."""
