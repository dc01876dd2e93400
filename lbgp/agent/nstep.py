"""n-step transitions from a stream of single steps.

A transition is (obs, action, R, discount, next_obs) with R = sum_i gamma^i r_i over k <= n steps
and the bootstrap target R + discount * Q(next_obs). At a true termination the discount is 0 (no
bootstrap); at a time-limit truncation the episode did not end for the agent, so the discount stays
gamma^k and the value of the last observation is bootstrapped.
"""

from __future__ import annotations

import collections

import numpy as np


class NStepAccumulator:
    def __init__(self, n: int, discount: float):
        self.n = n
        self.discount = discount
        self._window: collections.deque = collections.deque()

    def reset(self) -> None:
        self._window.clear()

    def _emit(self, next_obs, terminal: bool):
        obs, action, _ = self._window[0]
        rewards = np.array([r for _, _, r in self._window])
        k = len(rewards)
        ret = float(np.sum(rewards * self.discount ** np.arange(k)))
        disc = 0.0 if terminal else self.discount**k
        self._window.popleft()
        return obs, action, ret, disc, next_obs

    def step(self, obs, action, reward: float, next_obs, terminal: bool = False, truncated: bool = False) -> list:
        """Add one step; returns the transitions that became complete (possibly none)."""
        self._window.append((np.asarray(obs, np.float32), np.asarray(action, np.float32), float(reward)))
        out = []
        if terminal or truncated:
            while self._window:
                out.append(self._emit(np.asarray(next_obs, np.float32), terminal))
        elif len(self._window) == self.n:
            out.append(self._emit(np.asarray(next_obs, np.float32), False))
        return out
