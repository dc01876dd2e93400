"""LBGP's redesigned goal policy: residual actor around the goal ahead, input standardisation,
correlated exploration, front-weighted spawns, actor warm-up, and old policy files still loading."""

import math

import numpy as np
import pytest
import torch

from lbgp.actions import DESIRED_GOAL, action_from_goal, goal_from_action
from lbgp.agent.actors import ExplorationNoise
from lbgp.agent.config import D4PGConfig
from lbgp.agent.learner import D4PGLearner, make_actor
from lbgp.agent.networks import MIN_OBS_STD, Actor
from lbgp.agent.policy import GOAL_DEADBAND_M, load_policy, save_policy
from lbgp.sim import make_env
from lbgp.sim import observation as obs_lib


def test_untrained_residual_actor_gives_exactly_the_goal_ahead_and_its_range_is_bounded():
    torch.manual_seed(0)
    actor = make_actor(D4PGConfig(), obs_lib.SIZE, 2)
    obs = torch.rand(32, obs_lib.SIZE) * 2 - 1
    with torch.no_grad():
        goals = np.array([goal_from_action(a) for a in actor(obs).numpy()])
    assert np.allclose(goals, DESIRED_GOAL, atol=1e-6)
    with torch.no_grad():  # saturate the residual: goals stay within +-0.75 m of the goal ahead
        actor.net[-1].bias.fill_(100.0)
        far = goal_from_action(actor(obs[:1])[0].numpy())
    assert np.allclose(far, np.asarray(DESIRED_GOAL) + 0.75, atol=1e-4)


def test_paper_preset_is_the_plain_actor_and_e2e_is_never_residual():
    assert make_actor(D4PGConfig.paper(), obs_lib.SIZE, 2).residual_scale == 0.0
    assert make_actor(D4PGConfig(method="e2e"), obs_lib.SIZE, 2).residual_scale == 0.0
    cfg = D4PGConfig.paper()
    assert (cfg.sigma, cfg.noise_correlation, cfg.spawn_front_share, cfg.prior_weight, cfg.normalize_obs) == (0.3, 0.0, 0.5, 0.0, False)


def test_learner_sets_input_standardisation_once_for_all_four_networks():
    learner = D4PGLearner(D4PGConfig(hidden=(16, 16)), obs_lib.SIZE, 2)
    assert not learner.obs_stats_set
    obs = np.random.default_rng(0).normal(0.3, 0.2, (500, obs_lib.SIZE)).astype(np.float32)
    obs[:, 5] = 0.1  # a constant dimension: its std is floored, not zero
    learner.set_obs_stats(obs)
    for net in (learner.actor, learner.target_actor, learner.critic, learner.target_critic):
        assert torch.allclose(net.norm.obs_mean, torch.from_numpy(obs.mean(0)), atol=1e-5)
        assert float(net.norm.obs_std[5]) == pytest.approx(MIN_OBS_STD)
        assert float(net.norm.obs_std[0]) == pytest.approx(0.2, rel=0.15)
    assert learner.obs_stats_set and bool(learner.state_dict()["obs_stats_set"])


def test_actor_stays_fixed_during_warmup_then_learns():
    torch.manual_seed(0)
    learner = D4PGLearner(D4PGConfig(hidden=(16, 16), actor_warmup_updates=3, batch_size=8), obs_lib.SIZE, 2)
    rng = np.random.default_rng(0)
    batch = {"obs": torch.rand(8, obs_lib.SIZE), "action": torch.rand(8, 2), "ret": torch.rand(8),
             "discount": torch.full((8,), 0.9), "next_obs": torch.rand(8, obs_lib.SIZE)}
    first = [p.clone() for p in learner.actor.parameters()]
    for _ in range(3):
        learner.update(batch)
    assert all(torch.equal(a, b) for a, b in zip(first, learner.actor.parameters()))
    for _ in range(3):
        learner.update(batch)
    assert not all(torch.equal(a, b) for a, b in zip(first, learner.actor.parameters()))
    del rng


