"""D4PG building blocks: categorical projection, n-step returns, replay, curriculum, policy files."""

import numpy as np
import pytest
import torch

from lbgp.agent.config import D4PGConfig
from lbgp.agent.curriculum import Curriculum
from lbgp.agent.distributional import categorical_projection
from lbgp.agent.networks import Actor
from lbgp.agent.nstep import NStepAccumulator
from lbgp.agent.policy import load_policy, save_policy
from lbgp.agent.replay import ReplayBuffer

ATOMS = torch.linspace(-2.0, 2.0, 5)  # spacing 1


def test_projection_hand_computed():
    probs = torch.tensor([[0.0, 0.0, 1.0, 0.0, 0.0]])  # all mass on 0
    # r + g * z = 0.5 + 0.5 * 0 = 0.5: halfway between atoms 0 and 1
    out = categorical_projection(probs, torch.tensor([0.5]), torch.tensor([0.5]), ATOMS)
    torch.testing.assert_close(out, torch.tensor([[0.0, 0.0, 0.5, 0.5, 0.0]]))
    # landing exactly on an atom keeps all the mass there
    out = categorical_projection(probs, torch.tensor([1.0]), torch.tensor([0.9]), ATOMS)
    torch.testing.assert_close(out, torch.tensor([[0.0, 0.0, 0.0, 1.0, 0.0]]))
    # beyond the support: clipped to the end atom
    out = categorical_projection(probs, torch.tensor([7.0]), torch.tensor([1.0]), ATOMS)
    torch.testing.assert_close(out, torch.tensor([[0.0, 0.0, 0.0, 0.0, 1.0]]))


def test_projection_two_atom_case():
    probs = torch.tensor([[0.25, 0.0, 0.0, 0.0, 0.75]])  # mass at -2 and +2
    # r = 0.2, g = 0.5: -2 -> -0.8 (0.8 on -1, 0.2 on 0), +2 -> 1.2 (0.8 on 1, 0.2 on 2)
    out = categorical_projection(probs, torch.tensor([0.2]), torch.tensor([0.5]), ATOMS)
    torch.testing.assert_close(out, torch.tensor([[0.0, 0.25 * 0.8, 0.25 * 0.2, 0.75 * 0.8, 0.75 * 0.2]]))


def test_projection_preserves_mass_and_terminal_is_a_point_mass():
    gen = torch.Generator().manual_seed(0)
    probs = torch.softmax(torch.randn(64, 51, generator=gen), -1)
    atoms = torch.linspace(-30, 30, 51)
    returns = torch.randn(64, generator=gen) * 10
    discounts = torch.rand(64, generator=gen)
    out = categorical_projection(probs, returns, discounts, atoms)
    torch.testing.assert_close(out.sum(-1), torch.ones(64))
    assert torch.all(out >= 0)
    # discount 0 (terminal): the target is the return alone, whatever the next distribution
    out = categorical_projection(probs, torch.full((64,), 3.0), torch.zeros(64), atoms)
    mean = (out * atoms).sum(-1)
    torch.testing.assert_close(mean, torch.full((64,), 3.0))


def _collect(acc, rewards, end):
    out = []
    for i, r in enumerate(rewards):
        last = i == len(rewards) - 1
        out += acc.step([float(i)], [0.0], r, [float(i + 1)], terminal=last and end == "terminal", truncated=last and end == "truncated")
    return out


def test_nstep_returns_in_the_middle_of_an_episode():
    acc = NStepAccumulator(3, 0.5)
    out = _collect(acc, [1.0, 2.0, 4.0, 8.0], end=None)
    assert len(out) == 2
    obs, _, ret, disc, nxt = out[0]
    assert obs[0] == 0 and ret == pytest.approx(1 + 0.5 * 2 + 0.25 * 4) and disc == pytest.approx(0.125) and nxt[0] == 3
    obs, _, ret, disc, nxt = out[1]
    assert obs[0] == 1 and ret == pytest.approx(2 + 0.5 * 4 + 0.25 * 8) and nxt[0] == 4


