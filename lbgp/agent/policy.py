"""Policy files: a trained actor with everything needed to use it, loadable with one call.

    policy = lbgp.agent.load_policy("lbgp/agent/pretrained/lbgp_jackal.pt")
    action = policy.act(observation)      # observation: the 57-number vector; action in [-1, 1]^2

A policy file holds the actor's weights, its sizes, the method (lbgp: goal actions; e2e: (v, w)),
the robot it was trained on, the observation layout version, and training facts.
"""

from __future__ import annotations

import numpy as np
import torch

from lbgp.agent.checkpoint import load_checked, save_atomic
from lbgp.agent.networks import Actor
from lbgp.sim import observation as obs_lib

FORMAT = "lbgp-policy"
VERSION = 2  # 2: input standardisation buffers and the residual goal form (version 1 files still load)
READABLE = (1, 2)


class Policy:
    """A deterministic actor: ``act(observation) -> action``."""

    def __init__(self, actor: Actor, method: str, meta: dict):
        self.actor = actor.eval()
        self.method = method
        self.control = "goal" if method == "lbgp" else "velocity"
        self.meta = meta

    def reset(self) -> None:
        pass

    @torch.no_grad()
    def act(self, observation) -> np.ndarray:
        obs = np.asarray(observation, np.float32)
        if obs.shape != (obs_lib.SIZE,):
            raise ValueError(f"policy expects an observation of shape ({obs_lib.SIZE},), got {obs.shape}")
        return self.actor(torch.from_numpy(obs)[None])[0].numpy()


def save_policy(path, actor: Actor, method: str, robot: str, hidden, extra: dict | None = None, residual_scale: float = 0.0) -> None:
    save_atomic(
        {
            "format": FORMAT,
            "version": VERSION,
            "method": method,
            "robot": robot,
            "obs_size": obs_lib.SIZE,
            "obs_frames": obs_lib.FRAMES,
            "action_size": 2,
            "hidden": list(hidden),
            "residual_scale": float(residual_scale),
            "actor": {k: v.detach().clone() for k, v in actor.state_dict().items()},
            "extra": dict(extra or {}),
        },
        path,
    )


def load_policy(path) -> Policy:
    """Load a policy file; a corrupt, foreign or mismatched file raises a ValueError saying why."""
    data = load_checked(path, FORMAT)
    if data.get("version") not in READABLE:
        raise ValueError(f"{path}: policy file version {data.get('version')} is not supported (expected one of {READABLE})")
    if data.get("obs_size") != obs_lib.SIZE or data.get("obs_frames") != obs_lib.FRAMES:
        raise ValueError(
            f"{path}: policy was trained on {data.get('obs_size')}-number observations of {data.get('obs_frames')} "
            f"frames; this lbgp builds {obs_lib.SIZE} of {obs_lib.FRAMES}"
        )
    if data.get("method") not in ("lbgp", "e2e"):
        raise ValueError(f"{path}: unknown policy method {data.get('method')!r} (expected an lbgp policy for method lbgp or e2e)")
    expected = f"an lbgp policy ({data.get('method')}) with {obs_lib.SIZE} inputs and 2 outputs"
    try:
        actor = Actor(int(data["obs_size"]), int(data["action_size"]), tuple(int(h) for h in data["hidden"]),
                      residual_scale=float(data.get("residual_scale", 0.0)))
        meta = {k: data[k] for k in ("robot", "hidden", "extra")}
        weights = dict(data["actor"])
        if data["version"] == 1:  # no standardisation, plain actor: identity buffers
            weights = {**{k: v for k, v in actor.state_dict().items() if k not in weights}, **weights}
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise ValueError(f"{path}: malformed policy file, expected {expected} ({type(exc).__name__}: {exc})") from None
    try:
        actor.load_state_dict(weights)
    except (RuntimeError, KeyError, TypeError, AttributeError) as exc:
        reason = (str(exc).strip().splitlines() or [type(exc).__name__])[0][:120]
        raise ValueError(f"{path}: actor weights do not match the stored sizes, expected {expected} ({reason})") from None
    if int(data["action_size"]) != 2:
        raise ValueError(f"{path}: policy has {data['action_size']} outputs, expected {expected}")
    return Policy(actor, data["method"], meta)