def test_correlated_exploration_noise_keeps_sigma_and_is_correlated():
    rng = np.random.default_rng(0)
    noise = ExplorationNoise(0.2, 0.8, rng)
    x = np.array([noise.sample() for _ in range(20000)])
    assert np.std(x) == pytest.approx(0.2, rel=0.05)
    lag1 = np.corrcoef(x[:-1, 0], x[1:, 0])[0, 1]
    assert lag1 == pytest.approx(0.8, abs=0.03)
    white = np.array([ExplorationNoise(0.2, 0.0, rng).sample() for _ in range(2000)])
    assert abs(np.corrcoef(white[:-1, 0], white[1:, 0])[0, 1]) < 0.1


@pytest.mark.parametrize("share, expected", [(0.5, 0.5), (0.9, 0.9), (1.0, 1.0)])
def test_training_spawns_in_front_with_the_configured_share(share, expected):
    env = make_env("straight", seed=3, spawn_front_share=share)
    front = []
    for _ in range(120):
        env.reset()
        alpha = env.info()["alpha"]
        front.append(abs(alpha) < math.pi / 2)
    assert np.mean(front) == pytest.approx(expected, abs=0.1)


def test_version_1_policy_files_load_as_plain_actors(tmp_path):
    torch.manual_seed(0)
    actor = Actor(obs_lib.SIZE, 2, (8,))
    save_policy(tmp_path / "p.pt", actor, "lbgp", "jackal", (8,))
    data = torch.load(tmp_path / "p.pt", weights_only=True)
    data["version"] = 1
    data.pop("residual_scale")
    data["actor"] = {k: v for k, v in data["actor"].items() if not k.startswith("norm.") and k != "base"}
    torch.save(data, tmp_path / "v1.pt")
    obs = np.random.default_rng(0).uniform(-1, 1, obs_lib.SIZE).astype(np.float32)
    assert np.allclose(load_policy(tmp_path / "v1.pt").act(obs), load_policy(tmp_path / "p.pt").act(obs))


def test_residual_policy_file_round_trips(tmp_path):
    torch.manual_seed(0)
    actor = make_actor(D4PGConfig(hidden=(8,)), obs_lib.SIZE, 2)
    with torch.no_grad():
        actor.net[-1].bias.fill_(0.3)
        actor.set_obs_stats(torch.full((obs_lib.SIZE,), 0.1), torch.full((obs_lib.SIZE,), 0.5))
    save_policy(tmp_path / "r.pt", actor, "lbgp", "jackal", (8,), residual_scale=actor.residual_scale)
    obs = np.random.default_rng(1).uniform(-1, 1, obs_lib.SIZE).astype(np.float32)
    expected = actor(torch.from_numpy(obs)[None])[0].detach().numpy()
    assert np.allclose(load_policy(tmp_path / "r.pt", goal_deadband=0.0, mirror_average=False).act(obs), expected, atol=1e-6)
    assert not np.allclose(expected, action_from_goal(DESIRED_GOAL))


def _residual_policy_file(tmp_path, bias_x: float, bias_y: float):
    torch.manual_seed(0)
    actor = make_actor(D4PGConfig(hidden=(8,)), obs_lib.SIZE, 2)
    with torch.no_grad():  # a constant residual whatever the observation
        actor.net[-1].weight.zero_()
        actor.net[-1].bias.copy_(torch.tensor([bias_x, bias_y]))
    save_policy(tmp_path / "r.pt", actor, "lbgp", "jackal", (8,), residual_scale=actor.residual_scale)
    return tmp_path / "r.pt"


