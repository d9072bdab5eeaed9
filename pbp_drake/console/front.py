"""The run's page behind a front of our own: a token and the page's own origin, or HTTP 403.

The front keeps Drake's Meshcat on a private localhost port and serves the page (Meshcat's,
with our console panel injected) and a websocket relay to it; docs/design.md ("The page")
explains the token, the door (`meshcat_door`), the checked frames (`page_messages`) and the
pacing of a slow page (`PendingMessages`, `FRAME`, `ACK`). The front never calls a Meshcat
method; it runs an asyncio loop on a daemon thread. Close the front before letting go of
the Meshcat: Drake aborts the process when a Meshcat dies on another thread (as one left in
a reference cycle does, in whichever thread collects).
"""

import asyncio
import collections
import concurrent.futures
import contextlib
import email.utils
import errno
import hmac
import http
import http.client
import json
import logging
import math
import re
import secrets
import socket
import threading
import time
import urllib.parse

from websockets.asyncio.client import connect
from websockets.asyncio.server import serve
from websockets.datastructures import Headers
from websockets.exceptions import InvalidHandshake
from websockets.http11 import Response

from pbp_drake.console.meshcat_door import MeshcatDoor
from pbp_drake.console.page_messages import MAX_MESSAGE, BadMessage, read_page_message
from pbp_drake.console.pending_messages import PendingMessages, message_key
from pbp_drake.scenarios import ScenarioError
from pbp_drake.systems.operators.browser_guard import register_front, unregister_front, warn

LOG = logging.getLogger(__name__)  # websockets' connection log, every poll: INFO
COOKIE = "pbp_drake_token"
LINES = ("title", "status", "result", "notice")
ENDED_NOTICE = "This run has ended; you can close this page."
REFUSAL = ("This page needs the address `pbp-drake run` printed (with its ?token=...); "
           "open that one.\n")
_TOKEN = re.compile(r"[A-Za-z0-9_-]+")
_PAGES = ("/", "/index.html", "/meshcat.html")
# Small, so that a slow page's messages wait in our queue, where they coalesce, not in the
# websocket's or the kernel's buffers (megabytes on localhost unless fixed).
WRITE_LIMIT = 2**14
SEND_BUFFER = 2**15
# The relay's pacing: each batch ends with FRAME, which our page answers with ACK at its
# next animation frame; the next batch waits for it (a client that never answers is sent
# batches as fast as it reads).
FRAME, ACK = "pbp_drake_frame", "pbp_drake_ack"
# Our page's heartbeat, each second and at once when its tab is shown or hidden: HERE while
# the tab is in view, AWAY while it is hidden (its keys and pad reach nobody: a hidden page
# counts as absent at once, whatever its timers do). It beats from the moment it has drawn
# its first batch: a page still loading its scene cannot be driven from, so a reopened
# page's run goes on only once that batch is on screen.
HERE, AWAY = "pbp_drake_here", "pbp_drake_away"
# A page unheard this long counts as gone (`pages_present`: a sleeping computer's, a frozen
# or hung tab's). A tab in view beats each second, unthrottled; a hidden one said AWAY, so
# the once-a-minute timers of long-hidden tabs and the stopped animation frames (no ACK)
# never count. The rest is room for a main thread that stalls (no key gets through then
# either): a page whose CPU was throttled eight times, on a busy two-core machine, went 8 s
# without a timer; and even Chrome's answers to websocket pings wait for that thread.
SILENCE_LIMIT = 10.0
# A page's bad frame closes its websocket with this code (policy violation); a frame over
# MAX_MESSAGE bytes, with websockets' 1009.
BAD_FRAME_CLOSE = 1008
# Accept errors (out of file descriptors) closer together than this are one burst: one line.
ACCEPT_BURST = 10.0
# A connection to Meshcat the front closed counts as its own this long (until Meshcat has
# read the close).
CLOSING_GRACE = 1.0
# How long a closing connection waits for the other side's close (websockets' 10 s would
# outlast a command's end); the front's close waits twice that, then cancels.
CLOSE_TIMEOUT = 1.0

