"""The critic's hindsight of the next second (``lbgp train --set critic_future=true``): the features,
the actors appending them after an episode, the learner's actor reading the agent input only, and a
run whose policy file is an ordinary 57-input policy."""

import math

import numpy as np
import pytest
import torch

from lbgp.agent.actors import play_episode
from lbgp.agent.config import D4PGConfig
from lbgp.agent.critic_future import SIZE, STEPS, continue_path, hindsight_features
from lbgp.agent.learner import D4PGLearner, make_actor
from lbgp.agent.nstep import NStepAccumulator
from lbgp.agent.policy import load_policy
from lbgp.agent.train import Trainer
from lbgp.geometry import from_frame, integrate_unicycle
from lbgp.sim import make_env
from lbgp.sim import observation as obs_lib

WIDE = obs_lib.SIZE + SIZE  # the observation, then the hindsight features


def _circle(v: float, w: float, n: int, start=(1.0, -2.0, 0.3)) -> np.ndarray:
    return np.array([integrate_unicycle(np.array(start), v, w, 0.2 * k) for k in range(n)])


def test_features_are_the_true_relative_robot_pose_and_the_persons_next_second():
    persons = _circle(0.5, 0.4, 8)
    ahead = np.array([[1.5, 0.2, 0.1]])
    robots = np.concatenate([from_frame(ahead, p) for p in persons])
    feats = hindsight_features(robots, persons)
    assert feats.shape == (8, SIZE) and feats.dtype == np.float32
    assert np.allclose(feats[:, :3], obs_lib.scale(ahead), atol=1e-6)  # the robot, noise-free, in the person's frame
    # on a circle every step looks the same from the person: k steps on = the arc of 0.2 k s,
    # also past the episode's end, where the path is continued at its last twist
    arc = np.array([integrate_unicycle(np.zeros(3), 0.5, 0.4, 0.2 * k) for k in range(1, STEPS + 1)])
    for t in range(8):
        assert np.allclose(feats[t, 3:], obs_lib.scale(arc), atol=1e-5), t
    assert not np.allclose(arc[:, 1], 0.0, atol=0.01)  # the turn shows


def test_the_continued_path_repeats_the_last_step_and_a_single_pose_stays():
    straight = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    assert np.allclose(continue_path(straight, 2)[2:], [[0.2, 0.0, 0.0], [0.3, 0.0, 0.0]])
    assert np.allclose(continue_path(np.array([[1.0, 2.0, math.pi / 2]]), 3), [[1.0, 2.0, math.pi / 2]] * 4)


def test_bad_poses_are_refused_by_name():
    with pytest.raises(ValueError, match="hindsight features need"):
        hindsight_features(np.zeros((3, 3)), np.zeros((4, 3)))
    bad = np.zeros((3, 3))
    bad[1, 0] = np.nan
    with pytest.raises(ValueError, match="not finite"):
        hindsight_features(np.zeros((3, 3)), bad)


def test_actors_append_the_features_after_the_episode_and_act_on_the_observation_alone():
    torch.manual_seed(0)
    cfg = D4PGConfig(hidden=(8,), n_step=1, critic_future=True)
    actor = make_actor(cfg, obs_lib.SIZE, 2)
    with torch.no_grad():
        actor.net[-1].weight.normal_(0.0, 0.5)  # actions that depend on the observation
    plain = D4PGConfig(hidden=(8,), n_step=1)
    runs = [play_episode(make_env("circles", robot="jackal", seed=3, horizon=6), actor, True, c, np.random.default_rng(1),
                         NStepAccumulator(1, c.discount)) for c in (cfg, plain)]
    (obs, action, ret, _, next_obs), total, steps = runs[0]
    assert steps == 6 and obs.shape == (6, WIDE) and next_obs.shape == (6, WIDE)
    # the same episode as without the features: the actor never saw them
    for got, want in zip(runs[0][0], runs[1][0]):
        assert np.array_equal(got[..., : want.shape[-1]] if got.ndim == 2 else got, want)
    assert np.array_equal(next_obs[:-1, obs_lib.SIZE:], obs[1:, obs_lib.SIZE:])  # one-step transitions chain
    # the robot part is the true pose, close to the noisy observation's newest robot frame
    assert np.allclose(obs[:, obs_lib.SIZE : obs_lib.SIZE + 3], obs[:, :3], atol=0.1)
    assert np.any(np.abs(obs[:, obs_lib.SIZE + 4 :: 3]) > 1e-3)  # the circling person's future turns left or right


def test_the_learners_actor_reads_the_agent_input_and_the_critic_the_features():
    cfg = D4PGConfig(hidden=(8,), batch_size=16, actor_warmup_updates=0, critic_future=True)
    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    assert learner.critic_inputs == WIDE and learner.critic.norm.obs_std.shape == (WIDE,) and learner.actor.norm.obs_std.shape == (obs_lib.SIZE,)
    rng = np.random.default_rng(0)
    stored = rng.uniform(-1, 1, (64, WIDE)).astype(np.float32)
    stored[:, obs_lib.SIZE:] *= 0.1
    learner.set_obs_stats(stored)
    assert torch.allclose(learner.critic.norm.obs_std[obs_lib.SIZE:], torch.from_numpy(stored[:, obs_lib.SIZE:].std(0, ddof=1)), atol=1e-5)
    assert torch.allclose(learner.actor.norm.obs_std, torch.from_numpy(stored[:, : obs_lib.SIZE].std(0, ddof=1)), atol=1e-5)
    batch = {"obs": torch.from_numpy(stored[:16]), "action": torch.zeros(16, 2), "ret": torch.ones(16),
             "discount": torch.full((16,), 0.9), "next_obs": torch.from_numpy(stored[16:32])}
    for _ in range(3):
        losses = learner.update(batch)
    assert all(np.isfinite(v) for v in losses.values())
    other = batch["obs"].clone()
    other[:, obs_lib.SIZE:] = 0.5
    action = learner.actor(batch["obs"][:, : obs_lib.SIZE])
    assert not torch.allclose(learner.critic(batch["obs"], action), learner.critic(other, action))  # the critic uses them


def test_the_setting_parses_and_mirror_augmentation_is_refused():
    assert D4PGConfig.parse_setting("critic_future=true") == ("critic_future", True)
    with pytest.raises(ValueError, match="critic_future and mirror_augment"):
        D4PGConfig(critic_future=True, mirror_augment=True).validate()


def test_a_run_with_the_hindsight_critic_writes_an_ordinary_policy(tmp_path):
    cfg = D4PGConfig(total_steps=100, min_replay=40, horizon=10, hidden=(16,), batch_size=16, actor_warmup_updates=0,
                     seed=1, critic_future=True)
    trainer = Trainer(cfg, tmp_path / "run", backend="inline", progress=False)
    summary = trainer.run()
    assert summary["learner_updates"] > 0 and trainer.replay.obs.shape[1] == WIDE
    assert np.any(trainer.replay.obs[: len(trainer.replay), obs_lib.SIZE:] != 0)
    policy = load_policy(tmp_path / "run" / "policy.pt")
    assert policy.actor.obs_size == obs_lib.SIZE
    assert np.all(np.isfinite(policy.act(np.zeros(obs_lib.SIZE, np.float32))))
