"""Argument types of `pbp-drake run` and `session`: each flag's value is checked when the line is
parsed, and a bad one is refused by argparse (exit 2) as `argument --FLAG: what is wrong`."""

import argparse
import math

from pbp_drake.console.front import check_token
from pbp_drake.scenarios import ScenarioError


def _finite(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r}: give a finite number")
    return value


def port(text):
    """`--port`: an integer in 0..65535, 0 for a free one."""
    try:
        value = int(text)
    except ValueError:
        value = None
    if value is None or not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a port: give an integer in 0..65535 (0: a free one)")
    return value


def realtime_rate(text):
    """`--realtime-rate`: finite and positive."""
    value = _finite(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(
            f"{text!r}: give a positive rate (1: real time); --headless runs as fast as "
            "possible")
    return value


def wait_seconds(text):
    """`--wait-for-browser`: finite and not negative."""
    value = _finite(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: give a number of seconds, 0 or more")
    return value


def method_list(text):
    """`--methods a,b,c` as a list."""
    return [method.strip() for method in text.split(",") if method.strip()]


def chosen_methods(text, example):
    """`--methods a,b,c` as a list; ScenarioError when it names no method (`example`: a list
    that would do) or one twice."""
    methods = method_list(text)
    if not methods:
        raise ScenarioError(f"--methods {text!r} names no method; give them comma-separated, "
                            f"e.g. {example}")
    if len(set(methods)) != len(methods):
        raise ScenarioError(f"--methods {','.join(methods)} names a method twice")
    return methods


def token(text):
    """`--token`: the page's secret, as `pbp_drake.console.front.check_token` takes it."""
    try:
        return check_token(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


#: The exit codes of `pbp-drake`, as the CLI reference lists them.
EXIT_SUCCESS = 0
EXIT_FAILED = 1
EXIT_USAGE = 2
EXIT_STOPPED = 3
EXIT_WRITE_FAILED = 4
EXIT_DRIVER = 5
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143
EXIT_CODES = {
    EXIT_SUCCESS: "success: the task reached its target (a session: every method's run did; "
                  "a study: every trial ran)",
    EXIT_FAILED: "a task failed (its time limit passed), a trial failed with an error, or "
                 "damaged files were skipped",
    EXIT_USAGE: "refused before anything ran: a bad flag, file or scenario, a port in use, "
                "no browser in time for a person's run",
    EXIT_STOPPED: "`run`, `session`: the person pressed Stop in the page (a session is "
                  "resumed by the same command)",
    EXIT_WRITE_FAILED: "a file could not be written (no space left, a quota, a read-only or "
                       "failing disk), said in one line; nothing half-written is left, and "
                       "the same command resumes a study or session",
    EXIT_DRIVER: "`run --hardware`, `driver-sim`: the link to the arm's driver or the "
                 "robot's relay broke a rule (its status silent too long, a bad status, the "
                 "loop behind the wall clock, a command the driver would abort on); nothing "
                 "more is sent, the robot holds where it was last commanded, and one line "
                 "says why",
    EXIT_INTERRUPTED: "interrupted by Ctrl-C (a study or session is resumed by the same "
                      "command)",
    EXIT_TERMINATED: "`study`, `report`, `session`: ended by SIGTERM, as by Ctrl-C (a study "
                     "or session is resumed by the same command)",
}
