"""benchmarks/critic_guided_acting.py: acting with the critic's best goal near the actor's."""

import dataclasses
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from ablation_scenarios import scenario_seed  # noqa: E402
from critic_guided_acting import GRID, CriticGuidedPolicy, load_critic, main  # noqa: E402

from lbgp.actions import mirror_action  # noqa: E402
from lbgp.agent.checkpoint import save_atomic  # noqa: E402
from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.learner import D4PGLearner  # noqa: E402
from lbgp.agent.policy import load_policy, save_policy  # noqa: E402
from lbgp.agent.train import CHECKPOINT_FORMAT  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import default_policy_path, make_policy  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402

SHIPPED = str(default_policy_path("lbgp"))


def write_checkpoint(path: Path, cfg: D4PGConfig, learner: D4PGLearner) -> None:
    """The parts of a training checkpoint that load_critic reads, written as training writes them."""
    save_atomic({"format": CHECKPOINT_FORMAT, "version": 1, "config": dataclasses.asdict(cfg),
                 "learner": learner.state_dict()}, path)


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
    write_checkpoint(tmp_path / "checkpoint.pt", cfg, learner)
    critic = load_critic(tmp_path)
    obs = torch.as_tensor(np.stack(noisy_observations("turning_inside", 1, 3)), dtype=torch.float32)
    actions = torch.tensor([[0.2, 0.1], [-0.3, 0.5], [0.0, 0.0]])
    with torch.no_grad():
        torch.testing.assert_close(critic.q_value(obs, actions), learner.critic.q_value(obs, actions))
    # a run whose critic reads hindsight features is refused with its reason
    future = D4PGConfig(method="lbgp", robot="jackal", critic_future=True)
    write_checkpoint(tmp_path / "checkpoint.pt", future, D4PGLearner(future, obs_lib.SIZE, 2))
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


def write_untrained_run(folder: Path, seed: int) -> None:
    """A run folder as training leaves it: checkpoint.pt and policy.pt, its actor and critic randomly
    perturbed (an untrained actor sends its base goal whatever the noise: the episodes would not tell)."""
    torch.manual_seed(seed)
    cfg = D4PGConfig(method="lbgp", robot="jackal")
    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    with torch.no_grad():
        for p in [*learner.critic.parameters(), *learner.policy_actor.parameters()]:
            p.add_(0.3 * torch.randn_like(p))
    folder.mkdir(parents=True)
    write_checkpoint(folder / "checkpoint.pt", cfg, learner)
    save_policy(folder / "policy.pt", learner.policy_actor, "lbgp", "jackal", cfg.hidden,
                residual_scale=cfg.actor_residual_scale)


def test_main_pairs_every_run_with_its_own_plain_policy_on_the_sim_tables_episodes(tmp_path):
    for i in range(2):
        write_untrained_run(tmp_path / "runs" / f"r_s{i}", seed=i)
    out = tmp_path / "guided.json"
    result = main(["--runs", str(tmp_path / "runs"), "--radii", "0.2", "--scenarios", "turning_inside",
                   "--episodes", "1", "--json", str(out)])
    assert json.loads(out.read_text())["guided_minus_plain"] == result["guided_minus_plain"]
    scored = result["runs"]
    assert set(scored) == {"r_s0", "r_s1", "r_s0@critic0.2", "r_s1@critic0.2"}
    # the plain policy is scored on the sim table's episode of the scenario
    plain = evaluate(load_policy(tmp_path / "runs" / "r_s1" / "policy.pt"), "lbgp", ["turning_inside"], robot="jackal",
                     episodes=1, seed=scenario_seed(0, "turning_inside"), obs_noise=True)[0]["reward"]
    assert scored["r_s1"]["sum"] == pytest.approx(plain, abs=1e-3)
    diffs = [scored[f"r_s{i}@critic0.2"]["sum"] - scored[f"r_s{i}"]["sum"] for i in range(2)]
    assert result["guided_minus_plain"]["0.2"]["per_seed"] == pytest.approx(diffs, abs=2e-3)
    assert any(abs(d) > 1e-3 for d in diffs)  # the critic's picks changed what the robot did


def test_main_refuses_grid_widths_outside_the_action_range(tmp_path, capsys):
    for radii in ("0", "1.5", "-0.1"):
        with pytest.raises(SystemExit) as stop:
            main(["--runs", str(tmp_path), "--radii", radii, "--json", str(tmp_path / "x.json")])
        assert stop.value.code == 2 and "--radii" in capsys.readouterr().err  # a usage error, before looking for runs
    assert not (tmp_path / "x.json").exists()
