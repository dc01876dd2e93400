"""Actor and distributional critic networks (torch).

Both standardise their observation input with fixed per-dimension statistics (buffers ``obs_mean``
and ``obs_std``, identity until the learner sets them from its first replay contents; they travel
with the weights and are saved in checkpoints and policy files). The raw observation's dimensions
differ in spread by two orders of magnitude (a 0.3 rad/s turn moves the person's heading by 0.02 per
frame, the robot's position spans the whole [-0.5, 0.5]).

The actor has two output forms:

* plain (the paper's): ``a = tanh(net(obs))`` in [-1, 1]^2;
* residual (``residual_scale > 0``, LBGP's default): ``a = base + residual_scale * tanh(net(obs))``,
  clipped to [-1, 1], with the last layer initialised to zero, so that an untrained actor gives
  exactly the ``base`` action (the goal 1.5 m ahead) and learning only has to find where to deviate.
  With ``turn_lead > 0`` the base is turn-aware: the goal ahead moves ``turn_lead`` metres farther
  per rad/s of the person's turn rate as the observation shows it
  (``lbgp.sim.observation.turn_rate_weights``), because a robot tracking a goal around a turning
  person falls behind it (docs/ablations.md).

With ``motion_features`` both networks also see five motion estimates read linearly off the
observation (the person's velocity and turn rate, the robot's velocity; ``motion_feature_weights``),
appended to it before the standardisation: nothing the stacked frames do not hold, only
differences the network need not learn.

Both take ``obs_size`` inputs: the 57-number observation, or 59 with the previous action after it
(``previous_goal``, ``lbgp.agent.previous_goal``).
"""

from __future__ import annotations

import numpy as np
import torch
from torch import nn

from lbgp.actions import GOAL_X
from lbgp.sim.observation import SIZE as OBS_SIZE
from lbgp.sim.observation import MOTION_FEATURES, motion_feature_weights, turn_rate_weights

MIN_OBS_STD = 0.01  # floor of the standardisation's std (scaled units: 6 cm, 1.8 deg): pure-noise
# dimensions are not blown up


def mlp(sizes, out: int) -> nn.Sequential:
    """LayerNorm + tanh on the first layer (acme's LayerNormMLP), ELU after the others."""
    layers: list[nn.Module] = [nn.Linear(sizes[0], sizes[1]), nn.LayerNorm(sizes[1]), nn.Tanh()]
    for a, b in zip(sizes[1:-1], sizes[2:]):
        layers += [nn.Linear(a, b), nn.ELU()]
    layers.append(nn.Linear(sizes[-1], out))
    return nn.Sequential(*layers)


class Standardizer(nn.Module):
    """x -> (x - mean) / std with fixed buffers (identity until ``set_stats``)."""

    def __init__(self, size: int):
        super().__init__()
        self.register_buffer("obs_mean", torch.zeros(size))
        self.register_buffer("obs_std", torch.ones(size))

    def set_stats(self, mean: torch.Tensor, std: torch.Tensor) -> None:
        with torch.no_grad():
            self.obs_mean.copy_(mean)
            self.obs_std.copy_(torch.clamp(std, min=MIN_OBS_STD))

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        return (obs - self.obs_mean) / self.obs_std


class NetworkInputs(nn.Module):
    """The observation, with the motion estimates appended when asked (``motion_features``), as
    both networks see it before standardising it (``size`` numbers)."""

    def __init__(self, obs_size: int, motion_features: bool = False):
        super().__init__()
        self.motion_features = bool(motion_features)
        if self.motion_features and obs_size < OBS_SIZE:
            raise ValueError(f"motion_features reads the {OBS_SIZE}-number observation (and any inputs after it), got {obs_size} inputs")
        weights = np.zeros((obs_size, len(MOTION_FEATURES) if self.motion_features else 0), np.float32)
        if self.motion_features:  # read off the observation; extra inputs after it (the previous action) get no weight
            weights[:OBS_SIZE] = motion_feature_weights()
        self.register_buffer("weights", torch.from_numpy(weights), persistent=False)
        self.size = obs_size + weights.shape[1]

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        if not self.motion_features:
            return obs
        return torch.cat([obs, obs @ self.weights], dim=-1)