def test_goal_dead_band_shrinks_the_residual_goal_toward_the_goal_ahead(tmp_path):
    obs = np.zeros(obs_lib.SIZE, np.float32)
    ahead = np.asarray(DESIRED_GOAL)
    # residual 0.75 m * tanh(b): b = atanh(0.08 / 0.75) gives 8 cm straight to the left
    small = _residual_policy_file(tmp_path, 0.0, math.atanh(0.08 / 0.75))
    assert np.allclose(goal_from_action(load_policy(small, goal_deadband=0.0, mirror_average=False).act(obs)), ahead + [0.0, 0.08], atol=1e-5)
    assert np.allclose(goal_from_action(load_policy(small, goal_deadband=0.1, mirror_average=False).act(obs)), ahead, atol=1e-6)
    # a 0.3 m, 0.4 m residual (length 0.5 m) keeps its direction and loses 0.1 m of its length
    big = _residual_policy_file(tmp_path, math.atanh(0.3 / 0.75), math.atanh(0.4 / 0.75))
    assert np.allclose(goal_from_action(load_policy(big, goal_deadband=0.1, mirror_average=False).act(obs)), ahead + [0.24, 0.32], atol=1e-5)
    # the defaults: GOAL_DEADBAND_M, mirror averaged (a residual to the left whatever the observation
    # cancels against its mirror image, to the right: 0.3 m straight ahead is left, less the band)
    assert np.allclose(goal_from_action(load_policy(big).act(obs)), ahead + [0.3 - GOAL_DEADBAND_M, 0.0], atol=1e-5)
    with pytest.raises(ValueError, match="goal_deadband"):
        load_policy(big, goal_deadband=float("nan"))
    with pytest.raises(ValueError, match="goal_deadband"):
        load_policy(big, goal_deadband=-0.1)


def test_goal_dead_band_leaves_plain_actors_and_e2e_alone(tmp_path):
    torch.manual_seed(0)
    obs = np.random.default_rng(2).uniform(-1, 1, obs_lib.SIZE).astype(np.float32)
    for method in ("lbgp", "e2e"):  # plain tanh actors: no base goal to shrink toward
        actor = Actor(obs_lib.SIZE, 2, (8,))
        with torch.no_grad():
            actor.net[-1].bias.fill_(0.05)
        save_policy(tmp_path / f"{method}.pt", actor, method, "jackal", (8,))
        policy = load_policy(tmp_path / f"{method}.pt", goal_deadband=0.5, mirror_average=False)
        assert policy.goal_deadband == 0.0
        assert np.allclose(policy.act(obs), actor(torch.from_numpy(obs)[None])[0].detach().numpy(), atol=1e-6)


def test_mirror_averaged_acting_is_exactly_mirror_equivariant_for_every_kind_of_policy(tmp_path):
    """The default acting: a world and its mirror image get mirrored actions, whatever the actor
    learned, and the action is the mean of the actor's answer and its mirrored answer to the mirror
    image; ``mirror_average=False`` is the actor's own answer."""
    from lbgp.actions import mirror_action

    rng = np.random.default_rng(4)
    obs = rng.uniform(-1, 1, (5, obs_lib.SIZE)).astype(np.float32)
    for method, residual in (("lbgp", 0.75), ("lbgp", 0.0), ("e2e", 0.0)):
        torch.manual_seed(1)
        actor = Actor(obs_lib.SIZE, 2, (16,), residual_scale=residual, base=action_from_goal(DESIRED_GOAL) if residual else None)
        with torch.no_grad():
            for p in actor.net.parameters():
                p.add_(0.3 * torch.randn_like(p))  # an asymmetric actor (the residual one starts at zero)
        save_policy(tmp_path / "p.pt", actor, method, "jackal", (16,), residual_scale=residual)
        averaged = load_policy(tmp_path / "p.pt", goal_deadband=0.0)
        raw = load_policy(tmp_path / "p.pt", goal_deadband=0.0, mirror_average=False)
        assert averaged.mirror_average and not raw.mirror_average
        for o in obs:
            own, of_mirror = raw.act(o), raw.act(obs_lib.mirror(o))
            assert np.abs(own - mirror_action(of_mirror)).max() > 1e-3  # the actor itself is not symmetric
            np.testing.assert_allclose(averaged.act(o), 0.5 * (own + mirror_action(of_mirror)), atol=1e-6)
            np.testing.assert_allclose(averaged.act(obs_lib.mirror(o)), mirror_action(averaged.act(o)), atol=1e-6)
            np.testing.assert_allclose(raw.act(o), actor(torch.from_numpy(o)[None])[0].detach().numpy(), atol=1e-6)


