"""An honest but cheap learning check: a few minutes of real training on the straight level.

Training runs on the ``inline`` backend (actors in the learner's process, the learner catching up
with one update per collected step), so the run is the same every time for its seed, whatever the
machine's load. What is checked:

* the exploiting actor's returns (the paper's learning curve: noise-free episodes of the current
  policy) rise by a clear margin from the first third of the run to the last, and end clearly
  above a random policy's return on the same level;
* the final policy file beats the untrained network it started from.

For scale (12 seeded episodes of the straight level, robot starting anywhere around the person):
the untrained actor scores about -9.7, a random policy -5.7, the best constant goal (1.5 m ahead)
+1.3.
"""

import numpy as np
import pytest
import torch

from lbgp.agent import load_policy
from lbgp.agent.config import D4PGConfig
from lbgp.agent.networks import Actor
from lbgp.agent.train import read_curve, train
from lbgp.rollout import run_episode
from lbgp.sim import make_env
from lbgp.sim import observation as obs_lib


class RandomPolicy:
    control = "goal"

    def __init__(self, seed):
        self.rng = np.random.default_rng(seed)

    def act(self, observation):
        return self.rng.uniform(-1, 1, 2).astype(np.float32)


class NetworkPolicy:
    control = "goal"

    def __init__(self, actor):
        self.actor = actor

    def act(self, observation):
        with torch.no_grad():
            return self.actor(torch.from_numpy(observation)[None])[0].numpy()


def mean_return(policy, episodes=12, seed=1234):
    env = make_env("straight", seed=seed, control=policy.control)
    return float(np.mean([run_episode(env, policy).total_reward for _ in range(episodes)]))


@pytest.mark.slow
def test_short_training_learns_on_the_straight_level(tmp_path):
    # stay on the first curriculum level: unreachable thresholds and a budget as large as the run
    cfg = D4PGConfig(seed=0, total_steps=10_000, level_thresholds=(1e9, 1e9, 1e9), level_budget_fraction=(10.0, 10.0, 10.0))
    torch.manual_seed(cfg.seed)
    untrained = Actor(obs_lib.SIZE, 2, cfg.hidden)  # the learner's initial actor (same seed, same construction)
    summary = train(cfg, tmp_path / "run", backend="inline", progress=False)
    assert summary["final_level"] == "straight" and summary["learner_updates"] >= 9_000

    curve = [r["exploit_return"] for r in read_curve(tmp_path / "run" / "curve.csv")]
    third = len(curve) // 3
    first, last = float(np.mean(curve[:third])), float(np.mean(curve[-third:]))
    random = mean_return(RandomPolicy(0))
    assert last > first + 4.0, (first, last)
    assert last > random + 4.0, (last, random)

    trained = mean_return(load_policy(tmp_path / "run" / "policy.pt"))
    assert trained > mean_return(NetworkPolicy(untrained)) + 3.0
