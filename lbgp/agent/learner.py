"""The D4PG learner: distributional critic, deterministic actor, n-step targets, target networks."""

from __future__ import annotations

import copy

import torch
import torch.nn.functional as F

from lbgp.actions import DESIRED_GOAL, action_from_goal
from lbgp.agent.config import D4PGConfig
from lbgp.agent.critic_future import SIZE as CRITIC_FUTURE_SIZE
from lbgp.agent.distributional import categorical_projection
from lbgp.agent.networks import Actor, DistributionalCritic


def make_actor(cfg: D4PGConfig, obs_size: int, action_size: int) -> Actor:
    """The actor a config asks for (the learner's and every actor process's); ``obs_size``: the agent
    input's (``lbgp.agent.previous_goal.agent_input_size``)."""
    base = action_from_goal(DESIRED_GOAL) if cfg.actor_residual_scale > 0 else None
    return Actor(obs_size, action_size, cfg.hidden, residual_scale=cfg.actor_residual_scale, base=base,
                 turn_lead=cfg.turn_lead if cfg.actor_residual_scale > 0 else 0.0, motion_features=cfg.motion_features)


@torch.no_grad()
def polyak_(average: torch.nn.Module, net: torch.nn.Module, tau: float) -> None:
    """Move ``average``'s parameters ``tau`` of the way toward ``net``'s (in place)."""
    torch._foreach_lerp_(list(average.parameters()), list(net.parameters()), tau)