def _turning_observation(turn_rate: float, speed: float = 0.8) -> np.ndarray:
    """The noise-free observation of a person walking an arc at ``turn_rate`` with the robot 1.5 m ahead."""
    stack = obs_lib.ObservationStack()
    x = y = th = 0.0
    for k in range(obs_lib.FRAMES + 2):
        person = np.array([x, y, th])
        robot = person + [1.5 * math.cos(th), 1.5 * math.sin(th), 0.0]
        stack.reset(robot, person) if k == 0 else stack.push(robot, person)
        x, y = x + speed * obs_lib.FRAME_PERIOD * math.cos(th), y + speed * obs_lib.FRAME_PERIOD * math.sin(th)
        th += turn_rate * obs_lib.FRAME_PERIOD
    return stack.vector()


@pytest.mark.parametrize("turn_rate", [-0.6, -0.3, 0.0, 0.25, 0.5])
def test_turn_rate_estimate_reads_the_persons_turn_from_the_observation(turn_rate):
    obs = _turning_observation(turn_rate)
    w = obs_lib.turn_rate_weights()
    assert float(obs @ w) == pytest.approx(turn_rate, abs=1e-5)
    assert float(obs_lib.mirror(obs) @ w) == pytest.approx(-turn_rate, abs=1e-5)
    assert float(torch.from_numpy(obs) @ torch.from_numpy(w)) == pytest.approx(turn_rate, abs=1e-5)
    with pytest.raises(ValueError, match="past frames"):
        obs_lib.turn_rate_weights(obs_lib.FRAMES)


def test_turn_aware_base_moves_the_goal_ahead_by_the_lead_times_the_turn_rate(tmp_path):
    """An untrained actor with ``turn_lead`` gives the goal 1.5 m + lead * |turn rate| ahead, the same
    for either turn direction; the goal prior pulls toward that base (zero for the untrained actor),
    and a policy file keeps the lead (its dead band shrinks toward the observation's own base)."""
    cfg = D4PGConfig(hidden=(8,), turn_lead=0.4)
    actor = make_actor(cfg, obs_lib.SIZE, 2)
    obs = torch.from_numpy(np.stack([_turning_observation(w) for w in (0.0, 0.3, -0.3, 0.5)]))
    with torch.no_grad():
        goals = np.array([goal_from_action(a) for a in actor(obs).numpy()])
    assert np.allclose(goals, [[1.5, 0.0], [1.62, 0.0], [1.62, 0.0], [1.7, 0.0]], atol=1e-4)
    assert np.allclose(make_actor(D4PGConfig(hidden=(8,)), obs_lib.SIZE, 2)(obs).detach().numpy(),
                       action_from_goal(DESIRED_GOAL), atol=1e-6)  # no lead: the goal ahead whatever the turn

    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    with torch.no_grad():  # a residual 0.12 m short of the base for every observation: 0.06 in action units
        learner.actor.net[-1].bias.copy_(torch.tensor([math.atanh(-0.12 / 0.75), 0.0]))
        loss, q = learner.actor_loss(obs)
    # the prior is measured from each observation's own base (from the goal 1.5 m ahead, the
    # turning observations' goals would be 0, 0 and 0.08 m off instead)
    assert float(loss + q.mean()) == pytest.approx(0.06 ** 2, abs=1e-6)

    with torch.no_grad():  # a residual 0.05 m ahead, inside the dead band, whatever the observation
        actor.net[-1].bias.copy_(torch.tensor([math.atanh(0.05 / 0.75), 0.0]))
    save_policy(tmp_path / "t.pt", actor, "lbgp", "jackal", (8,), residual_scale=actor.residual_scale)
    policy = load_policy(tmp_path / "t.pt")
    assert policy.actor.turn_lead == pytest.approx(0.4)
    acted = np.array([goal_from_action(policy.act(o)) for o in obs.numpy()])
    assert np.allclose(acted, [[1.5, 0.0], [1.62, 0.0], [1.62, 0.0], [1.7, 0.0]], atol=1e-4)
    raw = np.array([goal_from_action(load_policy(tmp_path / "t.pt", goal_deadband=0.0).act(o)) for o in obs.numpy()])
    assert np.allclose(raw - acted, [[0.05, 0.0]] * 4, atol=1e-4)