class Actor(nn.Module):
    """Deterministic policy: observation -> action in [-1, 1]^action_size."""

    def __init__(self, obs_size: int, action_size: int, hidden=(256, 256), residual_scale: float = 0.0, base=None,
                 turn_lead: float = 0.0, motion_features: bool = False):
        super().__init__()
        self.obs_size = int(obs_size)  # the observation, or more with the previous action (lbgp.agent.previous_goal)
        self.inputs = NetworkInputs(obs_size, motion_features)
        self.norm = Standardizer(self.inputs.size)
        self.net = mlp([self.inputs.size, *hidden], action_size)
        self.residual_scale = float(residual_scale)
        if not 0.0 <= self.residual_scale <= 2.0:
            raise ValueError(f"residual_scale must be in [0, 2], got {residual_scale}")
        self.register_buffer("base", torch.zeros(action_size) if base is None else torch.as_tensor(base, dtype=torch.float32).reshape(action_size))
        self.turn_lead = float(turn_lead)  # m of goal distance per rad/s of the person's turn rate
        if not (np.isfinite(self.turn_lead) and 0.0 <= self.turn_lead <= 5.0):
            raise ValueError(f"turn_lead must be in [0, 5] m per rad/s, got {turn_lead}")
        if self.turn_lead > 0 and (self.residual_scale == 0 or action_size != 2):
            raise ValueError("turn_lead needs a residual goal actor (residual_scale > 0, 2 outputs)")
        # obs @ lead = the base goal's extra x in action units (x action = 2 (x - GOAL_X[0]) / span - 1)
        lead = np.zeros((obs_size, 1), np.float32)
        if self.turn_lead > 0:
            lead[:OBS_SIZE, 0] = turn_rate_weights() * self.turn_lead * 2.0 / (GOAL_X[1] - GOAL_X[0])
        self.register_buffer("_lead", torch.from_numpy(lead), persistent=False)
        if self.residual_scale > 0:
            last = self.net[-1]
            nn.init.zeros_(last.weight)
            nn.init.zeros_(last.bias)

    def base_action(self, obs: torch.Tensor) -> torch.Tensor:
        """The residual's base for each observation (batch, action_size): ``base``, its goal moved
        ahead by ``turn_lead`` * |turn rate| when that is set."""
        base = self.base.expand(*obs.shape[:-1], self.base.shape[0])
        if self.turn_lead == 0:
            return base
        shift = torch.abs(obs @ self._lead)  # (..., 1)
        return base + torch.cat([shift, torch.zeros_like(shift)], dim=-1)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        out = torch.tanh(self.net(self.norm(self.inputs(obs))))
        if self.residual_scale > 0:
            return torch.clamp(self.base_action(obs) + self.residual_scale * out, -1.0, 1.0)
        return out

    def set_obs_stats(self, mean: torch.Tensor, std: torch.Tensor) -> None:
        self.norm.set_stats(mean, std)


class DistributionalCritic(nn.Module):
    """(observation, action) -> logits of a categorical value distribution over fixed atoms."""

    def __init__(self, obs_size: int, action_size: int, num_atoms: int, v_min: float, v_max: float, hidden=(256, 256),
                 motion_features: bool = False):
        super().__init__()
        self.inputs = NetworkInputs(obs_size, motion_features)
        self.norm = Standardizer(self.inputs.size)
        self.net = mlp([self.inputs.size + action_size, *hidden], num_atoms)
        self.register_buffer("atoms", torch.linspace(v_min, v_max, num_atoms))

    def forward(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return self.net(torch.cat([self.norm(self.inputs(obs)), action], dim=-1))

    def q_value(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return (torch.softmax(self(obs, action), dim=-1) * self.atoms).sum(-1)

    def set_obs_stats(self, mean: torch.Tensor, std: torch.Tensor) -> None:
        self.norm.set_stats(mean, std)