INJECTION = """
<style>
#pbp-console { position: fixed; top: 56px; left: 8px; z-index: 10001; max-width: 45vw;
  box-sizing: border-box; padding: 6px 10px; border-radius: 4px; color: #fff;
  background: rgba(20, 22, 28, 0.85);
  font: 15px/1.4 system-ui, sans-serif; overflow-wrap: anywhere; pointer-events: none; }
#pbp-console > div { white-space: pre-wrap; }
#pbp-console > div:empty { display: none; }
#pbp-title { font-weight: bold; }
body.pbp-ended #status-message { display: none !important; }
</style>
<div id="pbp-console" style="display: none"><div id="pbp-title"></div>
<div id="pbp-status"></div><div id="pbp-result"></div><div id="pbp-notice"></div></div>
<script>
(function () {
  // Our token rides along when the address has it: a cookie is per host, not per port, so
  // another run's page on this machine may have replaced ours.
  var token = new URLSearchParams(location.search).get("token");
  var page = Math.random().toString(36).slice(2) + Date.now().toString(36);
  var query = "?page=" + page + (token ? "&token=" + encodeURIComponent(token) : "");
  var shown = {seq: -1}, served = false, ended = false, drawn = false;
  function take(state) {
    // The newest state wins, whether it came with the scene or by a poll.
    if (ended || state.seq < shown.seq) return;
    if (state.ended) end(state); else show(state);
  }
  function show(state) {
    shown = state;
    ["title", "status", "result", "notice"].forEach(function (name) {
      var line = document.getElementById("pbp-" + name), text = state[name] || "";
      if (line.textContent !== text) line.textContent = text;
    });
    var status = document.getElementById("pbp-status");
    if (state.time == null) status.removeAttribute("data-time");
    else status.setAttribute("data-time", String(state.time));
    var any = state.title || state.status || state.result || state.notice;
    document.getElementById("pbp-console").style.display = any ? "" : "none";
  }
  function end(state) {
    // The run is over: Meshcat's script must not retry, nor leave its yellow banner up.
    ended = true;
    do_reconnect = false;
    document.body.classList.add("pbp-ended");
    // Nothing answers the run's buttons and sliders any more (the keys' included).
    try {
      Object.keys(viewer.gui_controllers).forEach(function (name) {
        viewer.delete_control(name);
      });
    } catch (e) {}
    state = Object.assign({}, state);
    if (!state.notice) state.notice = "ENDED_TEXT";
    show(state);
  }
  function poll() {
    fetch("/pbp/state" + query, {cache: "no-store"})
      .then(function (r) { if (!r.ok) throw new Error(r.status); return r.json(); })
      .then(function (state) { served = true; take(state); })
      .catch(function () { if (served) end(shown); })
      .finally(function () { if (!ended) setTimeout(poll, 1000); });
  }
  // The relay's text frames: the panel's state (a poll would wait behind a slow page's
  // frames), and the end of a batch, answered at the next animation frame.
  var handle_meshcat_message = handle_message;
  handle_message = function (message) {
    if (typeof message.data !== "string") return handle_meshcat_message(message);
    var socket = message.target;
    if (message.data === "FRAME_TEXT") requestAnimationFrame(function () {
      if (socket.readyState === WebSocket.OPEN) socket.send("ACK_TEXT");
      if (!drawn) { drawn = true; beat(); }
    });
    else if (message.data.charAt(0) === "{") { served = true; take(JSON.parse(message.data)); }
  };
  function beat() {
    if (!drawn) return;  // a page still loading its scene is not one to drive from
    var socket = viewer.connection;
    if (socket && socket.readyState === WebSocket.OPEN)
      socket.send(document.hidden ? "AWAY_TEXT" : "HERE_TEXT");
  }
  setInterval(beat, 1000);
  document.addEventListener("visibilitychange", beat);
  // The run's buttons on screen at 1024x640: the Scene tree folded, the control panel open.
  try { viewer.gui.__folders["Scene"].close(); viewer.gui.open(); } catch (e) {}
  poll();
})();
</script>
""".replace("FRAME_TEXT", FRAME).replace("ACK_TEXT", ACK).replace("HERE_TEXT", HERE).replace(
    "AWAY_TEXT", AWAY).replace("ENDED_TEXT", ENDED_NOTICE)


