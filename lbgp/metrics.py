"""Per-episode follow-ahead metrics, the same for simulation, deployment logs and replays."""

from __future__ import annotations

import dataclasses
import math

import numpy as np


@dataclasses.dataclass
class EpisodeMetrics:
    setting: str = ""
    distances: list = dataclasses.field(default_factory=list)
    alphas: list = dataclasses.field(default_factory=list)  # radians
    rewards: list = dataclasses.field(default_factory=list)
    contact: bool = False
    terminated_early: bool = False

    def add(self, distance: float, alpha: float, reward: float) -> None:
        self.distances.append(float(distance))
        self.alphas.append(float(alpha))
        self.rewards.append(float(reward))

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
            "collision": bool(self.contact),
            "terminated_early": bool(self.terminated_early),
        }


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
        "collisions": int(sum(e.contact for e in episodes)),
        "terminated_early": int(sum(e.terminated_early for e in episodes)),
        "steps": float(np.mean([e.steps for e in episodes])) if episodes else nan,
    }