def test_nstep_terminal_has_no_bootstrap():
    acc = NStepAccumulator(3, 0.5)
    out = _collect(acc, [1.0, 2.0, 4.0, 8.0], end="terminal")
    assert len(out) == 4  # every remaining start is flushed at the end
    tail = out[2:]
    assert [t[0][0] for t in tail] == [2.0, 3.0]
    assert tail[0][2] == pytest.approx(4 + 0.5 * 8) and tail[0][3] == 0.0
    assert tail[1][2] == pytest.approx(8) and tail[1][3] == 0.0
    assert all(t[4][0] == 4.0 for t in tail)


def test_nstep_truncation_bootstraps_with_the_right_power():
    acc = NStepAccumulator(3, 0.5)
    out = _collect(acc, [1.0, 2.0, 4.0, 8.0], end="truncated")
    tail = out[2:]
    assert tail[0][3] == pytest.approx(0.25) and tail[1][3] == pytest.approx(0.5)  # gamma^k, k = 2, 1
    assert tail[0][2] == pytest.approx(4 + 0.5 * 8)


def test_replay_sampling_shapes_and_wraparound():
    buf = ReplayBuffer(10, 4, 2)
    for start in (0, 6):
        n = 6
        vals = np.arange(start, start + n, dtype=np.float32)
        buf.add_batch(np.repeat(vals[:, None], 4, 1), np.zeros((n, 2)), vals, np.ones(n), np.zeros((n, 4)))
    assert len(buf) == 10 and buf.cursor == 2
    batch = buf.sample(32, np.random.default_rng(0))
    assert batch["obs"].shape == (32, 4) and batch["action"].shape == (32, 2)
    assert batch["ret"].shape == (32,) and batch["next_obs"].dtype == torch.float32
    assert set(batch["ret"].tolist()) <= set(range(2, 12))  # 0 and 1 were overwritten
    state = buf.state_dict()
    assert state["ret"].tolist() == list(range(2, 12))  # oldest first
    other = ReplayBuffer(10, 4, 2)
    other.load_state_dict(state)
    np.testing.assert_array_equal(np.sort(other.ret), np.sort(buf.ret))


def test_replay_refuses_empty_sampling():
    with pytest.raises(ValueError, match="empty"):
        ReplayBuffer(4, 2, 2).sample(1, np.random.default_rng(0))


def test_curriculum_advances_on_threshold_and_on_budget():
    c = Curriculum(True, thresholds=(5.0, 5.0, 5.0), budget_fractions=(0.5, 0.5, 0.5), total_steps=1000, window=3)
    assert c.level == "straight"
    for ret in (6.0, 6.0):
        assert not c.record("straight", ret, 10)
    assert c.record("straight", 6.0, 20) and c.level == "circles"  # window full, mean 6 >= 5
    assert not c.record("circles", 0.0, 100)
    assert c.record("circles", 0.0, 520) and c.level == "smoothed"  # 500 steps = its budget
    assert c.history == [(0, "straight"), (20, "circles"), (520, "smoothed")]


def test_curriculum_advances_on_its_share_of_the_time_limit():
    c = Curriculum(True, (1e9, 1e9, 1e9), (0.1, 0.2, 0.3), total_steps=10**9, window=3, time_limit_s=100.0)
    assert not c.record("straight", 0.0, 10, wall_time=9.0)
    assert c.record("straight", 0.0, 20, wall_time=10.5) and c.level == "circles"
    assert not c.record("circles", 0.0, 30, wall_time=30.0)
    assert c.record("circles", 0.0, 40, wall_time=30.6) and c.level == "smoothed"  # 20 s after 10.5


def test_curriculum_ignores_returns_from_other_levels_and_without_curriculum_starts_at_the_end():
    c = Curriculum(True, (1.0, 1.0, 1.0), (1.0, 1.0, 1.0), 10**6, window=2)
    for _ in range(5):
        assert not c.record("circles", 100.0, 1)
    assert c.level == "straight"
    flat = Curriculum(False, (1.0, 1.0, 1.0), (1.0, 1.0, 1.0), 10**6)
    assert flat.level == "trajectories" and not flat.record("trajectories", 99.0, 10**7)


def test_curriculum_keeps_a_share_of_earlier_levels_for_explorers():
    c = Curriculum(True, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 100, window=1)
    c.record("straight", 1.0, 1)
    c.record("circles", 1.0, 2)  # now at smoothed
    rng = np.random.default_rng(0)
    picks = [c.pick_level(rng, exploring=True, earlier_share=0.2) for _ in range(2000)]
    share = sum(p != "smoothed" for p in picks) / len(picks)
    assert 0.15 < share < 0.25 and set(picks) == {"straight", "circles", "smoothed"}
    assert {c.pick_level(rng, exploring=False, earlier_share=0.2) for _ in range(100)} == {"smoothed"}


