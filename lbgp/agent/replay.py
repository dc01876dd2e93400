"""Uniform replay of n-step transitions (a ring buffer of numpy arrays)."""

from __future__ import annotations

import numpy as np
import torch

from lbgp.actions import mirror_actions
from lbgp.agent.previous_goal import mirror_input

FIELDS = ("obs", "action", "ret", "discount", "next_obs")


def mirrored(batch):
    """The mirror images of a batch of n-step transitions ``(obs, action, ret, discount, next_obs)``
    about the person's heading line: observations by ``lbgp.sim.observation.mirror`` (with the
    previous action, if they hold one, mirrored as an action), actions by
    ``lbgp.actions.mirror_actions``; the reward depends on distance and |alpha| only, so returns
    and discounts stay."""
    obs, action, ret, discount, next_obs = batch
    return mirror_input(obs), mirror_actions(action), ret, discount, mirror_input(next_obs)


class ReplayBuffer:
    def __init__(self, capacity: int, obs_size: int, action_size: int):
        self.capacity = int(capacity)
        self.obs = np.zeros((capacity, obs_size), np.float32)
        self.action = np.zeros((capacity, action_size), np.float32)
        self.ret = np.zeros(capacity, np.float32)
        self.discount = np.zeros(capacity, np.float32)
        self.next_obs = np.zeros((capacity, obs_size), np.float32)
        self.size = 0
        self.cursor = 0

    def __len__(self) -> int:
        return self.size

    def add_batch(self, obs, action, ret, discount, next_obs) -> np.ndarray:
        """Store the transitions; returns the slots they went to."""
        n = len(ret)
        idx = (self.cursor + np.arange(n)) % self.capacity
        self.obs[idx], self.action[idx], self.ret[idx] = obs, action, ret
        self.discount[idx], self.next_obs[idx] = discount, next_obs
        self.cursor = int((self.cursor + n) % self.capacity)
        self.size = int(min(self.size + n, self.capacity))
        return idx

    def oldest_first(self) -> np.ndarray:
        """The slots that hold transitions, from the oldest to the newest."""
        n = self.size
        return np.arange(n) if n < self.capacity else (self.cursor + np.arange(n)) % self.capacity

    def sample(self, batch_size: int, rng: np.random.Generator) -> dict[str, torch.Tensor]:
        if self.size == 0:
            raise ValueError("cannot sample from an empty replay buffer")
        idx = rng.integers(0, self.size, batch_size)
        return {f: torch.from_numpy(getattr(self, f)[idx]) for f in FIELDS}

    # -- checkpointing (tensors only, so that torch.load(weights_only=True) can read it)
    def state_dict(self) -> dict:
        order = self.oldest_first()
        return {f: torch.from_numpy(getattr(self, f)[order].copy()) for f in FIELDS}

    def checked_length(self, state: dict) -> int:
        """The number of transitions in a checkpoint's replay ``state``; ValueError naming the field
        that is missing or whose shape does not fit this buffer."""
        missing = [f for f in FIELDS if f not in state]
        if missing:
            raise ValueError(f"checkpoint replay lacks {', '.join(missing)}")
        n = len(state["ret"])
        widths = {"obs": self.obs.shape[1], "action": self.action.shape[1], "next_obs": self.next_obs.shape[1]}
        for f in FIELDS:
            shape = tuple(state[f].shape)
            if shape[0] != n or shape[1:] != ((widths[f],) if f in widths else ()):
                want = (n, widths[f]) if f in widths else (n,)
                raise ValueError(f"checkpoint replay field {f!r} has shape {shape}, expected {want}")
        return n

    def load_state_dict(self, state: dict) -> None:
        n = self.checked_length(state)
        if n > self.capacity:
            state = {f: v[-self.capacity :] for f, v in state.items()}
            n = self.capacity
        self.size, self.cursor = 0, 0
        if n:
            self.add_batch(*(state[f].numpy() for f in FIELDS))