def new_token():
    """A fresh random token for a run's address (32 URL-safe characters)."""
    return secrets.token_urlsafe(24)


def check_token(text):
    """`text` when it can be a run's token (16..128 of `A-Z a-z 0-9 _ -`), else ValueError:
    a guessable or unquotable token would weaken or break the address."""
    if not isinstance(text, str) or not 16 <= len(text) <= 128:
        size = len(text) if isinstance(text, str) else "none"
        raise ValueError(f"a token has 16 to 128 characters (this one has {size})")
    if not _TOKEN.fullmatch(text):
        raise ValueError("a token has only letters, digits, '_' and '-'")
    return text


class PortError(ScenarioError):
    """The page's port cannot be had; the message says what to do instead (the command
    line's refusal, exit 2)."""


def bind_page_port(port, host="localhost"):
    """A listening socket on `host:port` (port 0: a free one), bound before a run builds
    anything, so that a taken port fails at once with a PortError that says what to do."""
    try:
        return socket.create_server((host, port), backlog=64)
    except OSError as error:
        why = {errno.EADDRINUSE: "is in use",
               errno.EACCES: "may not be bound by this process"}.get(error.errno)
        if why is None:
            raise
        raise PortError(f"port {port} {why} (use --port 0 for a free one)") from None


def _panel_value(name, value):
    if name != "time":
        return None if value is None else str(value)
    # JSON has no NaN (the page's JSON.parse would fail): a time that is not finite is none.
    return float(value) if value is not None and math.isfinite(value) else None


def _response(status, body, content_type, *headers):
    status = http.HTTPStatus(status)
    return Response(status.value, status.phrase, Headers([
        ("Date", email.utils.formatdate(usegmt=True)), ("Connection", "close"),
        ("Content-Length", str(len(body))), ("Content-Type", content_type), *headers]), body)


