"""Policy averaging (``lbgp train --policy-average TAU``): the learner keeps an exponential moving
average of the actor's weights, the checkpoint carries it, and the run's policy file holds it while
the last actor is kept beside it as ``policy_last.pt``."""

import copy
import json

import numpy as np
import pytest
import torch

from lbgp.agent import load_policy
from lbgp.agent.config import D4PGConfig
from lbgp.agent.learner import D4PGLearner
from lbgp.agent.train import Trainer
from lbgp.sim import observation as obs_lib


def _batch(rng, n=16):
    obs = rng.uniform(-1, 1, (2 * n, obs_lib.SIZE)).astype(np.float32)
    return {"obs": torch.from_numpy(obs[:n]), "action": torch.from_numpy(rng.uniform(-1, 1, (n, 2)).astype(np.float32)),
            "ret": torch.from_numpy(rng.uniform(-1, 1, n).astype(np.float32)), "discount": torch.full((n,), 0.9),
            "next_obs": torch.from_numpy(obs[n:])}


def _params(net):
    return [p.detach().clone() for p in net.parameters()]


def test_the_average_follows_the_actor_by_tau_per_update_after_the_warm_up():
    tau = 0.25
    cfg = D4PGConfig(hidden=(8,), batch_size=16, actor_warmup_updates=2, policy_average=tau)
    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    rng = np.random.default_rng(0)
    learner.set_obs_stats(rng.uniform(-1, 1, (64, obs_lib.SIZE)).astype(np.float32))
    assert torch.equal(learner.average_actor.norm.obs_std, learner.actor.norm.obs_std)
    start = _params(learner.actor)
    for _ in range(2):  # warm-up: neither the actor nor its average moves
        learner.update(_batch(rng))
    assert all(torch.equal(a, b) for a, b in zip(_params(learner.average_actor), start))
    for _ in range(3):
        before = _params(learner.average_actor)
        learner.update(_batch(rng))
        actor = _params(learner.actor)
        for avg, old, new in zip(_params(learner.average_actor), before, actor):
            torch.testing.assert_close(avg, old + tau * (new - old))
    moved = [not torch.equal(a, b) for a, b in zip(_params(learner.average_actor), _params(learner.actor))]
    assert any(moved)  # the average lags the actor
    assert learner.policy_actor is learner.average_actor
    plain = D4PGLearner(D4PGConfig(hidden=(8,)), obs_lib.SIZE, 2)
    assert plain.average_actor is None and plain.policy_actor is plain.actor and "average_actor" not in plain.state_dict()


def test_the_checkpoint_carries_the_average_and_an_older_one_starts_it_at_the_actor():
    cfg = D4PGConfig(hidden=(8,), batch_size=16, actor_warmup_updates=0, policy_average=0.5)
    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    rng = np.random.default_rng(1)
    learner.set_obs_stats(rng.uniform(-1, 1, (64, obs_lib.SIZE)).astype(np.float32))
    for _ in range(3):
        learner.update(_batch(rng))
    state = copy.deepcopy(learner.state_dict())
    again = D4PGLearner(cfg, obs_lib.SIZE, 2)
    again.load_state_dict(state)
    assert all(torch.equal(a, b) for a, b in zip(_params(again.average_actor), _params(learner.average_actor)))
    del state["average_actor"]  # a checkpoint from a run without averaging, resumed with it
    older = D4PGLearner(cfg, obs_lib.SIZE, 2)
    older.load_state_dict(state)
    assert all(torch.equal(a, b) for a, b in zip(_params(older.average_actor), _params(learner.actor)))


def test_a_run_writes_the_average_as_its_policy_and_keeps_the_last_actor(tmp_path):
    cfg = D4PGConfig(total_steps=120, min_replay=40, horizon=10, hidden=(16,), batch_size=16, actor_warmup_updates=0,
                     policy_average=0.05, seed=2)
    trainer = Trainer(cfg, tmp_path / "run", backend="inline", progress=False)
    summary = trainer.run()
    assert summary["learner_updates"] > 0 and summary["policy_average"] == 0.05
    averaged, last = load_policy(tmp_path / "run" / "policy.pt"), load_policy(tmp_path / "run" / "policy_last.pt")
    for policy, net in ((averaged, trainer.learner.average_actor), (last, trainer.learner.actor)):
        for key, value in net.state_dict().items():
            assert torch.equal(policy.actor.state_dict()[key], value), key
    obs = np.random.default_rng(3).uniform(-0.5, 0.5, obs_lib.SIZE).astype(np.float32)
    assert not np.array_equal(averaged.act(obs), last.act(obs))
    assert json.loads((tmp_path / "run" / "config.json").read_text())["policy_average"] == 0.05
    plain = Trainer(D4PGConfig(**{**json.loads(cfg.to_json()), "policy_average": 0.0, "hidden": (16,)}), tmp_path / "plain",
                    backend="inline", progress=False)
    plain.run()
    assert (tmp_path / "plain" / "policy.pt").is_file() and not (tmp_path / "plain" / "policy_last.pt").exists()


def test_a_tau_outside_0_to_1_is_refused():
    with pytest.raises(ValueError, match="policy_average"):
        D4PGConfig(policy_average=1.0).validate()
    with pytest.raises(ValueError, match="policy_average"):
        D4PGConfig(policy_average=-0.1).validate()


def test_soft_target_updates_move_both_targets_by_tau_through_the_same_average():
    cfg = D4PGConfig(hidden=(8,), batch_size=16, actor_warmup_updates=0, target_tau=0.1)
    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    rng = np.random.default_rng(4)
    learner.set_obs_stats(rng.uniform(-1, 1, (64, obs_lib.SIZE)).astype(np.float32))
    before = {name: _params(getattr(learner, name)) for name in ("target_actor", "target_critic")}
    learner.update(_batch(rng))
    for name, net in (("target_actor", learner.actor), ("target_critic", learner.critic)):
        for got, old, new in zip(_params(getattr(learner, name)), before[name], _params(net)):
            torch.testing.assert_close(got, old + 0.1 * (new - old))
