"""Actor and distributional critic networks (torch)."""

from __future__ import annotations

import torch
from torch import nn


def mlp(sizes, out: int) -> nn.Sequential:
    """LayerNorm + tanh on the first layer (acme's LayerNormMLP), ELU after the others."""
    layers: list[nn.Module] = [nn.Linear(sizes[0], sizes[1]), nn.LayerNorm(sizes[1]), nn.Tanh()]
    for a, b in zip(sizes[1:-1], sizes[2:]):
        layers += [nn.Linear(a, b), nn.ELU()]
    layers.append(nn.Linear(sizes[-1], out))
    return nn.Sequential(*layers)


class Actor(nn.Module):
    """Deterministic policy: observation -> action in [-1, 1]^action_size."""

    def __init__(self, obs_size: int, action_size: int, hidden=(256, 256)):
        super().__init__()
        self.net = mlp([obs_size, *hidden], action_size)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        return torch.tanh(self.net(obs))


class DistributionalCritic(nn.Module):
    """(observation, action) -> logits of a categorical value distribution over fixed atoms."""

    def __init__(self, obs_size: int, action_size: int, num_atoms: int, v_min: float, v_max: float, hidden=(256, 256)):
        super().__init__()
        self.net = mlp([obs_size + action_size, *hidden], num_atoms)
        self.register_buffer("atoms", torch.linspace(v_min, v_max, num_atoms))

    def forward(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return self.net(torch.cat([obs, action], dim=-1))

    def q_value(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return (torch.softmax(self(obs, action), dim=-1) * self.atoms).sum(-1)
