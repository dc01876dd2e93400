"""Prioritised replay: the sum tree, the buffer's draws and weights, checkpoints, and a training run."""

import numpy as np
import pytest
import torch

from lbgp.agent.config import D4PGConfig
from lbgp.agent.learner import D4PGLearner
from lbgp.agent.prioritized_replay import PRIORITY_EPS, PrioritizedReplayBuffer, SumTree
from lbgp.agent.replay import ReplayBuffer
from lbgp.agent.train import Trainer


def filled(n=8, capacity=8, **kw):
    buf = PrioritizedReplayBuffer(capacity, 3, 2, **kw)
    obs = np.arange(n, dtype=np.float32)[:, None].repeat(3, 1)
    buf.add_batch(obs, np.zeros((n, 2), np.float32), np.zeros(n, np.float32), np.ones(n, np.float32), obs)
    return buf


def test_the_sum_tree_finds_each_leaf_in_proportion_to_its_value():
    tree = SumTree(5)  # padded to 8 leaves
    tree.set([0, 1, 2, 3, 4], [1.0, 0.0, 3.0, 0.5, 0.5])
    tree.set([3], [0.0])  # an update refreshes the sums above it
    assert tree.total == pytest.approx(4.5)
    leaves = tree.find(np.linspace(0, 4.5, 9001, endpoint=False))
    share = np.bincount(leaves, minlength=8) / len(leaves)
    assert np.allclose(share, [1 / 4.5, 0, 3 / 4.5, 0, 0.5 / 4.5, 0, 0, 0], atol=1e-3)
    with pytest.raises(ValueError, match="finite"):
        tree.set([0], [np.nan])


def test_draws_follow_the_priorities_and_the_weights_undo_them():
    buf = filled(exponent=1.0, correction=1.0)
    losses = np.full(8, 1.0 - PRIORITY_EPS)
    losses[5] = 7.0 - PRIORITY_EPS  # priority 7 against 1 for the others: drawn 7 / 14 of the time
    buf.update_priorities(np.arange(8), losses)
    rng = np.random.default_rng(0)
    drawn, weights = [], {}
    for _ in range(400):
        batch = buf.sample(32, rng)
        idx = batch["index"].numpy()
        drawn.append(idx)
        for i, w in zip(idx, batch["weight"].numpy()):
            weights.setdefault(int(i), set()).add(round(float(w), 6))
        assert np.array_equal(batch["obs"][:, 0].numpy(), idx.astype(np.float32))  # the rows drawn are the rows named
    share = np.bincount(np.concatenate(drawn), minlength=8) / (400 * 32)
    assert share[5] == pytest.approx(0.5, abs=0.02) and np.allclose(np.delete(share, 5), 0.5 / 7, atol=0.01)
    # with full correction, w ~ 1 / P: the frequent transition weighs 1/7 of the others (largest = 1)
    assert weights[5] == {round(1 / 7, 6)} and weights[0] == {1.0}


def test_new_transitions_get_the_largest_priority_seen():
    buf = filled(n=4, exponent=1.0)
    buf.update_priorities([0, 1, 2, 3], [5.0, 0.0, 0.0, 0.0])
    buf.add_batch(np.zeros((1, 3), np.float32), np.zeros((1, 2), np.float32), np.zeros(1, np.float32),
                  np.ones(1, np.float32), np.zeros((1, 3), np.float32))
    assert buf.tree.leaf_values([4])[0] == pytest.approx(5.0 + PRIORITY_EPS)


def test_priorities_survive_a_checkpoint_also_after_the_ring_wrapped():
    buf = filled(n=12, capacity=8)  # wrapped: slots 0-3 hold rows 8-11
    buf.update_priorities(np.arange(8), np.arange(8, dtype=float))
    again = PrioritizedReplayBuffer(8, 3, 2)
    again.load_state_dict(buf.state_dict())
    for row in range(4, 12):  # the same row keeps the same priority wherever it is stored
        old = buf.tree.leaf_values([np.flatnonzero(buf.obs[:, 0] == row)[0]])[0]
        new = again.tree.leaf_values([np.flatnonzero(again.obs[: again.size, 0] == row)[0]])[0]
        assert new == pytest.approx(old)
    # a uniform buffer's checkpoint: every transition at the largest priority
    plain = ReplayBuffer(8, 3, 2)
    plain.add_batch(buf.obs[:3], buf.action[:3], buf.ret[:3], buf.discount[:3], buf.next_obs[:3])
    fresh = PrioritizedReplayBuffer(8, 3, 2)
    fresh.load_state_dict(plain.state_dict())
    assert np.allclose(fresh.tree.leaf_values([0, 1, 2]), 1.0) and fresh.tree.total == pytest.approx(3.0)