class PageFront:
    """The public port of a run: Meshcat's page and websocket, to the token's holder only.

    Args:
        meshcat_port: the port of the run's Meshcat (on localhost, ideally a private one).
        listen_socket: from `bind_page_port`; None binds a free port on `host`.
        token: the run's token (checked by `check_token`); None draws `new_token()`.
        host: where to bind when `listen_socket` is None, and the host of `url`.

    Serving once made. `show`'s lines reach each page whenever they change (and by a poll
    each second), shown in a panel at the top left; the run's thread needs no event loop.
    """

    def __init__(self, meshcat_port, listen_socket=None, token=None, host="localhost"):
        self._token = new_token() if token is None else check_token(token)
        self._meshcat_port = meshcat_port
        self._socket = listen_socket or bind_page_port(0, host)
        self._port = self._socket.getsockname()[1]
        self._host = "localhost" if host in ("", "0.0.0.0", "::") else host
        self._lock = threading.Lock()
        self._state = dict.fromkeys((*LINES, "time"), None) | {"ended": False, "seq": 0}
        self._ended_pages, self._relays, self._heard, self._closed = set(), 0, 0, False
        self._upstreams, self._closed_upstreams = 0, collections.deque()  # close times
        self._accept_errors = None  # the last accept error's time, in a burst
        self._wakers = set()  # each relay's event: the state changed, send it
        self._last_heard = {}  # each relay's page -> when it last spoke; None: away
        self._door = MeshcatDoor(meshcat_port)
        if not self._door.shut:
            warn(f"Meshcat's port stays open to other programs on this machine "
                  f"({self._door.reason}): what a connection the page front did not open "
                  "sends is ignored while it stays")
        try:
            self._files = self._fetch_page()
        except (OSError, ValueError, http.client.HTTPException) as error:
            self._socket.close()
            self._door.close()
            raise ConnectionError(f"Meshcat at port {meshcat_port} did not serve its page: "
                                  f"{error}") from error
        self._loop = asyncio.new_event_loop()
        self._loop.set_exception_handler(self._loop_error)
        self._thread = threading.Thread(target=self._loop.run_forever, daemon=True,
                                        name=f"pbp-page-front-{self._port}")
        self._thread.start()
        try:
            self._server = asyncio.run_coroutine_threadsafe(self._serve(), self._loop).result(10)
        except BaseException:
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._door.close()
            raise
        register_front(meshcat_port, self)

    @property
    def url(self):
        return f"http://{self._host}:{self._port}/?token={self._token}"

    @property
    def port(self):
        return self._port

    @property
    def token(self):
        return self._token

    def pages(self):
        """How many pages are relayed now: whether a browser is there."""
        return self._relays

    def pages_present(self):
        """How many relayed pages someone can drive from: heard within `SILENCE_LIMIT`
        seconds, their tab not hidden (see `HERE`, `AWAY`). A page counts from its
        first HERE, once it has drawn its first batch."""
        since = time.monotonic() - SILENCE_LIMIT
        with self._lock:
            return sum(heard is not None and heard >= since
                       for heard in self._last_heard.values())

    def pages_heard(self):
        """How many relayed pages have sent a frame other than `AWAY` (our page's first
        `HERE` comes within a second): what `BrowserGuard` counts. One that sent nothing
        cannot press a key."""
        return self._heard

    def own_connections(self):
        """How many connections to Meshcat are the front's: open, opening, or closed less
        than `CLOSING_GRACE` seconds ago (Meshcat may not have read the close yet)."""
        with self._lock:
            now = time.monotonic()
            while self._closed_upstreams and self._closed_upstreams[0] < now - CLOSING_GRACE:
                self._closed_upstreams.popleft()
            return self._upstreams + len(self._closed_upstreams)

    @property
    def door_shut(self):
        """Whether Meshcat's port is shut to all but the front (see `meshcat_door`)."""
        return self._door.shut

    def show(self, **lines):
        """Sets the given lines of the page's panel (title, status, result, notice; None
        hides one) and `time`, the simulated time the status is of; others stay."""
        unknown = set(lines) - {*LINES, "time"}
        if unknown:
            raise TypeError(f"show() takes {', '.join(LINES)} and time, not "
                            f"{', '.join(sorted(unknown))}")
        with self._lock:
            self._state.update({name: _panel_value(name, value) for name, value in lines.items()})
            self._state["seq"] += 1
        self._wake_relays()

    def state(self):
        """What the page's panel shows (the lines, `time` and `ended`), a copy."""
        with self._lock:
            return dict(self._state)

    def end(self, text=None, wait=5.0):
        """Marks the run ended: the page shows `text` as its notice (None: `ENDED_NOTICE`),
        stops reconnecting and hides Meshcat's banner. Waits until every relayed page has
        been sent that (none left on the reconnect banner), at most `wait` s."""
        with self._lock:
            self._state.update(ended=True, notice=text)
            self._state["seq"] += 1
            self._ended_pages.clear()
        self._wake_relays()
        deadline = time.monotonic() + wait
        while time.monotonic() < deadline:
            with self._lock:
                if len(self._ended_pages) >= self._relays:
                    return
            time.sleep(0.02)

    def close(self):
        """Stops serving and closes every relay; a second call does nothing."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
        unregister_front(self._meshcat_port, self)
        with contextlib.suppress(concurrent.futures.TimeoutError):
            asyncio.run_coroutine_threadsafe(self._stop(), self._loop).result(
                4 * CLOSE_TIMEOUT + 5.0)
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(5.0)
        if not self._thread.is_alive():
            self._loop.close()
        self._door.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()

    def _wake_relays(self):
        def wake():
            for waker in self._wakers:
                waker.set()
        with contextlib.suppress(RuntimeError):  # the loop is closed: no relay to wake
            self._loop.call_soon_threadsafe(wake)

    def _fetch_page(self):
        # Meshcat's page, its script (wherever the page says: Drake 1.51 serves it at a
        # content address, not /meshcat.js) and icon, fetched once, here, off the loop.
        html, _ = self._door.get("/")
        html = html.decode()
        script = re.search(r'<script[^>]*\bsrc="([^"]+)"', html)
        if script is None or "</body>" not in html:
            raise ValueError("the page has no script or no </body>")
        source = "/" + script.group(1).lstrip("/")
        code, code_type = self._door.get(source)
        icon, icon_type = self._door.get("/favicon.ico")
        page = html.replace("</body>", INJECTION + "</body>", 1).encode()
        return {**{path: (page, "text/html; charset=utf-8") for path in _PAGES},
                source: (code, code_type), "/meshcat.js": (code, code_type),
                "/favicon.ico": (icon, icon_type)}

    async def _stop(self):
        self._server.close()  # and every connection, with its relay
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(self._server.wait_closed(), 2 * CLOSE_TIMEOUT)
        # What still runs ends here, on the running loop: a task left pending would be
        # destroyed with the loop, its cleanup failing with "no running event loop".
        others = [task for task in asyncio.all_tasks() if task is not asyncio.current_task()]
        for task in others:
            task.cancel()
        await asyncio.gather(*others, return_exceptions=True)
        await asyncio.get_running_loop().shutdown_asyncgens()

    async def _serve(self):
        # No keepalive pings: a page busy rendering answers late, and would be dropped for
        # being slow; a closed tab closes its socket anyway.
        return await serve(self._relay, sock=self._socket, process_request=self._answer,
                           write_limit=WRITE_LIMIT, compression=None, ping_interval=None,
                           max_size=MAX_MESSAGE, server_header=None,
                           close_timeout=CLOSE_TIMEOUT, logger=LOG)

    def _loop_error(self, loop, context):
        """asyncio's errors: an accept that failed (out of file descriptors: asyncio
        retries each second) is one line per burst, not a traceback each time."""
        error = context.get("exception")
        if self._closed and isinstance(error, ValueError) and "_start_serving" in repr(
                context.get("handle")):
            return  # asyncio's retry of such an accept, after the port was closed
        if not context.get("message", "").startswith("socket.accept() out of system"):
            loop.default_exception_handler(context)
            return
        now = time.monotonic()
        if self._accept_errors is None or now - self._accept_errors > ACCEPT_BURST:
            why = error.strerror if isinstance(error, OSError) and error.strerror else error
            warn(f"the page's port cannot accept connections for now ({why}); "
                  "it retries each second, and the run goes on")
        self._accept_errors = now

    def _authorised(self, request, query):
        offered = list(query.get("token", []))
        for header in request.headers.get_all("Cookie"):
            for pair in header.split(";"):
                name, _, value = pair.strip().partition("=")
                if name == COOKIE:
                    offered.append(value)
        token = self._token.encode()
        return any(hmac.compare_digest(value.encode(), token) for value in offered)

    async def _answer(self, connection, request):
        """The request's response, or None to go on to the websocket relay."""
        if not request.path.startswith("/"):  # `GET etc/passwd`, `GET ?token=T`
            return connection.respond(400, "A request's target starts with '/'.\n")
        url = urllib.parse.urlsplit(request.path)
        query = urllib.parse.parse_qs(url.query)
        if not self._authorised(request, query):
            return connection.respond(403, REFUSAL)
        if "websocket" in request.headers.get("Upgrade", "").lower():
            origin = request.headers.get("Origin")
            if origin is None or origin != "http://" + request.headers.get("Host", ""):
                return connection.respond(403, "This websocket is not from the run's page.\n")
            return None
        response = await self._file(url.path, query)
        if query.get("token"):
            response.headers["Set-Cookie"] = (f"{COOKIE}={self._token}; HttpOnly; "
                                              f"SameSite=Strict; Path=/")
        return response

    async def _file(self, path, query):
        if path == "/pbp/state":
            with self._lock:
                body = json.dumps(self._state).encode()
            return _response(200, body, "application/json", ("Cache-Control", "no-store"))
        found = self._files.get(path)
        if found is None:
            try:  # a mesh's or texture's file, at its content address
                found = await asyncio.to_thread(self._door.get, path)
            except (OSError, ValueError, http.client.HTTPException):
                return _response(404, b"Not found\n", "text/plain; charset=utf-8")
            if path.startswith("/cas-v1/"):
                self._files[path] = found
        return _response(200, *found, ("Cache-Control", "no-cache"))

    async def _relay(self, page):
        """One page's relay: a connection to Meshcat of its own (through the door), closed
        when the page goes or Meshcat does, whichever goes first, whenever it goes."""
        with self._lock:
            self._upstreams += 1
        sock = meshcat = port = None
        try:
            sock = await asyncio.to_thread(self._door.connect, 5.0)
            port = sock.getsockname()[1]
            meshcat = await connect(f"ws://localhost:{self._meshcat_port}/", sock=sock,
                                    max_size=None, compression=None, ping_interval=None,
                                    open_timeout=5.0, close_timeout=CLOSE_TIMEOUT,
                                    logger=LOG)
        except (OSError, TimeoutError, InvalidHandshake):
            await page.close(1011, "Meshcat is not reachable")
        else:
            await self._relay_between(page, meshcat)
        finally:
            if port is not None:
                self._door.forget(port)  # first: no other socket may take it meanwhile
            if meshcat is not None:
                await asyncio.gather(meshcat.close(), return_exceptions=True)
            if sock is not None:
                sock.close()  # did the websocket not start, it is still ours
            with self._lock:
                self._upstreams -= 1
                self._closed_upstreams.append(time.monotonic())

    async def _relay_between(self, page, meshcat):
        with contextlib.suppress(OSError, AttributeError):  # None, or closed: page gone
            page.transport.get_extra_info("socket").setsockopt(
                socket.SOL_SOCKET, socket.SO_SNDBUF, SEND_BUFFER)
        pending, ready, acked = PendingMessages(), asyncio.Event(), asyncio.Event()
        paced = False  # until the page's first ACK: a client that never answers
        heard = False  # until the page's first frame that is not refused
        sent_seq = -1  # the panel state this page was sent last
        self._wakers.add(ready)

        def hear():
            nonlocal heard
            self._heard += not heard
            heard = True

        async def to_meshcat():
            nonlocal paced
            async for message in page:
                with self._lock:  # a hidden tab stays away until it says HERE
                    if message == HERE or self._last_heard[page] is not None:
                        self._last_heard[page] = None if message == AWAY else time.monotonic()
                if message in (HERE, AWAY):
                    if message == HERE:
                        hear()  # as an ACK: a page in view, whose keys could drive
                    continue
                if message == ACK:
                    hear()
                    paced = True
                    acked.set()
                    ready.set()
                    continue
                try:  # only what Meshcat's page sends, freshly encoded: Meshcat's parser
                    message = read_page_message(message)  # dies on bytes it cannot read
                except BadMessage as error:
                    warn(f"a page's connection was closed: it sent a bad message ({error})")
                    await page.close(BAD_FRAME_CLOSE, f"bad message: {error}"[:120])
                    return
                hear()  # counted before Meshcat has the input: the guard sees it first
                await meshcat.send(message)

        async def from_meshcat():
            async for message in meshcat:
                pending.put(message_key(message), message)
                ready.set()

        async def send_state():
            # The panel's state goes out whenever it changes, between batches too: it is
            # one small message, and a slow page handles it before the next frame.
            nonlocal sent_seq
            with self._lock:
                state = dict(self._state)
            if state["seq"] != sent_seq:
                sent_seq = state["seq"]
                await page.send(json.dumps(state))
                if state["ended"]:  # sent before any close: the page shows it, see `end`
                    with self._lock:
                        self._ended_pages.add(id(page))

        async def to_page():
            acked.set()  # no batch is out yet
            while True:
                await ready.wait()
                ready.clear()
                await send_state()
                if not pending or (paced and not acked.is_set()):
                    continue  # the scene waits for the page's answer to the last batch
                while pending:  # the panel's state first, should it change meanwhile:
                    await send_state()  # a result must not wait behind a slow batch
                    await page.send(pending.pop())
                await send_state()
                acked.clear()
                await page.send(FRAME)

        self._relays += 1
        with self._lock:
            self._last_heard[page] = None  # away until its first HERE
        tasks = [asyncio.create_task(job()) for job in (to_meshcat, from_meshcat, to_page)]
        try:
            await asyncio.wait(tasks, return_when=asyncio.FIRST_COMPLETED)
        finally:
            self._relays -= 1
            self._heard -= heard
            with self._lock:
                del self._last_heard[page]
            self._wakers.discard(ready)
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
            await asyncio.gather(page.close(), return_exceptions=True)

