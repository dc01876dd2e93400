"""Acting with a smoothed goal: each step's goal an exponential average of the policy's goals.

    python benchmarks/goal_smoothing.py --runs REF_RUNS --smoothings 0.3,0.5 \
        --json results/goal_smoothing.json --jobs 2
    python benchmarks/goal_smoothing.py --runs REF_RUNS --smoothings "" --holds 0.1,0.2 --json FILE

Why try it: the two acting choices that separated from their alternative (the goal dead band and
mirror-averaged acting, docs/training.md) both take observation noise out of the goal. A low-pass
filter over time is the next such step: the goal asked for at step t becomes
``g_t = s * g_(t-1) + (1 - s) * policy(o_t)`` (``s`` the smoothing; the first step of an episode
takes the policy's goal as it is), i.e. a goal that lags the policy's by ``s / (1 - s)`` steps of
0.2 s. ``--holds``: a filter without lag for large changes instead (``HeldGoals``): the goal
sent stays the last one sent until the policy's goal is more than ``h`` metres from it, then jumps
there. The policy is the trained one as every user gets it (dead band and mirror averaging on),
so ``s = 0`` is exactly ``lbgp experiment sim``'s LBGP.

Each run of ``--runs`` (``<variant>_s<seed>/policy.pt``, as ``benchmarks/ablation_scenarios.py``
reads them) is scored at ``s = 0`` and at every ``--smoothings`` and ``--holds`` value on the sim table's episodes
(9 paper scenarios, 20 noisy seeded episodes each, Jackal); per value (keys ``"0.3"``, ``"hold0.1"``) the file gives the per-run
sums, their difference to the same run at ``s = 0`` paired by seed (mean and 95 % t half-width:
the runs are the seeds), and the per-row mean differences.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import run_policies, sim_table_rewards  # noqa: E402

from lbgp.actions import goal_from_action  # noqa: E402
from lbgp.metrics import reward_ci95  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402


class GoalFilter:
    """Wraps a goal policy and filters its goals over an episode, from the goal it sent last
    (``_last``, forgotten by ``reset``); subclasses say how in ``filtered``."""

    def __init__(self, policy):
        if getattr(policy, "control", None) != "goal":
            raise ValueError(f"{type(self).__name__} needs a goal policy (control 'goal')")
        self.policy, self.control, self._last = policy, "goal", None

    def reset(self) -> None:
        self._last = None
        if hasattr(self.policy, "reset"):
            self.policy.reset()

    def act(self, observation) -> np.ndarray:
        action = np.asarray(self.policy.act(observation), np.float32)
        self._last = action if self._last is None else self.filtered(action)
        return self._last

    def filtered(self, action: np.ndarray) -> np.ndarray:
        raise NotImplementedError


class SmoothedGoals(GoalFilter):
    """``act`` returns ``s * previous + (1 - s) * policy.act(obs)`` (the first step: the policy's).

    Goal actions are an affine map of the goal in metres (``lbgp.actions``), so averaging actions
    averages goals; a convex mix of two actions in [-1, 1]^2 stays in it."""

    def __init__(self, policy, smoothing: float):
        super().__init__(policy)
        if not (np.isfinite(smoothing) and 0.0 <= smoothing < 1.0):
            raise ValueError(f"smoothing must be in [0, 1), got {smoothing!r}")
        self.smoothing = float(smoothing)

    def filtered(self, action: np.ndarray) -> np.ndarray:
        return (self.smoothing * self._last + (1.0 - self.smoothing) * action).astype(np.float32)


class HeldGoals(GoalFilter):
    """``act`` returns the goal it returned last until the policy's goal is more than ``hold_m``
    metres from it, then the policy's goal (the first step: the policy's)."""

    def __init__(self, policy, hold_m: float):
        super().__init__(policy)
        if not (np.isfinite(hold_m) and hold_m >= 0.0):
            raise ValueError(f"hold must be a distance >= 0 m, got {hold_m!r}")
        self.hold_m = float(hold_m)

    def filtered(self, action: np.ndarray) -> np.ndarray:
        moved = np.hypot(*(goal_from_action(action) - goal_from_action(self._last)))
        return action if moved > self.hold_m else self._last


def acting_key(kind: str, value: float) -> str:
    """The results' key of one way of acting: ``"0.3"`` (smoothing), ``"hold0.1"`` (hold)."""
    return f"{value:g}" if kind == "smoothing" else f"hold{value:g}"


