"""Acting with a smoothed goal: each step's goal an exponential average of the policy's goals.

    python benchmarks/goal_smoothing.py --runs REF_RUNS --smoothings 0.3,0.5 \
        --json results/goal_smoothing.json --jobs 2

Why try it: the two acting choices that separated from their alternative (the goal dead band and
mirror-averaged acting, docs/training.md) both take observation noise out of the goal. A low-pass
filter over time is the next such step: the goal asked for at step t becomes
``g_t = s * g_(t-1) + (1 - s) * policy(o_t)`` (``s`` the smoothing; the first step of an episode
takes the policy's goal as it is), i.e. a goal that lags the policy's by ``s / (1 - s)`` steps of
0.2 s. The policy is the trained one as every user gets it (dead band and mirror averaging on),
so ``s = 0`` is exactly ``lbgp experiment sim``'s LBGP.

Each run of ``--runs`` (``<variant>_s<seed>/policy.pt``, as ``benchmarks/ablation_scenarios.py``
reads them) is scored at ``s = 0`` and at every ``--smoothings`` value on the sim table's episodes
(9 paper scenarios, 20 noisy seeded episodes each, Jackal); per value the file gives the per-run
sums, their difference to the same run at ``s = 0`` paired by seed (mean and 95 % t half-width:
the runs are the seeds), and the per-row mean differences.
"""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import run_policies, scenario_seed  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.metrics import reward_ci95  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402


class SmoothedGoals:
    """Wraps a goal policy: ``act`` returns ``s * previous + (1 - s) * policy.act(obs)``.

    Goal actions are an affine map of the goal in metres (``lbgp.actions``), so averaging actions
    averages goals; a convex mix of two actions in [-1, 1]^2 stays in it."""

    def __init__(self, policy, smoothing: float):
        if getattr(policy, "control", None) != "goal":
            raise ValueError("goal smoothing needs a goal policy (control 'goal')")
        if not (np.isfinite(smoothing) and 0.0 <= smoothing < 1.0):
            raise ValueError(f"smoothing must be in [0, 1), got {smoothing!r}")
        self.policy, self.smoothing, self.control = policy, float(smoothing), "goal"
        self._last = None

    def reset(self) -> None:
        self._last = None
        if hasattr(self.policy, "reset"):
            self.policy.reset()

    def act(self, observation) -> np.ndarray:
        action = np.asarray(self.policy.act(observation), np.float32)
        if self._last is not None:
            action = (self.smoothing * self._last + (1.0 - self.smoothing) * action).astype(np.float32)
        self._last = action
        return action


def score(job: tuple) -> tuple[str, float, dict]:
    """job: (run, policy_file, smoothing, scenarios, episodes, seed) -> (run, smoothing, per-scenario reward)."""
    run, policy_file, smoothing, scenarios, episodes, seed = job
    policy = SmoothedGoals(make_policy("lbgp", policy_file, robot="jackal"), smoothing)
    per_scenario = {name: round(float(evaluate(policy, "lbgp", [name], robot="jackal", episodes=episodes,
                                               seed=scenario_seed(seed, name), obs_noise=True)[0]["reward"]), 3)
                    for name in scenarios}
    return run, smoothing, per_scenario


def summarise(runs: dict[str, dict[str, dict]], smoothings: list[float]) -> dict[str, dict]:
    """Per smoothing: per-run sums, the paired difference of the sums to ``s = 0`` (mean, 95 % t
    half-width over the runs, separated or not) and each scenario's mean difference."""
    out = {}
    for s in smoothings:
        key = f"{s:g}"
        diffs = {run: sum(rows[key].values()) - sum(rows["0"].values()) for run, rows in runs.items()}
        values = list(diffs.values())
        half = reward_ci95(values) if len(values) > 1 else None
        mean = float(np.mean(values))
        scenarios = next(iter(runs.values()))["0"].keys()
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
    ap.add_argument("--smoothings", default="0.3,0.5", help="comma-separated smoothings s in (0, 1); 0 is always scored")
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (default: the 9 paper scenarios)")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--json", default="results/goal_smoothing.json")
    args = ap.parse_args(argv)
    try:
        smoothings = [float(s) for s in args.smoothings.split(",")]
    except ValueError:
        ap.error(f"--smoothings takes comma-separated numbers in (0, 1), got {args.smoothings!r}")
    if not all(0.0 < s < 1.0 for s in smoothings):
        ap.error(f"--smoothings takes numbers in (0, 1), got {args.smoothings!r}")
    if args.episodes < 1:
        ap.error("--episodes must be at least 1")
    policies = run_policies(args.runs.split(","), args.variants.split(",") if args.variants else None)
    if not policies:
        ap.error(f"no <run>/policy.pt under {args.runs}")
    scenarios = args.scenarios.split(",")
    unknown = sorted(set(scenarios) - set(scenario_names()))
    if unknown:
        ap.error(f"unknown scenario(s) {', '.join(unknown)}; known: {', '.join(scenario_names())}")
    jobs = [(run, str(path), s, scenarios, args.episodes, args.seed) for run, path in policies.items() for s in [0.0, *smoothings]]
    runs: dict[str, dict[str, dict]] = {}
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for run, s, per_scenario in pool.map(score, jobs):
            runs.setdefault(run, {})[f"{s:g}"] = per_scenario
    result = {
        "command": command_line("goal_smoothing.py", argv),
        "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios,
        "policies": {run: str(path) for run, path in policies.items()},
        "runs": runs, "smoothings": summarise(runs, smoothings),
    }
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
