"""A trained LBGP policy acting through a transform of its goals: a gain on its residual, a lead on its goal.

    python benchmarks/acting_transforms.py --gains 0.75,1,1.25,1.5 --leads 0.5 --seed 500 --jobs 2 \
        --json results/acting_transforms_seed500.json

Asks, without training, whether the shipped policy's goals are the right size and come at the right
time. Each transform wraps the policy as a user gets it (``lbgp.policies.make_policy``: goal dead
band and mirror-averaged acting included) and changes only the goal it sends to the planner:

* ``gain k``: goal = base + k * (goal - base), the residual around the actor's base goal scaled
  (k = 1: the policy itself). The goal prior pulls the residual toward zero in training, and the
  searched goals that react after a turn shows swing wider than LBGP's (docs/ceilings.md), so a
  larger residual might pay.
* ``lead b``: goal_t + b * (goal_t - goal_{t-1}), a first-order lead on the goal sequence (b = 0: the
  policy itself). The searched goals on trajectory_three move two to three steps before LBGP's.

Every variant and HC are scored on the same sim-table episodes as ``benchmarks/ablation_scenarios.py``
scores runs (20 noisy episodes per scenario, Jackal, ``--seed``): use a seed other than the sim
table's 0 to judge on held-out episodes. Reported per variant: each row, the 9-row sum and the
turning and trajectory rows' sums minus HC's.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402

import numpy as np  # noqa: E402

from ablation_scenarios import sim_table_rewards  # noqa: E402
from lbgp.actions import action_from_goal, goal_from_action  # noqa: E402
from lbgp.experiments.sim_table import LEAD_ROWS  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.policies import default_policy_path, make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402


class TransformedGoalPolicy:
    """``policy``'s goals with its residual scaled by ``gain`` and a lead ``lead`` on their sequence."""

    control = "goal"

    def __init__(self, policy, gain: float = 1.0, lead: float = 0.0):
        if getattr(policy, "control", None) != "goal":
            raise ValueError("acting transforms change a goal policy's goals; this policy sends velocities")
        if not (np.isfinite(gain) and np.isfinite(lead)):
            raise ValueError(f"gain and lead must be finite, got {gain!r} and {lead!r}")
        self.policy, self.gain, self.lead = policy, float(gain), float(lead)
        self._previous = None

    def reset(self) -> None:
        self._previous = None
        self.policy.reset()

    def act(self, observation) -> np.ndarray:
        base = self.policy.base_goal(observation) if self.gain != 1.0 else None  # before act: it reads the previous goal
        goal = goal_from_action(self.policy.act(observation))
        if base is not None:
            goal = base + self.gain * (goal - base)
        sent = goal if self._previous is None else goal + self.lead * (goal - self._previous)
        self._previous = goal
        return action_from_goal(sent).astype(np.float32)


def variant_name(gain: float, lead: float) -> str:
    return f"gain{gain:g}_lead{lead:g}"


def numbers(text: str, flag: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise SystemExit(f"{flag} takes comma-separated numbers, got {text!r}") from None
    if not values or not all(np.isfinite(values)):
        raise SystemExit(f"{flag} takes comma-separated finite numbers, got {text!r}")
    return values


def score(job: tuple) -> tuple[str, dict]:
    """job: (name, method, policy_file, gain, lead, scenarios, episodes, seed); method hc scores HC."""
    name, method, policy_file, gain, lead, scenarios, episodes, seed = job
    policy = make_policy(method, policy_file, robot="jackal")
    if method == "lbgp":
        policy = TransformedGoalPolicy(policy, gain, lead)
    per_scenario = sim_table_rewards(policy, method, scenarios, episodes, seed, planner_config_for("jackal", None))
    return name, {"gain": gain, "lead": lead, "per_scenario": per_scenario, "sum": round(sum(per_scenario.values()), 3)}


def rows_minus(per_scenario: dict, hc: dict, rows) -> float | None:
    names = [r for r in rows if r in per_scenario]
    return round(sum(per_scenario[r] - hc[r] for r in names), 3) if names else None


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--policy", help="an LBGP policy file (default: the shipped Jackal policy)")
    ap.add_argument("--gains", default="1", help="comma-separated gains on the residual (1: none)")
    ap.add_argument("--leads", default="0", help="comma-separated leads on the goal sequence (0: none)")
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (default: the 9 paper scenarios)")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--json", default="results/acting_transforms.json")
    args = ap.parse_args(argv)
    gains, leads = numbers(args.gains, "--gains"), numbers(args.leads, "--leads")
    scenarios = args.scenarios.split(",")
    unknown = sorted(set(scenarios) - set(scenario_names()))
    if unknown:
        ap.error(f"unknown scenarios {unknown}; known: {', '.join(scenario_names())}")
    if args.episodes < 1:
        ap.error(f"--episodes must be at least 1, got {args.episodes}")
    policy_file = args.policy or os.path.relpath(default_policy_path("lbgp", "jackal"))
    # the policy itself (gain 1, lead 0) always; then each gain without lead and each lead without gain
    pairs = dict.fromkeys([(1.0, 0.0)] + [(g, 0.0) for g in gains] + [(1.0, b) for b in leads])
    jobs = [("HC", "hc", None, 1.0, 0.0, scenarios, args.episodes, args.seed)]
    jobs += [(variant_name(g, b), "lbgp", policy_file, g, b, scenarios, args.episodes, args.seed) for g, b in pairs]
    with process_pool(args.jobs) as pool:
        scored = dict(pool.map(score, jobs))
    hc = scored.pop("HC")["per_scenario"]
    for row in scored.values():
        row["turning_minus_hc"] = rows_minus(row["per_scenario"], hc, LEAD_ROWS["turning"])
        row["trajectories_minus_hc"] = rows_minus(row["per_scenario"], hc, LEAD_ROWS["trajectory"])
    result = {"command": command_line("acting_transforms.py", argv), "policy": policy_file,
              "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios,
              "hc": {"per_scenario": hc, "sum": round(sum(hc.values()), 3)}, "variants": scored}
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
