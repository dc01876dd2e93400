"""The deployment loop's safety rules: which pose frames may be used, and when the robot must stop.

A frame is *rejected* (never used for a command) when it has a NaN/inf, when its timestamp is not
newer than the last accepted frame's (out of order or repeated), or when the robot or the person
moved more than ``max_jump`` metres since the last accepted frame (no person or robot can; a
mocap swap or glitch can). The data is *stale* when no frame was accepted for ``stale_after``
seconds, and the loop also stops the robot at once when the newest frame of a tick was rejected;
it drives again as soon as good frames return. After
``reanchor_after`` seconds (1 s) without an accepted frame the next finite frame becomes the new
anchor, whatever its timestamp and position: the bodies may really have moved far during a long
dropout, and a sender whose clock restarted (a mocap restart) or one frame stamped far in the
future (which makes every later good frame look out of order) blocks good data for at most that
long.

Independent of the data, the robot stops whenever it is closer than ``min_distance`` to the
person, whatever the policy wants. By default that is ``too_close_distance``: inside the band the
planner keeps (its safety distance), by half the planner's safety margin. A stop at the planner's own
boundary fired in normal driving, where the planner passes a walking person at that distance, and
left the robot standing in the person's way (results/real_protocol_table.md, U-turn: 16 of 20 LBGP
runs and 19 of 20 HC runs ended in contact before this).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from lbgp.real.frames import PoseFrame

OK = "ok"
STALE = "stale"
NON_FINITE = "non_finite"
OUT_OF_ORDER = "out_of_order"
JUMP = "jump"
TOO_CLOSE = "too_close"
NO_DATA = "no_data"
STOP_REASONS = (NO_DATA, STALE, NON_FINITE, OUT_OF_ORDER, JUMP, TOO_CLOSE)


@dataclasses.dataclass
class SafetyConfig:
    stale_after: float = 0.25  # s without an accepted frame -> stop
    max_jump: float = 1.5  # m between consecutive accepted frames, per body
    reanchor_after: float = 1.0  # s without an accepted frame -> next good frame is the new anchor
    min_distance: float | None = None  # m robot-person centre distance; None: too_close_distance(planner limits)
    stop_time: float = 0.15  # s: a safety stop brings the commanded speed from its limit to 0 this fast


def too_close_distance(limits) -> float:
    """The default ``too_close`` distance (robot centre to person centre) for a robot with these
    planner limits (``lbgp.planner.PlannerConfig``): footprint + person radius + half the safety
    margin. The planner keeps the full safety distance, letting the next pose dip at most
    ``clearance_tolerance`` into it, so its plans stay out of this distance (a robot slower to respond
    than the planner assumes can still come closer: the drive model, lbgp.drive_model, is for that);
    the other half of the margin still lies between this stop and contact with a disc-shaped person."""
    return limits.safety_distance - 0.5 * limits.safety_margin


class SafetyMonitor:
    def __init__(self, config: SafetyConfig | None = None):
        self.cfg = config or SafetyConfig()
        self.last: PoseFrame | None = None  # last accepted frame
        self.last_rejection = ""
        self.counts = {reason: 0 for reason in (NON_FINITE, OUT_OF_ORDER, JUMP)}
        self.accepted: list[PoseFrame] = []  # the frames the last ``update`` accepted, oldest first

    def check(self, frame: PoseFrame) -> str:
        """OK if the frame may be used (and remember it), else the reason it may not."""
        if not frame.is_finite():
            return self._reject(NON_FINITE)
        last = self.last
        if last is not None and frame.received - last.received > self.cfg.reanchor_after:
            last = None  # nothing accepted for a while: this frame is the new anchor (time and place)
        if last is not None:
            if frame.t <= last.t:
                return self._reject(OUT_OF_ORDER)
            if (
                np.hypot(*(frame.robot[:2] - last.robot[:2])) > self.cfg.max_jump
                or np.hypot(*(frame.person[:2] - last.person[:2])) > self.cfg.max_jump
            ):
                return self._reject(JUMP)
        self.last = frame
        return OK

    def _reject(self, reason: str) -> str:
        self.counts[reason] += 1
        self.last_rejection = reason
        return reason

    def update(self, frames: list[PoseFrame], now: float) -> str:
        """Check the frames that arrived since the last tick; the data status for this tick:
        the newest frame's rejection reason if it was bad, NO_DATA before the first good frame,
        STALE when the last good frame is older than ``stale_after``, else OK."""
        newest = OK
        self.accepted = []
        for frame in frames:
            newest = self.check(frame)
            if newest == OK:
                self.accepted.append(frame)
        if newest != OK:
            return newest
        if self.last is None:
            return NO_DATA
        if not now - self.last.received <= self.cfg.stale_after:
            return STALE
        return OK
