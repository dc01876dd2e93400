"""UDP/JSON transport: a pose source, a command sink, and the robot-side command listener.

Every listener binds to 127.0.0.1 unless another address is named, and drops datagrams from
senders that were not allowed (by IP, or IP and port). Sockets are non-blocking: nothing here
ever waits longer than the caller's timeout.
"""

from __future__ import annotations

import logging
import select
import socket

from lbgp.real.frames import FrameError, PoseFrame, decode_command, decode_frame, encode_command
from lbgp.real.throttle import ThrottledLog

log = ThrottledLog(logging.getLogger(__name__))
MAX_DATAGRAM = 65_507


def parse_address(text: str, default_host: str = "127.0.0.1") -> tuple[str, int]:
    """'PORT', 'HOST:PORT' -> (host, port)."""
    host, _, port = text.rpartition(":")
    try:
        number = int(port)
    except ValueError:
        raise ValueError(f"{text!r} is not PORT or HOST:PORT") from None
    if not 0 <= number < 65536:
        raise ValueError(f"port {number} out of range")
    return (host or default_host), number


class _Listener:
    def __init__(self, bind=("127.0.0.1", 0), allowed_senders=("127.0.0.1",)):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self.sock.bind(tuple(bind))
        except OSError as exc:
            self.sock.close()
            raise ValueError(f"cannot listen on {bind[0]}:{bind[1]}: {exc.strerror or exc}") from None
        self.sock.setblocking(False)
        self.allowed = {self._norm(s) for s in allowed_senders}
        self.rejected_senders = 0
        self.malformed = 0

    @staticmethod
    def _norm(sender):
        if isinstance(sender, str):
            host, _, port = sender.partition(":")
            return (host, int(port)) if port else (host, None)
        return (sender[0], sender[1] if len(sender) > 1 else None)

    @property
    def address(self) -> tuple[str, int]:
        return self.sock.getsockname()

    def _allowed(self, addr) -> bool:
        return (addr[0], addr[1]) in self.allowed or (addr[0], None) in self.allowed

    def _datagrams(self, timeout: float):
        """Datagrams from allowed senders that arrive within ``timeout`` (all queued ones, at least)."""
        ready, _, _ = select.select([self.sock], [], [], max(timeout, 0.0))
        while ready:
            try:
                data, addr = self.sock.recvfrom(MAX_DATAGRAM)
            except BlockingIOError:
                break
            if not self._allowed(addr):
                self.rejected_senders += 1
                log.warning("sender", "dropped a datagram from %s:%s (not an allowed sender)", *addr)
                continue
            yield data

    def close(self) -> None:
        self.sock.close()


class UdpPoseSource(_Listener):
    """Pose frames as JSON datagrams (see lbgp.real.frames)."""

    def __init__(self, bind=("127.0.0.1", 0), allowed_senders=("127.0.0.1",), clock=None):
        super().__init__(bind, allowed_senders)
        self.clock = clock

    def poll(self, now: float, timeout: float = 0.0) -> list[PoseFrame]:
        frames = []
        for data in self._datagrams(timeout):
            try:
                frame = decode_frame(data)
            except FrameError as exc:
                self.malformed += 1
                log.warning("malformed", "dropped a malformed pose datagram: %s", exc)
                continue
            frame.received = now
            frames.append(frame)
        return frames


def sending_socket(destination: tuple[str, int], bind: tuple[str, int] | None = None) -> socket.socket:
    """A UDP socket that only sends to ``destination``: bound to ``bind`` if given, else to the
    loopback address for a loopback destination, else to the one local address that routes to the
    destination (never all interfaces), and connected, so the kernel drops anything that arrives
    from another address; its receive buffer is kept minimal, since nothing reads it."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1)
        host = destination[0]
        if bind is not None:
            sock.bind(tuple(bind))
        elif host == "localhost" or host.startswith("127."):
            sock.bind(("127.0.0.1", 0))
        sock.connect(tuple(destination))  # binds the routed local address when not bound yet
    except OSError:
        sock.close()
        raise
    return sock


class UdpCommandSink:
    """Send each command as a JSON datagram to the robot's listener (see ``sending_socket``)."""

    def __init__(self, address: tuple[str, int], bind: tuple[str, int] | None = None):
        self.address = tuple(address)
        try:
            self.sock = sending_socket(self.address, bind)
        except OSError as exc:
            raise ValueError(f"cannot send commands to {self.address[0]}:{self.address[1]}: {exc.strerror or exc}") from None

    def send(self, t: float, v: float, w: float, status: str = "ok") -> None:
        try:
            self.sock.send(encode_command(t, v, w, status))
        except ConnectionRefusedError:  # nobody listening yet (ICMP port unreachable): the next one may land
            pass

    def close(self) -> None:
        self.sock.close()


class UdpCommandListener(_Listener):
    """The robot side of ``UdpCommandSink`` (used by the simulated robot and by tests)."""

    def poll(self, timeout: float = 0.0) -> list[tuple[float, float, float, str]]:
        out = []
        for data in self._datagrams(timeout):
            try:
                out.append(decode_command(data))
            except FrameError as exc:
                self.malformed += 1
                log.warning("malformed", "dropped a malformed command datagram: %s", exc)
        return out
