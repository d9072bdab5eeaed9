"""A text progress bar for a study's trials."""

import math
import sys


class ProgressBar:
    """`progress(done, total, record, elapsed)` as one line on `stream`: rewritten in place
    on a terminal, else printed every `every` trials (default: about 20 lines a study)."""

    def __init__(self, stream=None, width=30, every=None):
        self.stream = sys.stderr if stream is None else stream
        self.width = width
        self.every = every
        self.failures = 0
        self.errors = 0
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def line(self, done, total, elapsed):
        filled = int(round(self.width * done / total)) if total else self.width
        eta = elapsed / done * (total - done) if done else float("nan")
        eta_text = _duration(eta) if math.isfinite(eta) else "?"
        return (f"[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} trials, "
                f"{self.failures} failed ({self.errors} errors), {_duration(elapsed)} elapsed,"
                f" ETA {eta_text}")

    def __call__(self, done, total, record, elapsed):
        if not record["success"]:
            self.failures += 1
        if record["error"] is not None:
            self.errors += 1
        text = self.line(done, total, elapsed)
        if self.tty:
            self.stream.write("\r" + text + ("\n" if done == total else ""))
        else:
            every = self.every or max(1, total // 20)
            if done % every == 0 or done == total or record["error"] is not None:
                suffix = (f"  ({record['method']} seed {record['seed']}: {record['error']})"
                          if record["error"] is not None else "")
                self.stream.write(text + suffix + "\n")
        self.stream.flush()


def _duration(seconds):
    seconds = int(round(seconds))
    if seconds >= 3600:
        return f"{seconds // 3600}h{seconds % 3600 // 60:02d}m"
    if seconds >= 60:
        return f"{seconds // 60}m{seconds % 60:02d}s"
    return f"{seconds}s"
