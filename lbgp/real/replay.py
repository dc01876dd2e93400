"""Re-play an lbgp MCAP log: the metrics of the evaluation command again, and a rerun recording.

Also the ``mcap://FILE`` pose source: a log's frames fed to a fresh deployment loop on a virtual
clock (open loop: the logged robot does not react to the new commands).
"""

from __future__ import annotations

import json

from lbgp.geometry import distance_and_alpha
from lbgp.metrics import EpisodeMetrics, goal_ahead_of_person
from lbgp.real.mcap_log import frames_of, pose_of, read_log
from lbgp.sim.rewards import follow_ahead_reward


def _key(t: float) -> float:
    return round(t, 6)


def _status(msg) -> dict:
    """A /lbgp/status message's JSON ({} when a damaged log garbled it)."""
    try:
        status = json.loads(msg.data)
    except (ValueError, TypeError, RecursionError):
        return {}
    return status if isinstance(status, dict) else {}


def replay_log(path, recorder=None) -> tuple[EpisodeMetrics, dict]:
    """Metrics of a log's agent steps (D, alpha, reward from the logged poses), as the loop computed them."""
    log = read_log(path)
    steps = {_key(t) for t, m in log["/lbgp/status"] if _status(m).get("agent_step")}
    goals = {_key(t): pose_of(m) for t, m in log["/lbgp/goal"]}
    bands = {_key(t): [pose_of(p) for p in m.poses] for t, m in log["/lbgp/plan"]}
    metrics = EpisodeMetrics(setting=log["metadata"].get("setting", "replay"))
    if recorder is not None:
        recorder.begin_episode(f"replay of {path}")
    for frame in frames_of(log):
        key = _key(frame.t)
        if key not in steps:
            continue
        distance, alpha = distance_and_alpha(frame.robot, frame.person)
        reward = follow_ahead_reward(distance, alpha)
        metrics.add(distance, alpha, reward, frame.robot[2], frame.person[2], goal_ahead_of_person(goals.get(key), frame.person))
        if recorder is not None:
            recorder.log_step({"time": frame.t, "distance": distance, "alpha": alpha, "robot_pose": frame.robot,
                               "person_pose": frame.person, "goal": goals.get(key), "band": bands.get(key)}, reward)
    return metrics, log


class ReplayClock:
    """Virtual time: sleeping jumps there at once."""

    def __init__(self):
        self.t = 0.0

    def now(self) -> float:
        return self.t

    def sleep_until(self, t: float) -> None:
        self.t = max(self.t, t)


class McapPoseSource:
    """The frames of an lbgp log, delivered when the (virtual) clock passes their time."""

    def __init__(self, path):
        self.frames = frames_of(read_log(path))
        self.clock = ReplayClock()
        self.clock.t = self.frames[0].t if self.frames else 0.0
        self._next = 0

    @property
    def finished(self) -> bool:
        return self._next >= len(self.frames)

    def poll(self, now: float, timeout: float = 0.0) -> list:
        out = []
        while self._next < len(self.frames) and self.frames[self._next].t <= now + 1e-9:
            frame = self.frames[self._next]
            frame.received = now
            out.append(frame)
            self._next += 1
        return out

    def close(self) -> None:
        pass