def score(job: tuple) -> tuple[str, str, dict]:
    """job: (run, policy_file, kind, value, scenarios, episodes, seed) -> (run, acting key, per-scenario
    reward); kind "smoothing" (``SmoothedGoals``) or "hold" (``HeldGoals``)."""
    run, policy_file, kind, value, scenarios, episodes, seed = job
    wrapper = SmoothedGoals if kind == "smoothing" else HeldGoals
    policy = wrapper(make_policy("lbgp", policy_file, robot="jackal"), value)
    return run, acting_key(kind, value), sim_table_rewards(policy, "lbgp", scenarios, episodes, seed)


def summarise(runs: dict[str, dict[str, dict]], keys: list[str]) -> dict[str, dict]:
    """Per way of acting (``acting_key``): per-run sums, the paired difference of the sums to ``s = 0`` (mean, 95 % t
    half-width over the runs, separated or not) and each scenario's mean difference."""
    out = {}
    scenarios = next(iter(runs.values()))["0"].keys()
    for key in keys:
        diffs = {run: sum(rows[key].values()) - sum(rows["0"].values()) for run, rows in runs.items()}
        values = list(diffs.values())
        half = reward_ci95(values) if len(values) > 1 else None
        mean = float(np.mean(values))
        out[key] = {
            "sums": {run: round(sum(rows[key].values()), 3) for run, rows in runs.items()},
            "minus_unsmoothed_paired": {"per_run": {r: round(d, 3) for r, d in diffs.items()}, "difference": round(mean, 3),
                                        "ci95_half_width": None if half is None else round(half, 3),
                                        "separated": half is not None and abs(mean) > half},
            "per_scenario_mean_difference": {n: round(float(np.mean([rows[key][n] - rows["0"][n] for rows in runs.values()])), 3)
                                             for n in scenarios},
        }
    return out


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", required=True, help="comma-separated folders of training runs (<variant>_s<seed>/policy.pt)")
    ap.add_argument("--variants", help="comma-separated variants to score (default: every run found)")
    ap.add_argument("--smoothings", default="0.3,0.5", help="comma-separated smoothings s in (0, 1) (may be empty); 0 is always scored")
    ap.add_argument("--holds", default="", help="comma-separated goal holds h > 0 (m; default none)")
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (default: the 9 paper scenarios)")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--json", default="results/goal_smoothing.json")
    args = ap.parse_args(argv)
    try:
        smoothings = [float(s) for s in args.smoothings.split(",") if s.strip()]
        holds = [float(h) for h in args.holds.split(",") if h.strip()]
    except ValueError:
        ap.error(f"--smoothings and --holds take comma-separated numbers, got {args.smoothings!r} and {args.holds!r}")
    if not all(0.0 < s < 1.0 for s in smoothings):
        ap.error(f"--smoothings takes numbers in (0, 1), got {args.smoothings!r}")
    if not all(np.isfinite(h) and h > 0.0 for h in holds):
        ap.error(f"--holds takes distances > 0 m, got {args.holds!r}")
    if not smoothings and not holds:
        ap.error("nothing to compare with s = 0: give --smoothings or --holds")
    if args.episodes < 1:
        ap.error("--episodes must be at least 1")
    policies = run_policies(args.runs.split(","), args.variants.split(",") if args.variants else None)
    if not policies:
        ap.error(f"no <run>/policy.pt under {args.runs}")
    scenarios = args.scenarios.split(",")
    unknown = sorted(set(scenarios) - set(scenario_names()))
    if unknown:
        ap.error(f"unknown scenario(s) {', '.join(unknown)}; known: {', '.join(scenario_names())}")
    acting = [("smoothing", s) for s in [0.0, *smoothings]] + [("hold", h) for h in holds]
    jobs = [(run, str(path), kind, value, scenarios, args.episodes, args.seed) for run, path in policies.items() for kind, value in acting]
    runs: dict[str, dict[str, dict]] = {}
    with process_pool(args.jobs) as pool:
        for run, key, per_scenario in pool.map(score, jobs):
            runs.setdefault(run, {})[key] = per_scenario
    result = {
        "command": command_line("goal_smoothing.py", argv),
        "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios,
        "policies": {run: str(path) for run, path in policies.items()},
        "runs": runs, "smoothings": summarise(runs, [acting_key(k, v) for k, v in acting[1:]]),
    }
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
