"""An honest but cheap learning check: a couple of minutes of real training on the straight level
beat a random policy by a clear margin (seeded; marked slow, still part of CI)."""

import numpy as np
import pytest

from lbgp.agent import load_policy
from lbgp.agent.config import D4PGConfig
from lbgp.agent.train import train
from lbgp.rollout import run_episode
from lbgp.sim import make_env


class RandomPolicy:
    control = "goal"

    def __init__(self, seed):
        self.rng = np.random.default_rng(seed)

    def act(self, observation):
        return self.rng.uniform(-1, 1, 2).astype(np.float32)


def mean_return(policy, episodes=12, seed=1234):
    env = make_env("straight", seed=seed, control=policy.control)
    return float(np.mean([run_episode(env, policy).total_reward for _ in range(episodes)]))


@pytest.mark.slow
def test_short_training_beats_random_on_the_straight_level(tmp_path):
    # stay on the first curriculum level: unreachable threshold and a budget as large as the run
    cfg = D4PGConfig(seed=0, total_steps=10**9, time_limit_s=150.0, level_thresholds=(1e9, 1e9, 1e9), level_budget_fraction=(1.0, 1.0, 1.0))
    summary = train(cfg, tmp_path / "run", progress=False)
    assert summary["final_level"] == "straight" and summary["learner_updates"] > 500
    trained = mean_return(load_policy(tmp_path / "run" / "policy.pt"))
    random = mean_return(RandomPolicy(0))
    assert trained > random + 4.0, (trained, random)