def test_policy_file_round_trip(tmp_path):
    actor = Actor(57, 2, (32, 32))
    save_policy(tmp_path / "p.pt", actor, "lbgp", "jackal", (32, 32), extra={"steps": 5})
    policy = load_policy(tmp_path / "p.pt", mirror_average=False)  # the actor's own answer
    obs = np.random.default_rng(0).uniform(-1, 1, 57).astype(np.float32)
    expected = actor(torch.from_numpy(obs)[None])[0].detach().numpy()
    np.testing.assert_allclose(policy.act(obs), expected, rtol=1e-6)
    assert policy.control == "goal" and policy.meta["extra"]["steps"] == 5
    with pytest.raises(ValueError, match="observation of shape"):
        policy.act(np.zeros(10))


def test_corrupt_and_foreign_policy_files_give_clear_errors(tmp_path):
    save_policy(tmp_path / "p.pt", Actor(57, 2, (8,)), "e2e", "jackal", (8,))
    data = (tmp_path / "p.pt").read_bytes()
    (tmp_path / "truncated.pt").write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="not a readable lbgp-policy file"):
        load_policy(tmp_path / "truncated.pt")
    torch.save({"format": "something-else"}, tmp_path / "foreign.pt")
    with pytest.raises(ValueError, match="not a lbgp-policy file"):
        load_policy(tmp_path / "foreign.pt")
    blob = torch.load(tmp_path / "p.pt", weights_only=True)
    blob["hidden"] = [16]
    torch.save(blob, tmp_path / "mismatch.pt")
    with pytest.raises(ValueError, match="do not match"):
        load_policy(tmp_path / "mismatch.pt")
    with pytest.raises(FileNotFoundError):
        load_policy(tmp_path / "missing.pt")


def test_config_validation():
    with pytest.raises(ValueError, match="method"):
        D4PGConfig(method="ppo").validate()
    with pytest.raises(ValueError, match="unknown training config keys"):
        D4PGConfig.from_dict({"learning_rate": 1})


def _actor_steps(method, prior_weight, steps=50):
    """Train only the actor against a critic that is indifferent to the action (all-zero weights:
    uniform atoms, Q = 0 everywhere): only the goal prior can move the actions."""
    from lbgp.agent.learner import D4PGLearner
    from lbgp.sim import observation as obs_lib

    torch.manual_seed(0)
    # the paper's plain actor: the residual form starts at the prior exactly (tests/test_goal_policy.py)
    learner = D4PGLearner(D4PGConfig.paper(method=method, prior_weight=prior_weight, actor_lr=1e-2), obs_lib.SIZE, 2)
    with torch.no_grad():
        for p in learner.critic.parameters():
            p.zero_()
    obs = torch.rand(64, obs_lib.SIZE) * 2 - 1
    before = learner.actor(obs).detach()
    for _ in range(steps):
        loss, _ = learner.actor_loss(obs)
        learner.actor_opt.zero_grad()
        loss.backward()
        learner.actor_opt.step()
    return before, learner.actor(obs).detach(), learner.prior


def test_goal_prior_pulls_lbgp_actions_to_the_goal_ahead_and_nothing_else_moves_them():
    from lbgp.actions import goal_from_action

    before, after, prior = _actor_steps("lbgp", 1.0)
    assert np.allclose(goal_from_action(prior.numpy()), [1.5, 0.0])
    gap_before = (before - prior).norm(dim=1).mean()
    gap_after = (after - prior).norm(dim=1).mean()
    assert gap_after < 0.2 * gap_before
    # no prior (plain D4PG) or E2E (wheel commands have no prior): an indifferent critic leaves the actor be
    for method, weight in (("lbgp", 0.0), ("e2e", 1.0)):
        before, after, _ = _actor_steps(method, weight)
        assert torch.allclose(before, after)


def test_negative_prior_weight_is_refused():
    with pytest.raises(ValueError, match="prior_weight"):
        D4PGConfig(prior_weight=-1.0).validate()
