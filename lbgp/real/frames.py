"""What travels between the outside world and the deployment loop: pose frames and commands.

UDP/JSON wire format (one UTF-8 JSON object per datagram; documented in docs/deploy.md):

    pose frame   {"t": 12.345, "robot": [x, y, yaw], "person": [x, y, yaw]}
    command      {"t": 12.345, "v": 0.31, "w": -0.12, "status": "ok"}

``t`` is the sender's timestamp in seconds (monotonic per sender), positions in metres in the
motion-capture world frame, yaw in radians (counter-clockwise from +x), v in m/s, w in rad/s.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np


MAX_FRAME_BYTES = 4096  # a pose frame is ~100 bytes; anything longer is dropped before parsing


class FrameError(ValueError):
    """A datagram that is not a well-formed pose frame or command."""


def _json(data: bytes, what: str):
    """Parse one datagram's JSON; every way it can fail (size, encoding, syntax, nesting too deep
    for the parser) is a FrameError."""
    if len(data) > MAX_FRAME_BYTES:
        raise FrameError(f"{what} of {len(data)} bytes is longer than {MAX_FRAME_BYTES}")
    try:
        return json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError, ValueError) as exc:
        raise FrameError(f"not a JSON {what}: {type(exc).__name__}") from None


@dataclasses.dataclass
class PoseFrame:
    t: float  # source timestamp, s
    robot: np.ndarray  # (x, y, yaw)
    person: np.ndarray  # (x, y, yaw)
    received: float = math.nan  # loop clock time at arrival, s (set by the source)

    def is_finite(self) -> bool:
        return bool(math.isfinite(self.t) and np.all(np.isfinite(self.robot)) and np.all(np.isfinite(self.person)))


def _pose(value, what: str) -> np.ndarray:
    # NaN/inf are representable (Python's json reads NaN/Infinity) and are left for the safety
    # monitor to reject, so that they are counted and logged rather than silently dropped
    try:
        pose = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError, RecursionError):
        raise FrameError(f"{what} must be [x, y, yaw] numbers, got {value!r}") from None
    if pose.shape != (3,):
        raise FrameError(f"{what} must be [x, y, yaw], got {value!r}")
    return pose


def encode_frame(frame: PoseFrame) -> bytes:
    return json.dumps({"t": frame.t, "robot": [float(v) for v in frame.robot], "person": [float(v) for v in frame.person]}).encode()


def decode_frame(data: bytes) -> PoseFrame:
    msg = _json(data, "pose frame")
    if not isinstance(msg, dict) or not {"t", "robot", "person"} <= msg.keys():
        raise FrameError("a pose frame needs the keys t, robot and person")
    try:
        t = float(msg["t"])
    except (TypeError, ValueError, OverflowError):
        raise FrameError(f"t must be a number, got {msg['t']!r}") from None
    return PoseFrame(t, _pose(msg["robot"], "robot"), _pose(msg["person"], "person"))


def encode_command(t: float, v: float, w: float, status: str = "ok") -> bytes:
    return json.dumps({"t": float(t), "v": float(v), "w": float(w), "status": status}).encode()


def decode_command(data: bytes) -> tuple[float, float, float, str]:
    msg = _json(data, "command")
    try:
        out = float(msg["t"]), float(msg["v"]), float(msg["w"]), str(msg.get("status", "ok"))
    except (KeyError, TypeError, ValueError, AttributeError, OverflowError) as exc:
        raise FrameError(f"not a JSON command: {exc!r}") from None
    if not all(math.isfinite(x) for x in out[:3]):
        raise FrameError(f"command has non-finite numbers: {out[:3]}")
    return out
