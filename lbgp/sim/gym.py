"""Gymnasium wrapper over the same follow-ahead task, for users of that API.

    import gymnasium as gym
    import lbgp.sim.gym  # registers the ids
    env = gym.make("lbgp/FollowAhead-v0", level="circles", robot="jackal", control="goal")

``terminated`` is the paper's termination (too close, too far, contact); ``truncated`` is the
episode horizon. ``info`` carries D, alpha, raw poses, the planner's band, etc.
"""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces

from lbgp.sim.env import make_env


class FollowAheadGymEnv(gymnasium.Env):
    metadata = {"render_modes": []}

    def __init__(self, level: str = "straight", robot: str = "jackal", **options):
        self.env = make_env(level, robot=robot, **options)
        obs_spec, act_spec = self.env.observation_spec(), self.env.action_spec()
        self.observation_space = spaces.Box(-1.0, 1.0, obs_spec.shape, np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, act_spec.shape, np.float32)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if seed is not None:
            self.env.task.rng = np.random.default_rng(seed)
        timestep = self.env.reset()
        return np.asarray(timestep.observation, np.float32), self.env.info()

    def step(self, action):
        timestep = self.env.step(np.asarray(action, np.float32))
        terminated = bool(timestep.last() and timestep.discount == 0.0)
        truncated = bool(timestep.last() and not terminated)
        return np.asarray(timestep.observation, np.float32), float(timestep.reward), terminated, truncated, self.env.info()


ENV_ID = "lbgp/FollowAhead-v0"
if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="lbgp.sim.gym:FollowAheadGymEnv")
