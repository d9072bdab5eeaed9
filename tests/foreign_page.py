"""A page from elsewhere: a raw websocket client that connects to a Meshcat server with any
`Origin` and sends the messages a Meshcat page sends (msgpack maps, as the browser does).

It stands for another tab of the user's browser, or any program on the machine: Drake's
Meshcat checks no origin. Only sockets are used here, so it may run on any thread.
"""

import base64
import os
import socket
import struct
import threading

import msgpack

_BINARY_FRAME, _CLOSE_FRAME = 0x82, 0x88  # FIN set


class ForeignPage:
    """One websocket connection to `localhost:port`, opened with `origin` at `path` (which
    may hold a `?token=`); ConnectionError, with the status line, when it is refused."""

    def __init__(self, port, origin="http://evil.example", path="/"):
        self._socket = socket.create_connection(("localhost", port), timeout=5.0)
        key = base64.b64encode(os.urandom(16)).decode()
        self._socket.sendall((
            f"GET {path} HTTP/1.1\r\nHost: localhost:{port}\r\nUpgrade: websocket\r\n"
            f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
            f"Sec-WebSocket-Version: 13\r\nOrigin: {origin}\r\n\r\n").encode())
        response = b""
        while b"\r\n\r\n" not in response:
            chunk = self._socket.recv(4096)
            if not chunk:
                raise ConnectionError("Meshcat closed the connection during the handshake")
            response += chunk
        status = response.split(b"\r\n", 1)[0]
        if b" 101 " not in status:
            raise ConnectionError(f"Meshcat refused the websocket: {status!r}")
        # Meshcat streams the scene to every page: read it all, so no buffer fills.
        self._received = bytearray(response.split(b"\r\n\r\n", 1)[1])
        self._lock = threading.Lock()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        try:
            while chunk := self._socket.recv(65536):
                with self._lock:
                    self._received += chunk
        except OSError:
            pass

    def received(self):
        """Every byte Meshcat sent this page so far (frames and all)."""
        with self._lock:
            return bytes(self._received)

    def send(self, message):
        self._send_frame(_BINARY_FRAME, msgpack.packb(message))

    def press(self, button):
        """What Meshcat's page sends when a button is clicked (or its key pressed)."""
        self.send({"type": "button", "name": button})

    def close(self):
        try:
            self._send_frame(_CLOSE_FRAME, struct.pack(">H", 1000))
        except OSError:
            pass
        self._socket.close()

    def _send_frame(self, opcode, payload):
        # A client masks every frame (RFC 6455, 5.3).
        size = len(payload)
        if size < 126:
            header = bytes([opcode, 0x80 | size])
        elif size < 1 << 16:
            header = bytes([opcode, 0x80 | 126]) + struct.pack(">H", size)
        else:
            header = bytes([opcode, 0x80 | 127]) + struct.pack(">Q", size)
        mask = os.urandom(4)
        masked = bytes(byte ^ mask[i % 4] for i, byte in enumerate(payload))
        self._socket.sendall(header + mask + masked)
