"""Per-episode follow-ahead metrics, the same for simulation, deployment logs and replays."""

from __future__ import annotations

import dataclasses
import math

import numpy as np


LOOP_ANGLE = math.pi  # rad: a loop turns the robot's heading (relative to the person's) through more than this


class LoopDetector:
    """Counts loops: stretches of an episode in which the robot's heading, relative to the
    person's, turns through more than 180 degrees while the robot's goal stays ahead of the person
    (a planner that circles instead of slowing down). Following a person round a U-turn turns the
    robot with the person and is not a loop. Fed once per agent step."""

    def __init__(self):
        self.loops = 0
        self._last = None  # unwrapped relative heading at the previous step of the current stretch
        self._low = self._high = 0.0

    def add(self, robot_yaw: float, person_yaw: float, goal_ahead: bool = True) -> None:
        relative = math.remainder(robot_yaw - person_yaw, 2.0 * math.pi)
        if not goal_ahead:
            self._last = None
            return
        if self._last is None:
            self._last = self._low = self._high = relative
            return
        self._last += math.remainder(relative - self._last, 2.0 * math.pi)
        self._low, self._high = min(self._low, self._last), max(self._high, self._last)
        if self._high - self._low > LOOP_ANGLE:
            self.loops += 1
            self._low = self._high = self._last  # each further half turn counts again


@dataclasses.dataclass
class EpisodeMetrics:
    setting: str = ""
    distances: list = dataclasses.field(default_factory=list)
    alphas: list = dataclasses.field(default_factory=list)  # radians
    rewards: list = dataclasses.field(default_factory=list)
    contact: bool = False
    terminated_early: bool = False
    loop_detector: LoopDetector = dataclasses.field(default_factory=LoopDetector)

    def add(self, distance: float, alpha: float, reward: float, robot_yaw: float | None = None,
            person_yaw: float | None = None, goal_ahead: bool = True) -> None:
        """One agent step. With the two headings (rad) the step also feeds the loop detector;
        ``goal_ahead``: the robot's goal lies in front of the person (True when there is no goal)."""
        self.distances.append(float(distance))
        self.alphas.append(float(alpha))
        self.rewards.append(float(reward))
        if robot_yaw is not None and person_yaw is not None:
            self.loop_detector.add(float(robot_yaw), float(person_yaw), goal_ahead)

    @property
    def loops(self) -> int:
        return self.loop_detector.loops

    @property
    def steps(self) -> int:
        return len(self.rewards)

    @property
    def total_reward(self) -> float:
        return float(np.sum(self.rewards)) if self.rewards else 0.0

    def summary(self) -> dict:
        d = np.asarray(self.distances)
        a = np.degrees(np.asarray(self.alphas))
        nan = math.nan
        return {
            "setting": self.setting,
            "steps": self.steps,
            "reward": self.total_reward,
            "distance_mean": float(d.mean()) if d.size else nan,
            "distance_std": float(d.std()) if d.size else nan,
            "alpha_mean_deg": float(a.mean()) if a.size else nan,
            "alpha_std_deg": float(a.std()) if a.size else nan,
            # how far from straight in front the robot was once it had time to get there
            "abs_alpha_second_half_deg": float(np.abs(a[a.size // 2 :]).mean()) if a.size else nan,
            "collision": bool(self.contact),
            "terminated_early": bool(self.terminated_early),
            "loops": self.loops,
        }


def goal_ahead_of_person(goal, person_pose) -> bool:
    """Whether a world goal (x, y, ...) lies in front of the person (True when there is no goal)."""
    if goal is None:
        return True
    c, s = math.cos(float(person_pose[2])), math.sin(float(person_pose[2]))
    return c * (float(goal[0]) - float(person_pose[0])) + s * (float(goal[1]) - float(person_pose[1])) > 0.0


def reward_ci95(rewards) -> float:
    """Half-width of the 95 % confidence interval of the mean episode reward (Student's t); NaN
    with fewer than two episodes, 0 when every episode scored the same."""
    r = np.asarray(rewards, dtype=float)
    if r.size < 2:
        return math.nan
    from scipy import stats

    return float(stats.t.ppf(0.975, r.size - 1) * r.std(ddof=1) / math.sqrt(r.size))


def aggregate(episodes: list[EpisodeMetrics]) -> dict:
    """Mean +- std over all steps of all episodes; reward = mean accumulated reward per episode."""
    d = np.concatenate([np.asarray(e.distances) for e in episodes]) if episodes else np.zeros(0)
    a = np.degrees(np.concatenate([np.asarray(e.alphas) for e in episodes])) if episodes else np.zeros(0)
    rewards = [e.total_reward for e in episodes]
    nan = math.nan
    return {
        "episodes": len(episodes),
        "distance_mean": float(d.mean()) if d.size else nan,
        "distance_std": float(d.std()) if d.size else nan,
        "alpha_mean_deg": float(a.mean()) if a.size else nan,
        "alpha_std_deg": float(a.std()) if a.size else nan,
        "reward": float(np.mean(rewards)) if rewards else nan,
        "reward_std": float(np.std(rewards)) if rewards else nan,
        "reward_ci95": reward_ci95(rewards),
        "episode_rewards": [float(r) for r in rewards],  # in episode (seed) order: methods pair up by index
        "collisions": int(sum(e.contact for e in episodes)),
        "terminated_early": int(sum(e.terminated_early for e in episodes)),
        "loops": int(sum(e.loops > 0 for e in episodes)),  # episodes with at least one loop
        "steps": float(np.mean([e.steps for e in episodes])) if episodes else nan,
    }
