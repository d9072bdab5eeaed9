"""A keyboard run of the reaching task under attack from this machine, while its person (a
raw authorised websocket, as the page's script would be) holds ←: an authorised page sends
the frames Meshcat's parser dies on and one over the size limit, programs connect straight to
Meshcat's private port, pages close as they connect, requests name targets without `/`, and
a Chromium page of another origin tries Meshcat's port and the front. The run never stops or
pauses, simulated time goes on through it all until the person presses Stop, the person's
key moves the hand, and no traceback is printed.
"""

import contextlib
import itertools
import pathlib
import re
import socket
import sys
import threading
import time
import urllib.parse

import msgpack
import pytest
from browser_page import NEEDS_BROWSER, open_page, running, simulated_time
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from pbp_drake.cli_types import EXIT_STOPPED
from pbp_drake.console.front import HERE
from pbp_drake.console.page import CHOICE_BUTTONS
from pbp_drake.systems.operators.keyboard_operator import LEFT_BUTTON

pytestmark = [pytest.mark.slow, pytest.mark.browser]

# The run's time limit (s of simulated time), far past the attacks even on a busy machine:
# the person's Stop ends it once they are over.
DURATION = 600.0
# Simulated seconds of the run, ← held from 0.5 s on, before the person presses Stop.
PRESSED = 5.0
START_Y = 0.08  # the hand starts at about (0.53, 0.08, 0.70)
# Held ← all along, the hand never reaches the target: the run ends at the person's Stop.
RESULT = re.compile(r"^hsr_reach \[teleop, seed 0\]: stopped at (\S+) s, .*, "
                    r"hand at \[(\S+), (\S+), (\S+)\]$")
DEADLY = [b"\xc1", b"\x82\xa4type\xa6button\xa4na", b"\xdd\xff\xff\xff\xff",
          b"\x81\xa4type\xdb\xff\xff\xff\xff", b"\xc6\xff\xff\xff\xff", b"\x90" * 5000]


def _listening_ports(pid):
    """The TCP ports process `pid` listens on (from /proc: its sockets' inodes)."""
    inodes = set()
    for link in pathlib.Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = link.readlink().as_posix()
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    ports = set()
    for table in ("tcp", "tcp6"):
        for line in open(f"/proc/{pid}/net/{table}").read().splitlines()[1:]:
            fields = line.split()
            if fields[3] == "0A" and fields[9] in inodes:  # LISTEN
                ports.add(int(fields[1].rsplit(":", 1)[1], 16))
    return ports


def _authorised(port, token, **options):
    return connect(f"ws://localhost:{port}/?token={token}", origin=f"http://localhost:{port}",
                   open_timeout=10.0, **options)


class Person:
    """The person's page (`page`, an authorised websocket): reads all it is sent, says it is
    in view each second (`HERE`, as our page does once it has drawn its scene) and presses
    ← every 50 ms (a key's auto-repeat) while `pressing` is set."""

    def __init__(self, page):
        self.page = page
        self.pressing, self.closed = threading.Event(), None
        self._stop = threading.Event()
        self._threads = [threading.Thread(target=job, daemon=True)
                         for job in (self._read, self._press)]
        for thread in self._threads:
            thread.start()

    def _read(self):
        try:
            while True:
                self.page.recv()
        except ConnectionClosed as closed:
            self.closed = closed

    def _press(self):
        press = msgpack.packb({"type": "button", "name": LEFT_BUTTON})
        for tick in itertools.count():
            if self._stop.is_set():
                return
            try:
                if tick % 20 == 0:
                    self.page.send(HERE)
                if self.pressing.is_set():
                    self.page.send(press)
            except ConnectionClosed:
                return
            self._stop.wait(0.05)

    def stop_run(self):
        """Lets go of ← and presses the page's Stop."""
        self._stop.set()
        self._threads[1].join()
        self.page.send(msgpack.packb({"type": "button", "name": CHOICE_BUTTONS["stop"]}))

    def close(self):
        self._stop.set()
        self.page.close()


def _authorised_frame(port, token, frame):
    """An authorised page that sends `frame` as it connects: the close it gets."""
    with _authorised(port, token) as page:
        page.send(frame)
        try:
            while True:
                page.recv(timeout=10.0)
        except ConnectionClosed:
            return page.protocol.close_rcvd.code
        except TimeoutError:
            return None


def _raw(port, request, read=True):
    with socket.create_connection(("localhost", port), timeout=10.0) as raw:
        raw.sendall(request.encode())
        return raw.recv(64) if read else b""