class D4PGLearner:
    def __init__(self, cfg: D4PGConfig, obs_size: int, action_size: int):
        """``obs_size``: the agent input's (the actor's); with ``cfg.critic_future`` the replay's and
        the critic's inputs hold the hindsight features after it (``lbgp.agent.critic_future``)."""
        self.cfg = cfg
        self.actor_inputs = int(obs_size)  # the actor reads the first obs_size numbers of a stored input
        self.actor = make_actor(cfg, obs_size, action_size)
        # what the critic, and so the replay, holds per step: the agent input, then any hindsight features
        self.critic_inputs = self.actor_inputs + (CRITIC_FUTURE_SIZE if cfg.critic_future else 0)
        self.critic = DistributionalCritic(self.critic_inputs, action_size, cfg.num_atoms, cfg.v_min, cfg.v_max, cfg.hidden,
                                           motion_features=cfg.motion_features)
        self.target_actor = copy.deepcopy(self.actor).requires_grad_(False)
        self.target_critic = copy.deepcopy(self.critic).requires_grad_(False)
        # cfg.policy_average > 0: an exponential moving average of the actor's weights, for the policy file
        self.average_actor = copy.deepcopy(self.actor).requires_grad_(False) if cfg.policy_average > 0 else None
        self.actor_opt = torch.optim.Adam(self.actor.parameters(), lr=cfg.actor_lr, foreach=True)
        self.critic_opt = torch.optim.Adam(self.critic.parameters(), lr=cfg.critic_lr, foreach=True)
        self.updates = 0
        self.sample_losses = None  # each transition's critic loss in the last update's batch
        # LBGP's goal prior (cfg.prior_weight): a residual actor's base (the goal 1.5 m straight ahead
        # of the person, turn-aware with cfg.turn_lead), a plain actor's the goal ahead
        self.prior = torch.as_tensor(action_from_goal(DESIRED_GOAL), dtype=torch.float32)
        self.prior_weight = cfg.prior_weight if cfg.method == "lbgp" else 0.0
        self.obs_stats_set = not cfg.normalize_obs  # nothing to set when inputs are not standardised
        self.actor_stats_fixed = False  # the actors' standardisation came with them (lbgp.agent.fine_tune): keep it

    def set_obs_stats(self, observations) -> None:
        """Fix the input standardisation of all four networks from a sample of observations
        (called once, on the first replay contents, before the first update); with motion features
        the statistics are those of the networks' inputs, the features included."""
        with torch.no_grad():
            stored = torch.as_tensor(observations, dtype=torch.float32)
            actor_in = self.actor.inputs(stored[:, : self.actor_inputs])
            critic_in = self.critic.inputs(stored)
        for net in [] if self.actor_stats_fixed else self._actor_copies():
            net.set_obs_stats(actor_in.mean(0), actor_in.std(0))
        for net in (self.critic, self.target_critic):
            net.set_obs_stats(critic_in.mean(0), critic_in.std(0))
        self.obs_stats_set = True

    def _actor_copies(self) -> list[Actor]:
        """The actor, its target and (with cfg.policy_average) its weight average."""
        return [net for net in (self.actor, self.target_actor, self.average_actor) if net is not None]

    def start_actor_from(self, actor_state: dict) -> None:
        """Start the actor, its target and its average as a trained actor (``actor_state``, a state
        dict of the actor this config builds), keeping that actor's input standardisation:
        ``set_obs_stats`` then standardises the critic's inputs only (fine-tuning, lbgp.agent.fine_tune)."""
        for net in self._actor_copies():
            net.load_state_dict(actor_state)
        self.actor_stats_fixed = True

    def update(self, batch: dict[str, torch.Tensor], actor_batch: dict[str, torch.Tensor] | None = None) -> dict[str, float]:
        """One critic and (after the warm-up) one actor step. A prioritised batch carries importance
        ``weight``s for the critic's loss; ``actor_batch``: the actor's own batch (default: ``batch``).
        Each transition's critic loss is left in ``self.sample_losses`` (for new priorities)."""
        obs, action = batch["obs"], batch["action"]
        # critic: cross-entropy to the projected n-step target distribution
        with torch.no_grad():
            next_action = self.target_actor(batch["next_obs"][:, : self.actor_inputs])
            next_probs = torch.softmax(self.target_critic(batch["next_obs"], next_action), dim=-1)
            target = categorical_projection(next_probs, batch["ret"], batch["discount"], self.critic.atoms)
        logits = self.critic(obs, action)
        sample_losses = -(target * F.log_softmax(logits, dim=-1)).sum(-1)
        critic_loss = (sample_losses * batch["weight"]).mean() if "weight" in batch else sample_losses.mean()
        self.sample_losses = sample_losses.detach().numpy()
        self.critic_opt.zero_grad(set_to_none=True)
        critic_loss.backward()
        torch.nn.utils.clip_grad_norm_(self.critic.parameters(), self.cfg.grad_clip)
        self.critic_opt.step()

        actor_loss, q = self.actor_loss(obs if actor_batch is None else actor_batch["obs"])
        if self.updates >= self.cfg.actor_warmup_updates:
            self.actor_opt.zero_grad(set_to_none=True)
            actor_loss.backward()
            torch.nn.utils.clip_grad_norm_(self.actor.parameters(), self.cfg.grad_clip)
            self.actor_opt.step()
            if self.average_actor is not None:
                polyak_(self.average_actor, self.actor, self.cfg.policy_average)

        self.updates += 1
        if self.cfg.target_tau > 0:
            polyak_(self.target_actor, self.actor, self.cfg.target_tau)
            polyak_(self.target_critic, self.critic, self.cfg.target_tau)
        elif self.updates % self.cfg.target_update_period == 0:
            self.target_actor.load_state_dict(self.actor.state_dict())
            self.target_critic.load_state_dict(self.critic.state_dict())
        return {"critic_loss": float(critic_loss.detach()), "actor_loss": float(actor_loss.detach()), "q": float(q.detach().mean())}

    def actor_loss(self, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Deterministic policy gradient through the critic's expected value, plus (LBGP) the goal
        prior; ``obs``: stored inputs (the actor reads their first ``actor_inputs`` numbers)."""
        actor_obs = obs[:, : self.actor_inputs]
        action = self.actor(actor_obs)
        q = self.critic.q_value(obs, action)
        loss = -q.mean()
        if self.prior_weight > 0:
            prior = self.actor.base_action(actor_obs) if self.actor.residual_scale > 0 else self.prior
            loss = loss + self.prior_weight * ((action - prior) ** 2).sum(-1).mean()
        return loss, q

    def state_dict(self) -> dict:
        return {
            "actor": self.actor.state_dict(),
            "critic": self.critic.state_dict(),
            "target_actor": self.target_actor.state_dict(),
            "target_critic": self.target_critic.state_dict(),
            "actor_opt": self.actor_opt.state_dict(),
            "critic_opt": self.critic_opt.state_dict(),
            "updates": torch.tensor(self.updates),
            "obs_stats_set": torch.tensor(self.obs_stats_set),
            "actor_stats_fixed": torch.tensor(self.actor_stats_fixed),
            **({"average_actor": self.average_actor.state_dict()} if self.average_actor is not None else {}),
        }

    def load_state_dict(self, state: dict) -> None:
        self.actor.load_state_dict(state["actor"])
        self.critic.load_state_dict(state["critic"])
        self.target_actor.load_state_dict(state["target_actor"])
        self.target_critic.load_state_dict(state["target_critic"])
        self.actor_opt.load_state_dict(state["actor_opt"])
        self.critic_opt.load_state_dict(state["critic_opt"])
        self.updates = int(state["updates"])
        self.obs_stats_set = bool(state.get("obs_stats_set", True))
        self.actor_stats_fixed = bool(state.get("actor_stats_fixed", False))
        if self.average_actor is not None:
            self.average_actor.load_state_dict(state["average_actor"] if "average_actor" in state else state["actor"])

    @property
    def policy_actor(self) -> Actor:
        """The actor a run's policy file holds: the weight average with cfg.policy_average, else the actor."""
        return self.average_actor if self.average_actor is not None else self.actor
