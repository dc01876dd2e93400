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
"""

from __future__ import annotations

import torch
from torch import nn

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


class Actor(nn.Module):
    """Deterministic policy: observation -> action in [-1, 1]^action_size."""

    def __init__(self, obs_size: int, action_size: int, hidden=(256, 256), residual_scale: float = 0.0, base=None):
        super().__init__()
        self.norm = Standardizer(obs_size)
        self.net = mlp([obs_size, *hidden], action_size)
        self.residual_scale = float(residual_scale)
        if not 0.0 <= self.residual_scale <= 2.0:
            raise ValueError(f"residual_scale must be in [0, 2], got {residual_scale}")
        self.register_buffer("base", torch.zeros(action_size) if base is None else torch.as_tensor(base, dtype=torch.float32).reshape(action_size))
        if self.residual_scale > 0:
            last = self.net[-1]
            nn.init.zeros_(last.weight)
            nn.init.zeros_(last.bias)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        out = torch.tanh(self.net(self.norm(obs)))
        if self.residual_scale > 0:
            return torch.clamp(self.base + self.residual_scale * out, -1.0, 1.0)
        return out

    def set_obs_stats(self, mean: torch.Tensor, std: torch.Tensor) -> None:
        self.norm.set_stats(mean, std)


class DistributionalCritic(nn.Module):
    """(observation, action) -> logits of a categorical value distribution over fixed atoms."""

    def __init__(self, obs_size: int, action_size: int, num_atoms: int, v_min: float, v_max: float, hidden=(256, 256)):
        super().__init__()
        self.norm = Standardizer(obs_size)
        self.net = mlp([obs_size + action_size, *hidden], num_atoms)
        self.register_buffer("atoms", torch.linspace(v_min, v_max, num_atoms))

    def forward(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return self.net(torch.cat([self.norm(obs), action], dim=-1))

    def q_value(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return (torch.softmax(self(obs, action), dim=-1) * self.atoms).sum(-1)

    def set_obs_stats(self, mean: torch.Tensor, std: torch.Tensor) -> None:
        self.norm.set_stats(mean, std)
