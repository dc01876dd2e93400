"""Rate-limited warnings: a flood of bad datagrams must not become a flood of log lines."""

from __future__ import annotations

import logging
import time


class ThrottledLog:
    """At most one line per ``period`` seconds for each kind of event; the next line that gets
    through says how many of that kind were left out in between."""

    def __init__(self, logger: logging.Logger, period: float = 1.0, clock=time.monotonic):
        self.logger, self.period, self.clock = logger, period, clock
        self._last: dict[str, float] = {}
        self._suppressed: dict[str, int] = {}

    def warning(self, kind: str, message: str, *args) -> None:
        now = self.clock()
        last = self._last.get(kind)
        if last is not None and now - last < self.period:
            self._suppressed[kind] = self._suppressed.get(kind, 0) + 1
            return
        left_out = self._suppressed.pop(kind, 0)
        self._last[kind] = now
        if left_out:
            message += f" (and {left_out} more like it in the last {now - last:.1f} s)"
        self.logger.warning(message, *args)
