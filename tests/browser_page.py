"""What the headless-browser tests share: Debian's chromium driven by Playwright (the PyPI
package and its driver only, never `playwright install`), a page opened on a URL, a free
port, and a command run for the test's length, its output read with timeouts.

A test module that needs the browser sets `pytestmark = NEEDS_BROWSER` (slow, and skipped
where chromium or Playwright is missing).
"""

import contextlib
import io
import json
import queue
import re
import shutil
import socket
import subprocess
import threading
import time
import urllib.request

import matplotlib.image
import numpy as np
import pytest

CHROMIUM = shutil.which("chromium")
try:
    from playwright.sync_api import sync_playwright
except ImportError:  # pragma: no cover - depends on the environment
    sync_playwright = None

# The project's flags for headless Chromium on this machine: software WebGL, and no
# background connections (the network is closed, and they would be refused).
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--enable-unsafe-swiftshader",
                 "--disable-background-networking"]

# The pages draw at most this many frames a second. Without a GPU Chromium draws WebGL in
# software, and an uncapped page draws as many frames as the CPU allows, taking it from the
# run it shows and from the tests alongside. A page's keys, buttons and text do not wait for
# its frames, and its scene's messages coalesce while it draws (the front's pacing), as on a
# slow computer.
FRAME_RATE = 3

# Each animation frame callback runs only in a frame at least 1/FRAME_RATE after the last one
# shown (the callbacks of one frame share its time), or waits for a later frame.
_FRAME_CAP = """(() => {
  const period = 1000 / %r, request = window.requestAnimationFrame.bind(window),
        cancel = window.cancelAnimationFrame.bind(window), waiting = new Map();
  let shown = -Infinity, last_id = 0;
  window.requestAnimationFrame = function (callback) {
    const id = ++last_id;
    const frame = function (time) {
      if (time !== shown && time - shown < period) {
        waiting.set(id, request(frame));
        return;
      }
      waiting.delete(id);
      shown = time;
      callback(time);
    };
    waiting.set(id, request(frame));
    return id;
  };
  window.cancelAnimationFrame = function (id) { cancel(waiting.get(id)); waiting.delete(id); };
})();"""

NEEDS_BROWSER = [
    pytest.mark.slow,
    pytest.mark.browser,
    pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed"),
    pytest.mark.skipif(sync_playwright is None, reason="playwright is not installed"),
]


@contextlib.contextmanager
def open_page(url, viewport=(1280, 720), timeout_ms=20_000, cpu_slowdown=None):
    """A headless Chromium page loaded from `url` (its default timeout `timeout_ms`),
    drawing at most FRAME_RATE frames a second, closed with its browser on leaving.
    `cpu_slowdown` (e.g. 10): the page's CPU throttled that many times once it has loaded
    (Chrome DevTools' CPU throttling), a slow laptop's."""
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS,
                                             timeout=30_000)
        try:
            page = browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
            page.set_default_timeout(timeout_ms)
            page.add_init_script(_FRAME_CAP % float(FRAME_RATE))
            page.goto(url, wait_until="load")
            if cpu_slowdown is not None:
                page.context.new_cdp_session(page).send(
                    "Emulation.setCPUThrottlingRate", {"rate": float(cpu_slowdown)})
            yield page
        finally:
            browser.close()


def control(page, label):
    """The row of the page's control panel (Meshcat's dat.gui) labelled exactly `label`, a
    regular expression."""
    return page.locator(".dg li.cr").filter(
        has=page.locator(".property-name", has_text=re.compile(f"^{label}$")))


def click(page, label, timeout_ms=60_000):
    """Clicks the control labelled exactly `label` (plain text) once the page shows it. The
    panel may be folded: this sends the click its row would."""
    row = control(page, re.escape(label))
    row.wait_for(state="attached", timeout=timeout_ms)
    row.dispatch_event("click")


def console_line(page, name):
    """The console panel's line `name` (title, status, result, notice): its text, as the
    page front's panel shows it."""
    return page.locator(f"#pbp-{name}")


def banner_shown(page):
    """Whether Meshcat's yellow "No connection to server" banner is on screen: its element
    shown, or its yellow in the screenshot's top strip, where Meshcat puts it (the middle
    half of the width, in pure yellow; the scene's yellow target is darker and lower)."""
    if page.locator("#status-message").is_visible():
        return True
    image = matplotlib.image.imread(io.BytesIO(page.screenshot(type="png")), format="png")
    height, width = image.shape[:2]
    strip = np.round(image[:40, width // 4: 3 * width // 4, :3] * 255).astype(int)
    yellow = (strip[..., 0] > 240) & (strip[..., 1] > 240) & (strip[..., 2] < 40)
    return int(np.count_nonzero(yellow)) > 200


@contextlib.contextmanager
def running(command, cwd=None, stdin=subprocess.DEVNULL):
    """`command` started (its stderr merged into its stdout, read as `Output`), as
    `(process, output)`; on leaving, the process is killed when it still runs, so that a
    failed test leaves nothing behind. `stdin` is passed to the process as given."""
    process = subprocess.Popen(command, cwd=cwd, stdin=stdin, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True)
    try:
        yield process, Output(process.stdout)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(timeout=10)


def free_port():
    with socket.socket() as probe:
        probe.bind(("localhost", 0))
        return probe.getsockname()[1]


def simulated_time(port, token):
    """The run's simulated time, as the page front's `/pbp/state` (what the panel fetches)
    says it now."""
    with urllib.request.urlopen(f"http://localhost:{port}/pbp/state?token={token}",
                                timeout=10) as response:
        return json.loads(response.read())["time"]


class Output:
    """The lines of a process's output, read on a thread so that every wait has a timeout."""

    def __init__(self, stream):
        self.lines = []
        self._queue = queue.Queue()
        threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream):
        for line in stream:
            self._queue.put(line.rstrip("\n"))
        self._queue.put(None)

    def wait_for(self, pattern, timeout):
        """The first match of `pattern` in the lines to come, or None at the timeout or end."""
        deadline = time.monotonic() + timeout
        while (remaining := deadline - time.monotonic()) > 0:
            try:
                line = self._queue.get(timeout=remaining)
            except queue.Empty:
                return None
            if line is None:
                return None
            self.lines.append(line)
            if match := re.search(pattern, line):
                return match
        return None

    def text(self):
        return "\n".join(self.lines[-40:])
