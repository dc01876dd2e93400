"""Policy files: a trained actor with everything needed to use it, loadable with one call.

    policy = lbgp.agent.load_policy("lbgp/agent/pretrained/lbgp_jackal.pt")
    action = policy.act(observation)      # observation: the 57-number vector; action in [-1, 1]^2

A policy file holds the actor's weights, its sizes, the method (lbgp: goal actions; e2e: (v, w)),
the robot it was trained on, the observation layout version, training facts, and the planner
settings training changed from the robot's preset (``Policy.planner_changes``, e.g.
``{"sqp_iterations": 1}`` after ``lbgp train --set planner_sqp_iterations=1``; {} for the shipped
policies): ``lbgp evaluate``, ``demo`` and ``deploy`` drive the planner the policy was trained on
(``lbgp.stack.policy_planner``).

A residual LBGP policy acts with a goal dead band (``GOAL_DEADBAND_M``): its residual goal, the
deviation from the goal 1.5 m ahead, is shrunk by that distance toward zero (a soft threshold), so
a residual smaller than the band gives exactly the goal ahead and a larger one keeps its direction.
Measured over the ablation's three LBGP seeds on the paper scenarios (docs/training.md): the small
residuals are mostly the observation noise passed through, and the goal they jitter costs reward
where the person walks straight.

Every policy acts mirror-averaged (``MIRROR_AVERAGE``): the task is symmetric about the person's
heading line (``lbgp.sim.observation.mirror``), so the actor is asked about the observation and its
mirror image, and the action is the mean of its answer and the mirrored answer to the mirror image.
The result is exactly mirror-equivariant (a world and its mirror image get mirrored actions, so a
left-right bias the actor learned cancels) and averages two estimates of the same action (less of
the noise the actor passes through). Measured on the paper scenarios over the ablation's seeds
(docs/training.md); ``mirror_average=False`` gives the actor's own answer. What it costs: from
straight behind the person, passing means choosing a side, which an equivariant policy cannot
prefer (its lateral goal is zero in a state that is its own mirror image); the real-world
protocol's behind starts lose what the shipped actor's side preference had won there
(docs/training.md).

A policy trained with the previous goal as an input (``lbgp.agent.previous_goal``) remembers the
action it returned last and feeds it back with the next observation; ``reset()`` (called by every
rollout and by ``lbgp deploy`` at each start) forgets it. Its mirror averaging mirrors that action too.
"""

from __future__ import annotations

import numpy as np
import torch

from lbgp.actions import action_from_goal, goal_from_action, mirror_action
from lbgp.agent.checkpoint import load_checked, save_atomic
from lbgp.agent.networks import Actor
from lbgp.agent.previous_goal import agent_input, agent_input_size, first_previous_action, mirror_input, reads_previous_action
from lbgp.planner.config import checked_changes
from lbgp.sim import observation as obs_lib

FORMAT = "lbgp-policy"
VERSION = 6  # 2: input standardisation buffers and the residual goal form; 3: the turn-aware base;
# 4: the motion-feature inputs; 5: the previous goal as an input; 6: the planner changes of training
READABLE = (1, 2, 3, 4, 5, 6)
GOAL_DEADBAND_M = 0.075  # m: a residual policy's dead band around its base goal (0: the actor's raw goal); 0.1 until 2026-12-06 (docs/training.md)
MIRROR_AVERAGE = True  # act with the mean of the actor's answers to the observation and its mirror image


def shrink_residual(action, base, deadband_m: float) -> np.ndarray:
    """The goal of ``action`` moved ``deadband_m`` metres toward the goal of ``base`` (no further
    than onto it): a soft threshold on the residual goal's length."""
    if deadband_m <= 0.0:
        return np.asarray(action, np.float32)
    goal, base_goal = goal_from_action(action), goal_from_action(base)
    residual = goal - base_goal
    length = float(np.hypot(*residual))
    if length <= deadband_m:
        return action_from_goal(base_goal).astype(np.float32)
    return action_from_goal(base_goal + residual * (1.0 - deadband_m / length)).astype(np.float32)