def test_turn_lead_needs_a_residual_actor():
    with pytest.raises(ValueError, match="turn_lead"):
        D4PGConfig.paper(turn_lead=0.4).validate()
    with pytest.raises(ValueError, match="turn_lead"):
        D4PGConfig(turn_lead=-0.1).validate()
    with pytest.raises(ValueError, match="turn_lead"):
        Actor(obs_lib.SIZE, 2, (8,), turn_lead=0.4)
    assert make_actor(D4PGConfig(method="e2e", turn_lead=0.4), obs_lib.SIZE, 2).turn_lead == 0.0


@pytest.mark.parametrize("turn_rate", [-0.4, 0.0, 0.3])
def test_motion_features_read_the_persons_and_the_robots_motion_off_the_observation(turn_rate):
    """The person walks at 0.8 m/s on an arc with the robot held 1.5 m ahead: the features give the
    person's speed ahead, their turn rate, and the robot's ground velocity in the person frame (the
    person's plus the swing of the 1.5 m lever, 1.5 * turn rate to the left), all exact on a
    straight walk; the mirror image negates the lateral velocities and the turn rate. On an arc the
    estimates lag the turn: the displacements they difference were walked up to two frames ago, on
    headings up to 2 * turn rate * FRAME_PERIOD behind (hence the tolerance)."""
    obs = _turning_observation(turn_rate, speed=0.8)
    person_vx, person_vy, turn, robot_vx, robot_vy = obs @ obs_lib.motion_feature_weights()
    tol = 1e-5 if turn_rate == 0 else 0.8 * abs(turn_rate) * 2 * obs_lib.FRAME_PERIOD
    assert person_vx == pytest.approx(0.8, abs=tol) and person_vy == pytest.approx(0.0, abs=tol)
    assert turn == pytest.approx(turn_rate, abs=1e-5)
    assert robot_vx == pytest.approx(0.8, abs=tol) and robot_vy == pytest.approx(1.5 * turn_rate, abs=tol)
    mirrored = obs_lib.mirror(obs) @ obs_lib.motion_feature_weights()
    assert np.allclose(mirrored, [person_vx, -person_vy, -turn, robot_vx, -robot_vy], atol=1e-6)


def test_motion_feature_networks_standardise_the_features_and_round_trip_through_a_policy_file(tmp_path):
    cfg = D4PGConfig(hidden=(8,), motion_features=True)
    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    obs = np.stack([_turning_observation(w, speed=s) for w in (-0.4, 0.0, 0.3) for s in (0.4, 0.8)]).astype(np.float32)
    learner.set_obs_stats(obs)
    inputs = np.concatenate([obs, obs @ obs_lib.motion_feature_weights()], axis=1)
    for net in (learner.actor, learner.target_actor, learner.critic, learner.target_critic):
        assert net.norm.obs_mean.shape == (obs_lib.SIZE + len(obs_lib.MOTION_FEATURES),)
        assert torch.allclose(net.norm.obs_mean, torch.from_numpy(inputs.mean(0)), atol=1e-5)
    assert learner.critic(torch.from_numpy(obs), torch.zeros(len(obs), 2)).shape == (len(obs), cfg.num_atoms)
    actor = learner.actor
    with torch.no_grad():
        actor.net[-1].weight.normal_(0.0, 0.3)
    save_policy(tmp_path / "m.pt", actor, "lbgp", "jackal", (8,), residual_scale=actor.residual_scale)
    policy = load_policy(tmp_path / "m.pt", goal_deadband=0.0, mirror_average=False)
    assert policy.actor.inputs.motion_features
    expected = actor(torch.from_numpy(obs)).detach().numpy()
    assert np.allclose([policy.act(o) for o in obs], expected, atol=1e-6)
    with pytest.raises(ValueError, match="motion_features"):
        Actor(obs_lib.SIZE - 3, 2, (8,), motion_features=True)
    assert not make_actor(D4PGConfig(hidden=(8,)), obs_lib.SIZE, 2).inputs.motion_features
