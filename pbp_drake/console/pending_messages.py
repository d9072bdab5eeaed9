"""The relay's queue toward a slow page (`pbp_drake.console.front`)."""

import collections

import msgpack


def message_key(message):
    """What a Meshcat message sets, when a later one of the same key replaces it (a body's
    pose, one property, the real-time rate), else None: a barrier that keeps its place."""
    if not isinstance(message, bytes):
        return None
    fields = {}
    try:
        unpacker = msgpack.Unpacker(raw=False)
        unpacker.feed(message)
        for _ in range(unpacker.read_map_header()):
            name = unpacker.unpack()
            if name in ("type", "path", "property"):
                fields[name] = unpacker.unpack()
            else:
                unpacker.skip()
    except (ValueError, TypeError, msgpack.UnpackException):
        return None
    kind, path = fields.get("type"), str(fields.get("path"))
    if kind == "set_transform":
        return (kind, path)
    if kind == "set_property":
        return (kind, path, str(fields.get("property")))
    if kind == "realtime_rate":
        return (kind,)
    return None


class PendingMessages:
    """Meshcat's messages waiting for a slow page, bounded by what they set, not by time.

    A message with a key replaces its pending predecessor of the same key (in its place); a
    message without a key is a barrier that nothing moves across. So the queue is a list of
    segments, each the keyed messages since the last barrier and the barrier that closes it.
    """

    def __init__(self):
        self._segments = collections.deque([[{}, None]])  # [key -> message, barrier]
        self._size = 0

    def put(self, key, message):
        keyed, _ = self._segments[-1]
        if key is None:
            self._segments[-1][1] = message
            self._segments.append([{}, None])
        elif key in keyed:
            keyed[key] = message
            return
        else:
            keyed[key] = message
        self._size += 1

    def pop(self):
        """The oldest pending message; IndexError when none is."""
        if not self._size:
            raise IndexError("no message is pending")
        keyed, barrier = self._segments[0]
        self._size -= 1
        if keyed:
            return keyed.pop(next(iter(keyed)))
        # An empty segment that is not the open last one ends in its barrier.
        self._segments.popleft()
        return barrier

    def __len__(self):
        return self._size
