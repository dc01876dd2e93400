"""benchmarks/critic_guided_acting.py: acting with the critic's best goal near the actor's."""

import sys
from pathlib import Path

import numpy as np
import pytest
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from critic_guided_acting import GRID, CriticGuidedPolicy, load_critic  # noqa: E402

from lbgp.actions import mirror_action  # noqa: E402
from lbgp.agent.checkpoint import save_atomic  # noqa: E402
from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.learner import D4PGLearner  # noqa: E402
from lbgp.agent.train import CHECKPOINT_FORMAT  # noqa: E402
from lbgp.policies import default_policy_path, make_policy  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402

SHIPPED = str(default_policy_path("lbgp"))


class BowlCritic(torch.nn.Module):
    """A mirror-consistent critic for one observation: there it values an action by minus its
    squared distance to ``best``; in the observation's mirror image, to ``best``'s mirror image."""

    def __init__(self, obs, best):
        super().__init__()
        self.obs = torch.as_tensor(np.asarray(obs), dtype=torch.float32)
        self.best = torch.as_tensor(np.asarray(best), dtype=torch.float32)

    def q_value(self, obs, action):
        if torch.equal(obs, self.obs.expand_as(obs)):
            best = self.best
        elif torch.equal(obs, torch.as_tensor(obs_lib.mirror(self.obs.numpy())).expand_as(obs)):
            best = self.best * torch.tensor([1.0, -1.0])
        else:
            raise AssertionError("asked about an observation it does not know")
        return -((action - best) ** 2).sum(-1)


def test_the_guided_policy_sends_the_candidate_the_critic_values_most(noisy_observations):
    plain = make_policy("lbgp", SHIPPED, robot="jackal")
    radius = 0.1
    for obs in noisy_observations("turning_inside", 1, 5):
        own = plain.act(obs)
        # the critic's favourite lies up and right of the actor's action, beyond the grid: the corner wins
        guided = CriticGuidedPolicy(plain, BowlCritic(obs, np.clip(own + [0.5, 0.0], -1, 1)), radius)
        assert guided.act(obs) == pytest.approx(np.clip(own + [radius, 0.0], -1, 1), abs=1e-5)
        # a favourite inside the grid: the nearest grid point to it (spacing radius / 2)
        step = 2 * radius / (GRID - 1)
        guided = CriticGuidedPolicy(plain, BowlCritic(obs, own + [step * 0.9, -step * 1.1]), radius)
        assert guided.act(obs) == pytest.approx(own + [step, -step], abs=1e-5)


def test_a_critic_favouring_the_actors_own_action_changes_nothing(noisy_observations):
    plain = make_policy("lbgp", SHIPPED, robot="jackal")
    for obs in noisy_observations("turning_inside", 1, 5):
        own = plain.act(obs)
        guided = CriticGuidedPolicy(plain, BowlCritic(obs, own), 0.1)
        assert guided.act(obs) == pytest.approx(own, abs=1e-6)


def test_the_critic_is_read_back_from_a_training_checkpoint(tmp_path, noisy_observations):
    cfg = D4PGConfig(method="lbgp", robot="jackal")
    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    with torch.no_grad():
        for p in learner.critic.parameters():
            p.add_(0.1 * torch.randn_like(p))
    save_atomic({"format": CHECKPOINT_FORMAT, "version": 1, "config": cfg.__dict__ | {"hidden": list(cfg.hidden)},
                 "learner": learner.state_dict()}, tmp_path / "checkpoint.pt")
    critic = load_critic(tmp_path)
    obs = torch.as_tensor(np.stack(noisy_observations("turning_inside", 1, 3)), dtype=torch.float32)
    actions = torch.tensor([[0.2, 0.1], [-0.3, 0.5], [0.0, 0.0]])
    with torch.no_grad():
        torch.testing.assert_close(critic.q_value(obs, actions), learner.critic.q_value(obs, actions))
    # a run whose critic reads hindsight features is refused with its reason
    future = D4PGConfig(method="lbgp", robot="jackal", critic_future=True)
    save_atomic({"format": CHECKPOINT_FORMAT, "version": 1, "config": future.__dict__ | {"hidden": list(future.hidden)},
                 "learner": D4PGLearner(future, obs_lib.SIZE, 2).state_dict()}, tmp_path / "checkpoint.pt")
    with pytest.raises(ValueError, match="critic_future"):
        load_critic(tmp_path)


def test_mirror_images_get_mirrored_choices(noisy_observations):
    plain = make_policy("lbgp", SHIPPED, robot="jackal")
    for obs in noisy_observations("turning_inside", 1, 5):
        own = plain.act(obs)
        critic = BowlCritic(obs, own + [0.04, 0.07])
        choice = CriticGuidedPolicy(plain, critic, 0.1).act(obs)
        assert choice == pytest.approx(own + [0.05, 0.05], abs=1e-5)  # the grid point nearest the favourite
        assert CriticGuidedPolicy(plain, critic, 0.1).act(obs_lib.mirror(obs)) == pytest.approx(mirror_action(choice), abs=1e-5)
