"""One place that turns a method name (+ optional policy file) into a policy object.

Every policy has ``control`` ("goal" or "velocity"), ``act(observation) -> action`` and optionally
``reset()``; the simulator, the experiments and the real robot all get theirs from ``make_policy``.
"""

from __future__ import annotations

from pathlib import Path

from lbgp.conventions import DESIRED_DISTANCE

METHODS = ("lbgp", "e2e", "hc", "scripted")
PRETRAINED = Path(__file__).resolve().parent / "agent" / "pretrained"
# horizon 0: the planner already moves the goal with the person's velocity (GoalController), so an EKF
# forecast on top double-counts (measured: straight_ahead reward 25.6 at 0 s vs 22.2 at 0.4 s vs 10.7 at 1 s)
HC_DEFAULTS = {"distance": DESIRED_DISTANCE, "horizon": 0.0}


def default_policy_path(method: str = "lbgp", robot: str = "jackal") -> Path:
    return PRETRAINED / f"{method}_{robot}.pt"


def make_policy(method: str, policy_file=None, hc_distance: float | None = None, hc_horizon: float | None = None,
                robot: str | None = None, transfer: bool = False, goal_deadband: float | None = None,
                mirror_average: bool | None = None):
    """The policy of ``method``: lbgp/e2e load ``policy_file`` (default: the shipped Jackal one),
    hc builds the EKF baseline, scripted asks for a goal 1.5 m ahead.

    A policy file for another method is refused; so is one trained on another robot than
    ``robot`` unless ``transfer`` (zero-shot transfer, as in the paper's real-robot experiment).
    The shipped default policies are Jackal-trained and transfer by design. ``goal_deadband`` (m):
    a residual LBGP policy's dead band around its base goal (default: ``GOAL_DEADBAND_M``);
    ``mirror_average``: act mirror-averaged (default: ``MIRROR_AVERAGE``); see lbgp.agent.policy."""
    if method in ("lbgp", "e2e"):
        from lbgp.agent.policy import GOAL_DEADBAND_M, MIRROR_AVERAGE, load_policy

        path = Path(policy_file) if policy_file else default_policy_path(method)
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no such policy file")
        policy = load_policy(path, goal_deadband=GOAL_DEADBAND_M if goal_deadband is None else goal_deadband,
                             mirror_average=MIRROR_AVERAGE if mirror_average is None else mirror_average)
        if policy.method != method:
            raise ValueError(f"{path} holds a {policy.method} policy, not {method}")
        trained_on = policy.meta.get("robot")
        if robot is not None and trained_on != robot and not (transfer or policy_file is None):
            raise ValueError(f"{path} holds a {method} policy trained on the {trained_on}, not the {robot}; "
                             f"pass --transfer to run it on the {robot} anyway (zero-shot transfer)")
        return policy
    if method == "hc":
        from lbgp.baselines.hc import HCPolicy

        return HCPolicy(distance=HC_DEFAULTS["distance"] if hc_distance is None else hc_distance,
                        horizon=HC_DEFAULTS["horizon"] if hc_horizon is None else hc_horizon)
    if method == "scripted":
        from lbgp.rollout import ConstantGoalPolicy

        return ConstantGoalPolicy()
    raise ValueError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
