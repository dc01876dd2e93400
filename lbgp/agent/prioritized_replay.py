"""Prioritised replay (Schaul et al. 2016, proportional variant) for the critic, measured as an option.

A transition is drawn with probability ``P(i) = p_i / sum_k p_k`` where ``p_i = (loss_i + eps) **
exponent`` and ``loss_i`` is its critic cross-entropy when it was last trained on (new transitions
get the largest priority seen so far, so each is replayed at least about once). The critic's loss
is weighted by the importance weights ``w_i = (N P(i)) ** -correction``, divided by the batch's
largest. The D4PG paper lists prioritised replay among its options; acme's D4PG and this project's
default replay uniformly. Following Saglam et al. (2023, "Actor Prioritized Experience Replay"), the
actor's loss is computed on a separate uniform batch: a deterministic policy gradient taken
where the critic is least accurate points the wrong way.

The priorities sit in a sum tree (``SumTree``): drawing a batch and updating its priorities cost
O(batch x log capacity) numpy operations, not O(capacity).
"""

from __future__ import annotations

import numpy as np
import torch

from lbgp.agent.replay import FIELDS, ReplayBuffer

PRIORITY_EPS = 1e-3  # keeps every transition drawable (a loss of 0 would never be replayed again)


class SumTree:
    """Non-negative leaf values in a binary tree of partial sums (leaves padded to a power of two)."""

    def __init__(self, capacity: int):
        self.leaves = 1 << max(int(capacity) - 1, 1).bit_length()
        self.tree = np.zeros(2 * self.leaves)

    @property
    def total(self) -> float:
        return float(self.tree[1])

    def leaf_values(self, index) -> np.ndarray:
        return self.tree[np.asarray(index) + self.leaves]

    def set(self, index, values) -> None:
        """Set leaves ``index`` to ``values`` and refresh their ancestors (a repeated index keeps its
        last value, as numpy assignment does)."""
        node = np.asarray(index, dtype=np.int64) + self.leaves
        values = np.asarray(values, dtype=float)
        if np.any(~np.isfinite(values)) or np.any(values < 0):
            raise ValueError("priorities must be finite and >= 0")
        self.tree[node] = values
        node = np.unique(node // 2)
        while node[0] >= 1:  # every leaf is at the same depth, so each pass is one level up
            self.tree[node] = self.tree[2 * node] + self.tree[2 * node + 1]
            if node[0] == 1:
                break
            node = np.unique(node // 2)

    def find(self, mass) -> np.ndarray:
        """For each ``mass`` in [0, total): the leaf whose cumulative range holds it."""
        mass = np.asarray(mass, dtype=float).copy()
        node = np.ones(len(mass), dtype=np.int64)
        while node[0] < self.leaves:
            left = self.tree[2 * node]
            right = mass >= left
            mass = np.where(right, mass - left, mass)
            node = 2 * node + right
        return node - self.leaves


class PrioritizedReplayBuffer(ReplayBuffer):
    def __init__(self, capacity: int, obs_size: int, action_size: int, exponent: float = 0.6, correction: float = 0.4):
        super().__init__(capacity, obs_size, action_size)
        if not 0.0 < exponent <= 1.0 or not 0.0 <= correction <= 1.0:
            raise ValueError(f"priority exponent must be in (0, 1] and correction in [0, 1], got {exponent}, {correction}")
        self.exponent = float(exponent)
        self.correction = float(correction)
        self.tree = SumTree(self.capacity)
        self.max_priority = 1.0

    def add_batch(self, obs, action, ret, discount, next_obs) -> np.ndarray:
        idx = super().add_batch(obs, action, ret, discount, next_obs)
        self.tree.set(idx, np.full(len(idx), self.max_priority))
        return idx

    def sample(self, batch_size: int, rng: np.random.Generator) -> dict[str, torch.Tensor]:
        """A prioritised batch (stratified: one draw in each of ``batch_size`` equal slices of the
        total priority), with ``index`` (for :meth:`update_priorities`) and ``weight`` (importance
        weights, largest 1) besides the transition fields."""
        if self.size == 0:
            raise ValueError("cannot sample from an empty replay buffer")
        total = self.tree.total
        mass = (np.arange(batch_size) + rng.random(batch_size)) * (total / batch_size)
        idx = np.minimum(self.tree.find(np.minimum(mass, np.nextafter(total, 0.0))), self.size - 1)
        prob = self.tree.leaf_values(idx) / total
        weight = (self.size * np.maximum(prob, 1e-12)) ** -self.correction
        batch = {f: torch.from_numpy(getattr(self, f)[idx]) for f in FIELDS}
        batch["index"] = torch.from_numpy(idx)
        batch["weight"] = torch.from_numpy((weight / weight.max()).astype(np.float32))
        return batch

    def sample_uniform(self, batch_size: int, rng: np.random.Generator) -> dict[str, torch.Tensor]:
        return super().sample(batch_size, rng)

    def update_priorities(self, index, losses) -> None:
        """New priorities from the critic losses of the transitions at ``index``."""
        priority = (np.abs(np.asarray(losses, dtype=float)) + PRIORITY_EPS) ** self.exponent
        self.tree.set(np.asarray(index), priority)
        self.max_priority = max(self.max_priority, float(priority.max()))

    def state_dict(self) -> dict:
        state = super().state_dict()
        state["priority"] = torch.from_numpy(self.tree.leaf_values(self.oldest_first()).copy())
        return state

    def load_state_dict(self, state: dict) -> None:
        # every transition comes back at the largest priority (add_batch); a prioritised run's
        # checkpoint then restores its own (a uniform run's has none)
        if "priority" in state:
            n = self.checked_length(state)  # the transitions' fields first, so a missing one is named as such
            priority = state["priority"].numpy()
            if priority.shape != (n,) or not np.all(np.isfinite(priority) & (priority > 0)):
                raise ValueError(f"checkpoint replay's priorities must be one positive finite number per transition "
                                 f"({n}), got shape {priority.shape}")
        super().load_state_dict({f: v for f, v in state.items() if f != "priority"})
        if "priority" in state and self.size:
            priority = priority[-self.size :]
            self.tree.set(np.arange(self.size), priority)
            self.max_priority = max(1.0, float(priority.max()))
