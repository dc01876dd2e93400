import os

import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "disable")  # before anything imports mujoco


@pytest.fixture
def noisy_observations():
    """``collect(scenario, seed, n)``: the first n observations of a scenario with observation noise,
    the robot driven by a fixed action: inputs for tests of how a policy acts."""
    from lbgp.sim import make_env

    def collect(scenario: str, seed: int, n: int) -> list:
        env = make_env(scenario, seed=seed, obs_noise=True)
        ts, out = env.reset(), []
        for _ in range(n):
            out.append(ts.observation)
            ts = env.step(np.array([0.25, 0.1]))
        return out

    return collect
