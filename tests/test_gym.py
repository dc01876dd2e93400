import gymnasium
import numpy as np
from gymnasium.utils.env_checker import check_env

import lbgp.sim.gym  # noqa: F401  (registers the id)


def test_gymnasium_env_passes_the_checker():
    env = gymnasium.make("lbgp/FollowAhead-v0", level="straight", horizon=5).unwrapped
    check_env(env, skip_render_check=True)


def test_terminated_and_truncated():
    env = gymnasium.make("lbgp/FollowAhead-v0", level="straight_ahead", horizon=3, control="velocity")
    obs, info = env.reset(seed=1)
    assert obs.shape == (57,) and "distance" in info
    for _ in range(3):
        obs, reward, terminated, truncated, info = env.step(np.array([0.6, 0.0], np.float32))
    assert truncated and not terminated
    env.unwrapped.env.reset()
    env.unwrapped.env.place_robot(6.0, 0.0)
    _, _, terminated, truncated, _ = env.step(np.zeros(2, np.float32))
    assert terminated and not truncated
