"""Meshcat's port shut to everyone but the page front: a classic BPF filter
(`SO_ATTACH_FILTER`, Linux) on Meshcat's listening socket, a descriptor of this process,
that admits only the front's own sockets; docs/design.md ("The page") says how and what
it does not cover. It cannot be shut outside Linux, or for a Meshcat in another process or
not on loopback alone (`MeshcatDoor.reason`).
"""

import contextlib
import ctypes
import errno
import http.client
import os
import socket
import struct
import sys
import threading

SO_ATTACH_FILTER = 26  # <asm-generic/socket.h>; Python's socket module lacks it
# Classic BPF (<linux/filter.h>): loads of a word or half-word at an offset, a jump if
# equal, a return. Offsets below SKF_NET_OFF count from the IP header, others from TCP's.
_LOAD_WORD, _LOAD_HALF, _JUMP_IF_EQUAL, _RETURN = 0x20, 0x28, 0x15, 0x06
_NET = -0x100000
_KEEP, _DROP = 0xFFFFFFFF, 0
# Where the source address is in each IP header (IPv4's 4 bytes at 12, IPv6's 16 at 8).
_SOURCE = {socket.AF_INET: (12, 1), socket.AF_INET6: (8, 4)}
MAX_OPEN = 200  # the front's sockets to Meshcat at once (one a page): the jumps' reach


class MeshcatDoor:
    """The door to the Meshcat on `port` of this process: shut to all but `connect()`'s
    sockets when `shut`; else open (`reason` says why) and `connect()` connects plainly."""

    def __init__(self, port):
        self.port = int(port)
        self._lock = threading.Lock()
        self._admitted, self._closed = set(), False
        self._listeners, self.reason = _listeners(self.port)
        self._address = ("localhost", self.port)
        if self._listeners:
            self._address = self._listeners[0].getsockname()
            family = self._listeners[0].family
            if any(s.family != family or s.getsockname()[0] != self._address[0]
                   for s in self._listeners):
                self._close_listeners("Meshcat listens on more than one address")
            elif self._address[0] != "::1" and not self._address[0].startswith("127."):
                self._close_listeners(f"Meshcat listens on {self._address[0]}, not on "
                                      "this machine's loopback alone")
        if self._listeners:
            try:
                self._refilter()
            except OSError as error:
                self._close_listeners(f"the socket filter was refused ({error.strerror})")

    @property
    def shut(self):
        return bool(self._listeners)

    def connect(self, timeout=5.0):
        """A blocking socket connected to Meshcat (through the door when it is shut);
        OSError once the door is closed."""
        with self._lock:
            if self._closed:
                raise OSError(errno.ECONNREFUSED, "the door to Meshcat is closed")
            family = self._listeners[0].family if self._listeners else None
        if family is None:
            return socket.create_connection(self._address, timeout=timeout)
        sock = socket.socket(family, socket.SOCK_STREAM)
        try:
            sock.bind((self._address[0], 0))
            with self._lock:
                if self._closed:
                    raise OSError(errno.ECONNREFUSED, "the door to Meshcat is closed")
                if len(self._admitted) >= MAX_OPEN:
                    raise OSError(errno.EMFILE, f"{MAX_OPEN} connections to Meshcat are open")
                self._admitted.add(sock.getsockname()[1])
                self._refilter()
            sock.settimeout(timeout)
            sock.connect(self._address[:2])
        except BaseException:
            self.release(sock)
            raise
        return sock

    def forget(self, port):
        """Takes the port of a socket of `connect()`'s off the door, before that socket is
        closed: no other socket may take the port while the door admits it. The socket's
        connection goes on (an accepted connection keeps the filter it was accepted with)."""
        with self._lock:
            if port in self._admitted:
                self._admitted.discard(port)
                with contextlib.suppress(OSError):
                    self._refilter()

    def release(self, sock):
        """`forget`s `sock`'s port and closes it."""
        with contextlib.suppress(OSError):
            self.forget(sock.getsockname()[1])
        sock.close()

    def get(self, path, timeout=10.0):
        """Meshcat's answer to `GET path`: (body, content type); OSError unless 200."""
        sock = self.connect(timeout)
        try:
            connection = http.client.HTTPConnection("localhost", self.port, timeout=timeout)
            connection.sock = sock
            connection.request("GET", path, headers={"Host": f"localhost:{self.port}"})
            reply = connection.getresponse()
            body = reply.read()
            if reply.status != 200:
                raise OSError(f"Meshcat answered {reply.status} to GET {path}")
            return body, reply.getheader("Content-Type") or "application/octet-stream"
        finally:
            self.release(sock)

    def close(self):
        """Lets go of the listener, leaving the door shut to everyone."""
        with self._lock:
            self._closed = True
            self._admitted.clear()
            with contextlib.suppress(OSError):
                self._refilter()
            self._close_listeners(self.reason)

    def _refilter(self):
        if not self._listeners:
            return  # open, or let go of
        program = _program(self._listeners[0].family, self._address[0], self._admitted)
        for listener in self._listeners:
            _attach(listener, program)

    def _close_listeners(self, reason):
        for listener in self._listeners:
            listener.close()  # our duplicate: Meshcat's own descriptor stays open
        self._listeners, self.reason = [], reason


