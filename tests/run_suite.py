"""`make test`'s two pytest runs, at once: the tests that drive a page in Chromium or in real
time (marked `browser`), one at a time at the usual priority, and all the others in two
processes (pytest-xdist) at the lowest priority (nice 19). The pages are never starved: the
others take only the CPU that the real-time pages leave idle.

The other tests' report streams to the terminal; the browser tests' follows it. The exit
code is the first failed run's (pytest's codes; a run that found no test to run, code 5,
fails only when the other found none either). Ctrl-C reaches both runs, which share the
terminal's process group, and each ends as pytest ends on Ctrl-C.

    python tests/run_suite.py [PYTEST_ARGS...]   # e.g. -x, or a folder
"""

import os
import subprocess
import sys
import tempfile

PYTEST = [sys.executable, "-m", "pytest"]
NO_TESTS = 5  # pytest's exit code when no test was collected


def main(arguments):
    with tempfile.TemporaryFile("w+") as browser_report:
        browser = subprocess.Popen([*PYTEST, "-m", "browser", *arguments],
                                   stdout=browser_report, stderr=subprocess.STDOUT,
                                   stdin=subprocess.DEVNULL)
        others = subprocess.Popen([*PYTEST, "-m", "not browser", "-n", "2", "--dist",
                                   "worksteal", *arguments], preexec_fn=lambda: os.nice(19))
        try:
            codes = others.wait(), browser.wait()
        except KeyboardInterrupt:  # each run has its own Ctrl-C: wait for both to end
            codes = others.wait(), browser.wait()
        browser_report.seek(0)
        print("\nThe browser tests, run alongside (one at a time):", flush=True)
        sys.stdout.write(browser_report.read())
    failed = [code for code in codes if code not in (0, NO_TESTS)]
    return failed[0] if failed else NO_TESTS if set(codes) == {NO_TESTS} else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
