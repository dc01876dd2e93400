"""Starting a training run from a trained policy's actor (fine-tuning): ``lbgp train --init-policy FILE``.

The run's actor, its target copy and its weight average start as the policy file's actor, its
input standardisation included (``D4PGLearner.set_obs_stats`` then standardises only the critic's
inputs). The critic starts fresh and learns the values of that actor's behaviour during the actor
warm-up (``actor_warmup_updates``): the actor does not move until the critic has seen its data.
Use it to continue a shipped policy on a changed planner, on other dynamics or on another robot.

The policy file must hold the actor the run's configuration builds (method, hidden sizes, residual
goal form, turn lead, inputs); a file that does not is refused with the difference named.
"""

from __future__ import annotations

from pathlib import Path

from lbgp.agent.config import D4PGConfig
from lbgp.agent.learner import D4PGLearner, make_actor
from lbgp.agent.policy import load_policy


def initial_actor_mismatch(policy_actor, cfg: D4PGConfig, obs_size: int, method: str) -> str:
    """What differs between a policy file's actor and the one ``cfg`` builds ('' when nothing)."""
    if method != cfg.method:
        return f"the policy is method {method}, the run {cfg.method}"
    wanted = make_actor(cfg, obs_size, 2)
    for name in ("residual_scale", "turn_lead"):
        if float(getattr(policy_actor, name)) != float(getattr(wanted, name)):
            return f"{name} {getattr(policy_actor, name)} in the policy, {getattr(wanted, name)} in the run's configuration"
    if bool(policy_actor.inputs.motion_features) != bool(wanted.inputs.motion_features):
        return f"motion_features {policy_actor.inputs.motion_features} in the policy, {wanted.inputs.motion_features} in the run"
    theirs = {k: tuple(v.shape) for k, v in policy_actor.state_dict().items()}
    ours = {k: tuple(v.shape) for k, v in wanted.state_dict().items()}
    differing = [k for k in sorted(theirs.keys() | ours.keys()) if theirs.get(k) != ours.get(k)]
    if differing:
        k = differing[0]
        return (f"the actor's layers differ (hidden sizes or inputs): {k} is {theirs.get(k, 'absent')} in the policy, "
                f"{ours.get(k, 'absent')} in the run ({len(differing)} tensors differ)")
    return ""


def start_from_policy(learner: D4PGLearner, path: str | Path) -> None:
    """Load the actor of the policy file at ``path`` into ``learner`` (actor, target, average) and
    keep its input standardisation. A corrupt file or one whose actor does not fit the learner's
    configuration raises a ValueError naming the problem."""
    policy = load_policy(path)
    problem = initial_actor_mismatch(policy.actor, learner.cfg, learner.actor_inputs, policy.method)
    if problem:
        raise ValueError(f"{path}: cannot start this run from that policy: {problem}")
    learner.start_actor_from(policy.actor.state_dict())
