"""Categorical (C51) projection of a shifted and scaled value distribution onto fixed atoms."""

from __future__ import annotations

import torch


def categorical_projection(
    probs: torch.Tensor, returns: torch.Tensor, discounts: torch.Tensor, atoms: torch.Tensor
) -> torch.Tensor:
    """Project the distribution of ``returns + discounts * Z`` (Z ~ ``probs`` over ``atoms``) back
    onto ``atoms``.

    probs: (B, K) probabilities; returns, discounts: (B,); atoms: (K,) evenly spaced.
    Returns (B, K) probabilities; mass is preserved (values beyond the support go to its ends).
    """
    v_min, v_max = float(atoms[0]), float(atoms[-1])
    k = atoms.numel()
    delta = (v_max - v_min) / (k - 1)
    tz = (returns[:, None] + discounts[:, None] * atoms[None, :]).clamp(v_min, v_max)
    b = (tz - v_min) / delta
    lower = b.floor().long().clamp(0, k - 1)
    upper = b.ceil().long().clamp(0, k - 1)
    # when b lands exactly on an atom, lower == upper: give it all the mass
    w_upper = b - lower.to(b.dtype)
    w_lower = 1.0 - w_upper
    out = torch.zeros_like(probs)
    out.scatter_add_(1, lower, probs * w_lower)
    out.scatter_add_(1, upper, probs * w_upper)
    return out