def _attack(port, token, meshcat_port):
    """Every attack of the module's list once; what each got."""
    got = {"frames": [_authorised_frame(port, token, frame) for frame in DEADLY]}
    direct = []
    for _ in range(3):
        stranger = socket.socket()
        stranger.settimeout(1.0)
        try:
            stranger.connect(("localhost", meshcat_port))
            stranger.sendall(b"\xc1")
            direct.append("connected")
        except TimeoutError:
            direct.append("no answer")
        finally:
            stranger.close()
    got["direct"] = direct
    handshake = (f"GET /?token={token} HTTP/1.1\r\nHost: localhost:{port}\r\n"
                 "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
                 f"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                 f"Origin: http://localhost:{port}\r\n\r\n")
    for i in range(10):
        _raw(port, handshake, read=i % 2 == 0)
    got["targets"] = [_raw(port, f"GET {target} HTTP/1.1\r\nHost: x\r\n\r\n")[:12]
                      for target in ("etc/passwd", f"?token={token}")]
    return got


def _started_run(process, output):
    url = output.wait_for(r"^Meshcat: (http://\S+)", timeout=90)
    assert url, f"no Meshcat URL from pbp-drake:\n{output.text()}"
    address = urllib.parse.urlsplit(url.group(1))
    token = urllib.parse.parse_qs(address.query)["token"][0]
    ports = _listening_ports(process.pid) - {address.port}
    assert len(ports) == 1, ports  # Meshcat's private port
    return address.port, token, ports.pop()


def _command():
    return [sys.executable, "-m", "pbp_drake", "run", "diagrams/hsr_reach.yaml", "--method",
            "teleop", "--operator", "keyboard", "--duration", str(DURATION), "--port", "0",
            "--start-on-connect", "--keep-page", "0"]


def _until(condition, seconds):
    deadline = time.monotonic() + seconds
    while not (value := condition()):
        if time.monotonic() > deadline:
            return value
        time.sleep(0.05)
    return value


def _finished(process, output, person, port, token):
    """The person presses Stop: the run ends there, stopped by them and by nothing before.
    Returns where the hand ended across (y), after at least `PRESSED` s of the held ←."""
    assert _until(lambda: simulated_time(port, token) > PRESSED, 60), output.text()
    pressed = simulated_time(port, token)
    person.stop_run()
    result = output.wait_for(RESULT.pattern, timeout=60)
    assert result, f"no result line from pbp-drake:\n{output.text()}"
    person.close()
    process.wait(timeout=30)
    output.wait_for(r"$^", timeout=2)  # the rest of the output
    text = "\n".join(output.lines)
    for word in ("Paused", "Traceback", "CRITICAL", "Error"):
        assert word not in text, text
    # Stopped by the person's press (EXIT_STOPPED), not crashed nor ended before it.
    assert process.returncode == EXIT_STOPPED, text
    assert float(result.group(1)) >= pressed - 0.01, (pressed, text)
    return float(result.group(3))


@pytest.mark.timeout(240)
def test_a_keyboard_run_drives_on_through_hostile_clients(repo):
    with running(_command(), cwd=repo) as (process, output), contextlib.ExitStack() as stack:
        port, token, meshcat_port = _started_run(process, output)
        person = Person(stack.enter_context(_authorised(port, token, max_size=None)))
        assert _until(lambda: (simulated_time(port, token) or 0) > 0.5, 60), output.text()
        person.pressing.set()
        before = simulated_time(port, token)
        got = _attack(port, token, meshcat_port)
        # Simulated time went on past the attacks, with the person's page still there.
        after = before + 1.0
        assert _until(lambda: simulated_time(port, token) > after, 30), output.text()
        assert person.closed is None
        hand_y = _finished(process, output, person, port, token)
    assert got["frames"] == [1008] * 5 + [1009], got
    assert got["direct"] == ["no answer"] * 3, got
    assert got["targets"] == [b"HTTP/1.1 400"] * 2, got
    assert hand_y > START_Y + 0.1, f"the person's ← did not move the hand: y = {hand_y}"


FOREIGN = """async ([meshcat, front]) => {
  window.direct = new WebSocket(`ws://localhost:${meshcat}/`);
  window.direct.onopen = () => window.direct.send(new Uint8Array([0xc1]));
  const refused = await new Promise(done => {
    const socket = new WebSocket(`ws://localhost:${front}/`);
    socket.onopen = () => { socket.send(new Uint8Array([0xc1])); done("opened"); };
    socket.onerror = () => done("refused");
  });
  let http = "answered";
  try { await fetch(`http://localhost:${front}/`, {mode: "no-cors"}); }
  catch (e) { http = "failed"; }
  return [refused, http];
}"""


def _needs_browser(test):
    for mark in NEEDS_BROWSER:
        test = mark(test)
    return test


@_needs_browser
@pytest.mark.timeout(300)
def test_a_page_of_another_origin_in_chromium_reaches_nothing(repo):
    with running(_command(), cwd=repo) as (process, output), contextlib.ExitStack() as stack:
        port, token, meshcat_port = _started_run(process, output)
        person = Person(stack.enter_context(_authorised(port, token, max_size=None)))
        assert _until(lambda: (simulated_time(port, token) or 0) > 0.5, 60), output.text()
        person.pressing.set()
        with open_page("data:text/html,<title>elsewhere</title>") as page:
            refused, _ = page.evaluate(FOREIGN, [meshcat_port, port])
            started = simulated_time(port, token)
            # While two more simulated seconds pass, the socket to Meshcat never opens.
            assert _until(lambda: simulated_time(port, token) > started + 2.0, 60)
            direct_state = page.evaluate("window.direct.readyState")
        hand_y = _finished(process, output, person, port, token)
    assert refused == "refused"
    assert direct_state == 0  # CONNECTING: Meshcat's port never answered
    assert hand_y > START_Y + 0.1, f"the person's ← did not move the hand: y = {hand_y}"