class Policy:
    """A deterministic actor: ``act(observation) -> action``."""

    def __init__(self, actor: Actor, method: str, meta: dict, goal_deadband: float = GOAL_DEADBAND_M,
                 mirror_average: bool = MIRROR_AVERAGE, planner_changes: dict | None = None):
        if not (np.isfinite(goal_deadband) and goal_deadband >= 0.0):
            raise ValueError(f"goal_deadband must be a finite distance >= 0 m, got {goal_deadband!r}")
        self.actor = actor.eval()
        self.method = method
        self.control = "goal" if method == "lbgp" else "velocity"
        self.meta = meta
        # only a residual goal policy has a base goal to shrink toward
        self.goal_deadband = float(goal_deadband) if self.actor.residual_scale > 0 and self.control == "goal" else 0.0
        self.mirror_average = bool(mirror_average)
        self.previous_goal = reads_previous_action(self.actor)
        self.planner_changes = dict(planner_changes or {})  # PlannerConfig fields training changed from the preset
        self._previous = None

    def reset(self) -> None:
        """Start of an episode or run: forget the previous action."""
        self._previous = None

    def _actor_input(self, observation) -> np.ndarray:
        """The observation checked, with the previous action after it when the actor reads it."""
        obs = np.asarray(observation, np.float32)
        if obs.shape != (obs_lib.SIZE,):
            raise ValueError(f"policy expects an observation of shape ({obs_lib.SIZE},), got {obs.shape}")
        if self.previous_goal:
            obs = agent_input(obs, first_previous_action(self.actor) if self._previous is None else self._previous)
        return obs

    @torch.no_grad()
    def base_goal(self, observation) -> np.ndarray:
        """The goal (person frame, m) a residual goal actor adds its residual to for ``observation``
        (the goal 1.5 m ahead, moved ahead by a turn-aware base); a plain or E2E actor has none."""
        if self.control != "goal" or self.actor.residual_scale <= 0:
            raise ValueError(f"a base goal belongs to a residual goal policy; this one is a plain {self.method} actor")
        base = self.actor.base_action(torch.from_numpy(self._actor_input(observation))[None])[0].numpy()
        return goal_from_action(base)

    @torch.no_grad()
    def act(self, observation) -> np.ndarray:
        obs = self._actor_input(observation)
        if self.mirror_average:
            own, of_mirror = self.actor(torch.from_numpy(np.stack([obs, mirror_input(obs)]))).numpy()
            action = (0.5 * (own + mirror_action(of_mirror))).astype(np.float32)
        else:
            action = self.actor(torch.from_numpy(obs)[None])[0].numpy()
        if self.goal_deadband > 0.0:
            # the base of the observation and of its mirror image agree (it has no lateral part)
            base = self.actor.base_action(torch.from_numpy(obs)[None])[0].numpy()
            action = shrink_residual(action, base, self.goal_deadband)
        self._previous = np.array(action, np.float32)
        return action


def save_policy(path, actor: Actor, method: str, robot: str, hidden, extra: dict | None = None, residual_scale: float = 0.0,
                planner_changes: dict | None = None) -> None:
    """Write a policy file atomically; ``planner_changes``: the planner settings (PlannerConfig fields)
    the policy was trained with where they differ from the robot's preset."""
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
            "turn_lead": float(actor.turn_lead),
            "motion_features": bool(actor.inputs.motion_features),
            "previous_goal": reads_previous_action(actor),
            "planner": checked_changes(planner_changes or {}),
            "actor": {k: v.detach().clone() for k, v in actor.state_dict().items()},
            "extra": dict(extra or {}),
        },
        path,
    )


def load_policy(path, goal_deadband: float = GOAL_DEADBAND_M, mirror_average: bool = MIRROR_AVERAGE) -> Policy:
    """Load a policy file; a corrupt, foreign or mismatched file raises a ValueError saying why.
    ``goal_deadband`` (ignored by e2e and plain-actor policies), ``mirror_average``: see the
    module's docstring."""
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
        inputs = agent_input_size(bool(data.get("previous_goal", False)))  # obs_size is checked above
        actor = Actor(inputs, int(data["action_size"]), tuple(int(h) for h in data["hidden"]),
                      residual_scale=float(data.get("residual_scale", 0.0)), turn_lead=float(data.get("turn_lead", 0.0)),
                      motion_features=bool(data.get("motion_features", False)))
        meta = {k: data[k] for k in ("robot", "hidden", "extra")}
        planner_changes = checked_changes(data.get("planner", {}))  # none before version 6: the preset
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
    return Policy(actor, data["method"], meta, goal_deadband=goal_deadband, mirror_average=mirror_average,
                  planner_changes=planner_changes)
