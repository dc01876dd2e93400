"""The previous goal as an input (``lbgp train --previous-goal``): agent inputs and their mirror
image, the actors feeding back the action they sent, the replay and learner at 59 inputs, and a
policy file that carries its last action between steps and forgets it on reset."""

import numpy as np
import pytest
import torch

from lbgp.actions import mirror_action
from lbgp.agent.actors import play_episode
from lbgp.agent.config import D4PGConfig
from lbgp.agent.learner import D4PGLearner, make_actor
from lbgp.agent.nstep import NStepAccumulator
from lbgp.agent.policy import load_policy, save_policy
from lbgp.agent.previous_goal import agent_input, agent_input_size, mirror_input
from lbgp.agent.replay import mirrored
from lbgp.sim import make_env
from lbgp.sim import observation as obs_lib

SIZE = agent_input_size(True)


def _random_actor(cfg: D4PGConfig, seed: int = 0):
    """An actor of ``cfg`` whose output depends on every input, the previous action included."""
    torch.manual_seed(seed)
    actor = make_actor(cfg, agent_input_size(cfg.previous_goal), 2)
    with torch.no_grad():
        actor.net[-1].weight.normal_(0.0, 0.5)
        actor.net[0].weight[:, obs_lib.SIZE:].normal_(0.0, 3.0)  # the previous action matters
    return actor


def test_agent_input_appends_the_previous_action_and_mirrors_it_as_an_action():
    rng = np.random.default_rng(0)
    obs = rng.uniform(-1, 1, (4, obs_lib.SIZE)).astype(np.float32)
    prev = rng.uniform(-1, 1, (4, 2)).astype(np.float32)
    x = agent_input(obs, prev)
    assert x.shape == (4, SIZE) and np.array_equal(x[:, : obs_lib.SIZE], obs) and np.array_equal(x[:, obs_lib.SIZE:], prev)
    expected = np.stack([agent_input(obs_lib.mirror(o), mirror_action(p)) for o, p in zip(obs, prev)])
    assert np.allclose(mirror_input(x), expected)
    assert np.allclose(mirror_input(mirror_input(x[0])), x[0])
    assert np.array_equal(mirror_input(obs), obs_lib.mirror(obs))  # no previous action: the observation's mirror
    with pytest.raises(ValueError, match="agent input"):
        agent_input(obs[0], prev)
    with pytest.raises(ValueError, match="agent inputs have"):
        mirror_input(x[:, :-1])


def test_actors_feed_back_the_action_they_sent_one_step_before():
    cfg = D4PGConfig(hidden=(8,), previous_goal=True, n_step=3)
    actor = _random_actor(cfg)
    env = make_env("circles", robot="jackal", seed=1, horizon=7)
    (obs, action, _, _, next_obs), _, steps = play_episode(env, actor, True, cfg, np.random.default_rng(0), NStepAccumulator(3, cfg.discount))
    assert steps == 7 and obs.shape == (7, SIZE) and next_obs.shape == (7, SIZE)
    assert np.array_equal(obs[0, obs_lib.SIZE:], actor.base.numpy())  # the goal ahead at the first step
    assert np.array_equal(obs[1:, obs_lib.SIZE:], action[:-1])  # then the (noisy) action just sent
    assert np.std(action[:, 1]) > 0.01  # exploring: the fed-back actions really differ
    for k in range(7):  # an n-step transition bootstraps from the input n steps on (or the last one)
        assert np.array_equal(next_obs[k, obs_lib.SIZE:], action[min(k + 3, 7) - 1])
    mirror_obs, mirror_act, *_ = mirrored((obs, action, np.zeros(7), np.zeros(7), next_obs))
    assert np.allclose(mirror_obs[1:, obs_lib.SIZE:], mirror_act[:-1])  # mirrored transitions stay consistent


def test_learner_standardises_and_updates_on_59_inputs():
    cfg = D4PGConfig(hidden=(8,), previous_goal=True, batch_size=16, actor_warmup_updates=0)
    learner = D4PGLearner(cfg, SIZE, 2)
    rng = np.random.default_rng(0)
    obs = rng.uniform(-1, 1, (64, SIZE)).astype(np.float32)
    obs[:, obs_lib.SIZE:] *= 0.2
    learner.set_obs_stats(obs)
    for net in (learner.actor, learner.target_actor, learner.critic, learner.target_critic):
        assert torch.allclose(net.norm.obs_std[obs_lib.SIZE:], torch.from_numpy(obs[:, obs_lib.SIZE:].std(0, ddof=1)), atol=1e-5)
    batch = {"obs": torch.from_numpy(obs[:16]), "action": torch.zeros(16, 2), "ret": torch.ones(16),
             "discount": torch.full((16,), 0.9), "next_obs": torch.from_numpy(obs[16:32])}
    before = learner.actor(batch["obs"]).detach()
    losses = learner.update(batch)
    assert all(np.isfinite(v) for v in losses.values())
    assert not torch.equal(before, learner.actor(batch["obs"]).detach())


def test_a_policy_file_carries_its_last_action_and_forgets_it_on_reset(tmp_path):
    cfg = D4PGConfig(hidden=(8,), previous_goal=True)
    actor = _random_actor(cfg)
    save_policy(tmp_path / "p.pt", actor, "lbgp", "jackal", (8,), residual_scale=actor.residual_scale)
    data = torch.load(tmp_path / "p.pt", weights_only=True)
    assert data["version"] >= 5 and data["previous_goal"] is True and data["obs_size"] == obs_lib.SIZE
    policy = load_policy(tmp_path / "p.pt", goal_deadband=0.0, mirror_average=False)
    assert policy.previous_goal
    rng = np.random.default_rng(1)
    observations = rng.uniform(-1, 1, (3, obs_lib.SIZE)).astype(np.float32)
    expected, prev = [], actor.base.numpy()
    with torch.no_grad():
        for o in observations:
            prev = actor(torch.from_numpy(agent_input(o, prev))[None])[0].numpy()
            expected.append(prev)
    acted = [policy.act(o) for o in observations]
    assert np.allclose(acted, expected, atol=1e-6)
    assert not np.allclose(acted[1], policy.act(observations[1]), atol=1e-3)  # the same observation after other actions
    policy.reset()
    assert np.allclose(policy.act(observations[0]), expected[0], atol=1e-6)
    # mirror-averaged (the default), a mirrored run of observations gets the mirrored actions, step after step
    averaged = load_policy(tmp_path / "p.pt")
    own = [averaged.act(o) for o in observations]
    averaged.reset()
    of_mirror = [averaged.act(obs_lib.mirror(o)) for o in observations]
    assert np.allclose([mirror_action(a) for a in of_mirror], own, atol=1e-5)
    plain = make_actor(D4PGConfig(hidden=(8,)), obs_lib.SIZE, 2)
    save_policy(tmp_path / "q.pt", plain, "lbgp", "jackal", (8,), residual_scale=plain.residual_scale)
    assert not load_policy(tmp_path / "q.pt").previous_goal