def _listeners(port):
    """Duplicates of this process's listening TCP sockets on `port`, and why there are none."""
    if not sys.platform.startswith("linux"):
        return [], f"a socket filter needs Linux, not {sys.platform}"
    found = []
    for name in os.listdir("/proc/self/fd"):
        try:
            duplicate = os.dup(int(name))
        except OSError:
            continue  # closed meanwhile
        try:
            sock = socket.socket(fileno=duplicate)
        except OSError:
            os.close(duplicate)  # not a socket
            continue
        try:
            if (sock.type == socket.SOCK_STREAM
                    and sock.family in (socket.AF_INET, socket.AF_INET6)
                    and sock.getsockopt(socket.SOL_SOCKET, socket.SO_ACCEPTCONN)
                    and sock.getsockname()[1] == port):
                found.append(sock)
                continue
        except OSError:
            pass
        sock.close()
    return found, None if found else f"no socket of this process listens on port {port}"


def _program(family, address, ports):
    """The filter: keep a packet from `address` and one of `ports`, drop the rest."""
    offset, words = _SOURCE[family]
    packed = socket.inet_pton(family, address)
    steps = []  # (code, jump if true: a label or 0, jump if false: a label or 0, k)
    for i in range(words):
        steps.append((_LOAD_WORD, 0, 0, _NET + offset + 4 * i))
        steps.append((_JUMP_IF_EQUAL, 0, "drop", int.from_bytes(packed[4 * i:4 * i + 4], "big")))
    steps.append((_LOAD_HALF, 0, 0, 0))  # the TCP source port
    steps.extend((_JUMP_IF_EQUAL, "keep", 0, port) for port in sorted(ports))
    labels = {"drop": len(steps), "keep": len(steps) + 1}
    steps += [(_RETURN, 0, 0, _DROP), (_RETURN, 0, 0, _KEEP)]
    code = b"".join(
        struct.pack("HBBI", op, *(labels[j] - at - 1 if j else 0 for j in (yes, no)),
                    k & 0xFFFFFFFF)
        for at, (op, yes, no, k) in enumerate(steps))
    return code, len(steps)


def _attach(listener, program):
    code, count = program
    buffer = ctypes.create_string_buffer(code, len(code))
    # struct sock_fprog {unsigned short len; struct sock_filter *filter;}: the kernel copies
    # the instructions during the call, so the buffer may go after it.
    listener.setsockopt(socket.SOL_SOCKET, SO_ATTACH_FILTER,
                        struct.pack("HP", count, ctypes.addressof(buffer)))
