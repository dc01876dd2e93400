"""Curriculum over person-motion levels: straight -> circles -> smoothed -> trajectories.

The learner advances to the next level when the exploiting actor's mean return over the last
``window`` episodes on the current level reaches that level's threshold, or when the level has used
its share of the total step budget, or (for runs with a time limit) its share of the time limit,
whichever comes first. Exploring actors keep playing an earlier level in a small share
of their episodes (``earlier_share``) so that nothing is forgotten. Without curriculum, training
runs on the final level only (the paper's ablation).
"""

from __future__ import annotations

import collections

import numpy as np

from lbgp.sim.tasks import CURRICULUM


class Curriculum:
    def __init__(self, enabled: bool, thresholds, budget_fractions, total_steps: int, window: int = 10, time_limit_s: float = 0.0):
        self.levels = CURRICULUM
        self.enabled = enabled
        self.thresholds = tuple(thresholds)
        self.budgets = tuple(int(f * total_steps) for f in budget_fractions)
        self.time_budgets = tuple(f * time_limit_s if time_limit_s else float("inf") for f in budget_fractions)
        if len(self.thresholds) != len(self.levels) - 1 or len(self.budgets) != len(self.levels) - 1:
            raise ValueError(f"need a threshold and a budget for each of the first {len(self.levels) - 1} levels")
        self.index = 0 if enabled else len(self.levels) - 1
        self.level_start_step = 0
        self.level_start_time = 0.0
        self.returns: collections.deque = collections.deque(maxlen=window)
        self.history: list[tuple[int, str]] = [(0, self.level)]

    @property
    def level(self) -> str:
        return self.levels[self.index]

    @property
    def final(self) -> bool:
        return self.index == len(self.levels) - 1

    def record(self, level: str, episode_return: float, env_steps: int, wall_time: float = 0.0) -> bool:
        """Report one exploiting episode; returns True when the curriculum advanced."""
        if level == self.level:
            self.returns.append(episode_return)
        if self.final:
            return False
        full = len(self.returns) == self.returns.maxlen
        passed = full and float(np.mean(self.returns)) >= self.thresholds[self.index]
        out_of_budget = (
            env_steps - self.level_start_step >= self.budgets[self.index]
            or wall_time - self.level_start_time >= self.time_budgets[self.index]
        )
        if passed or out_of_budget:
            self.index += 1
            self.level_start_step = env_steps
            self.level_start_time = wall_time
            self.returns.clear()
            self.history.append((env_steps, self.level))
            return True
        return False

    def pick_level(self, rng: np.random.Generator, exploring: bool, earlier_share: float) -> str:
        """The level of an actor's next episode."""
        if exploring and self.enabled and self.index > 0 and rng.uniform() < earlier_share:
            return self.levels[int(rng.integers(0, self.index))]
        return self.level

    def state(self) -> dict:
        return {
            "index": self.index,
            "level_start_step": self.level_start_step,
            "level_start_time": self.level_start_time,
            "returns": list(self.returns),
            "history": [list(h) for h in self.history],
        }

    def load_state(self, state: dict) -> None:
        self.index = int(state["index"])
        self.level_start_step = int(state["level_start_step"])
        self.level_start_time = float(state.get("level_start_time", 0.0))
        self.returns.clear()
        self.returns.extend(state["returns"])
        self.history = [(int(s), str(lv)) for s, lv in state["history"]]
