"""What `read_first_status` and `read_first_state` use of a DrakeLcm (a test helper): a bus
whose first message on `channel` is `message`."""


class FirstMessage:

    def __init__(self, channel, message):
        self._channel, self._message, self._handlers = channel, message, {}

    def Subscribe(self, channel, handler):
        self._handlers[channel] = handler

    def HandleSubscriptions(self, timeout_millis):
        self._handlers[self._channel](self._message.encode())
        return 1