def test_an_inconsistent_checkpoint_replay_is_refused_by_name_and_leaves_the_buffer_as_it_was():
    buf = filled(n=6)
    state = buf.state_dict()
    cases = (({**state, "priority": state["priority"][:4]}, "priorities"),
             ({**state, "priority": torch.full((6,), float("nan"))}, "priorities"),
             ({**state, "next_obs": state["next_obs"][:5]}, "'next_obs'"),
             ({**state, "action": torch.zeros(6, 3)}, "'action'"),
             ({f: v for f, v in state.items() if f != "discount"}, "lacks discount"),
             ({f: v for f, v in state.items() if f != "ret"}, "lacks ret"))
    for bad, words in cases:
        target = filled(n=2)
        with pytest.raises(ValueError, match=words):
            target.load_state_dict(bad)
        assert target.size == 2 and target.tree.total == pytest.approx(2.0)  # untouched
    plain = ReplayBuffer(8, 3, 2)
    with pytest.raises(ValueError, match="'obs' has shape"):
        plain.load_state_dict({**state, "obs": torch.zeros(6, 4)})


def test_the_critic_loss_is_weighted_and_the_actor_learns_from_its_own_batch():
    cfg = D4PGConfig(hidden=(16,), actor_warmup_updates=0, normalize_obs=False, seed=0)
    torch.manual_seed(0)
    rng = np.random.default_rng(0)
    n, obs_size = 8, 57
    batch = {"obs": torch.randn(n, obs_size), "action": torch.rand(n, 2) * 2 - 1, "ret": torch.randn(n),
             "discount": torch.full((n,), 0.9), "next_obs": torch.randn(n, obs_size)}
    weight = torch.as_tensor(rng.random(n), dtype=torch.float32)
    other = {**batch, "obs": torch.randn(n, obs_size)}

    def run(b, actor_batch=None):
        torch.manual_seed(1)
        learner = D4PGLearner(cfg, obs_size, 2)
        learner.update(b, actor_batch)
        return learner

    plain, weighted = run(batch), run({**batch, "weight": weight})
    # the per-transition losses are reported before the step and do not depend on the weights
    assert np.allclose(plain.sample_losses, weighted.sample_losses) and plain.sample_losses.shape == (n,)
    differs = lambda a, b: any(not torch.equal(p, q) for p, q in zip(a.parameters(), b.parameters()))  # noqa: E731
    assert differs(plain.critic, weighted.critic)
    # the actor's step is taken on actor_batch when one is given, on the critic's batch otherwise
    assert differs(plain.actor, run(batch, other).actor) and not differs(plain.actor, run(batch, batch).actor)


def test_a_run_with_prioritised_replay_trains_and_resumes_with_its_priorities(tmp_path):
    assert D4PGConfig.parse_setting("priority_exponent=0.6") == ("priority_exponent", 0.6)
    with pytest.raises(ValueError, match="priority_exponent"):
        D4PGConfig(priority_exponent=1.5).validate()
    cfg = D4PGConfig(total_steps=100, min_replay=40, horizon=10, hidden=(16,), batch_size=16, actor_warmup_updates=0,
                     seed=1, priority_exponent=0.6)
    trainer = Trainer(cfg, tmp_path / "run", backend="inline", progress=False)
    summary = trainer.run()
    assert isinstance(trainer.replay, PrioritizedReplayBuffer) and summary["learner_updates"] > 0
    priorities = trainer.replay.tree.leaf_values(np.arange(len(trainer.replay)))
    assert len(np.unique(priorities)) > 10  # the critic's losses replaced the initial priorities
    resumed = Trainer(cfg, tmp_path / "run", resume=True, backend="inline", progress=False)
    assert len(resumed.replay) == len(trainer.replay) > 0
    assert np.allclose(resumed.replay.tree.leaf_values(np.arange(len(resumed.replay))), priorities)
