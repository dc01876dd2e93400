"""Does acting with several trained LBGP policies at once beat acting with one of them?

    python benchmarks/policy_ensemble.py --json results/policy_ensemble.json --jobs 2 \
        --ensemble results/motion_features_runs/LBGP_s0/policy.pt,results/motion_features_runs/LBGP_s1/policy.pt,...

An ensemble asks every member (each mirror-averaged, without its own dead band) for its goal,
acts with the mean of those goals (person frame, m) and then applies the goal dead band once
(lbgp.agent.policy.shrink_residual, around the first member's base goal: every member built with
the same turn lead has the same base). Each member alone and the ensemble are scored on the paper
scenarios as benchmarks/ablation_scenarios.py scores a run: Jackal, 20 episodes per scenario,
observation noise on, the sim table's seeds, so a member's sum here is its sum there.

``--ensemble`` may be given several times (one ensemble each). Reported per ensemble: its
per-scenario rewards and sum, its members' sums, their mean, and the ensemble's sum minus that
mean (what averaging the goals added over using one member, on average).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import scenario_seed  # noqa: E402

import numpy as np  # noqa: E402
import torch  # noqa: E402

from lbgp.actions import action_from_goal, goal_from_action  # noqa: E402
from lbgp.agent.policy import GOAL_DEADBAND_M, shrink_residual  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402


class EnsemblePolicy:
    """Acts with the mean goal of several LBGP goal policies, then the goal dead band once."""

    control = "goal"

    def __init__(self, policy_files, goal_deadband: float = GOAL_DEADBAND_M, robot: str = "jackal"):
        if not policy_files:
            raise ValueError("an ensemble needs at least one policy file")
        self.members = [make_policy("lbgp", f, robot=robot, goal_deadband=0.0) for f in policy_files]
        self.goal_deadband = float(goal_deadband)

    def reset(self) -> None:
        for m in self.members:
            m.reset()

    @torch.no_grad()
    def act(self, observation) -> np.ndarray:
        goal = np.mean([goal_from_action(m.act(observation)) for m in self.members], axis=0)
        return deadband_once(self.members[0], observation, goal, self.goal_deadband)


@torch.no_grad()
def deadband_once(policy, observation, goal, deadband_m: float) -> np.ndarray:
    """The action of ``goal`` (person frame, m; a mean of goals sent without dead band) moved
    ``deadband_m`` toward ``policy``'s base goal for ``observation`` (``shrink_residual``): the dead
    band applied once, to the mean. Unchanged without a dead band or for a plain actor (no base)."""
    action = action_from_goal(goal).astype(np.float32)
    if deadband_m <= 0.0 or policy.actor.residual_scale == 0:
        return action
    base = policy.actor.base_action(torch.from_numpy(np.asarray(observation, np.float32))[None])[0].numpy()
    return shrink_residual(action, base, deadband_m)


def score(job: tuple) -> tuple[tuple, float]:
    """job: (policy files, scenario, episodes, seed) -> (files, scenario), mean reward."""
    files, name, episodes, seed = job
    row = evaluate(EnsemblePolicy(files), "lbgp", [name], robot="jackal", episodes=episodes,
                   seed=scenario_seed(seed, name), obs_noise=True)[0]
    return (files, name), round(float(row["reward"]), 3)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/policy_ensemble.json")
    ap.add_argument("--ensemble", action="append", required=True, help="comma-separated LBGP policy files (repeatable)")
    ap.add_argument("--scenarios", default=",".join(scenario_names()))
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    ensembles = [tuple(f for f in spec.split(",") if f) for spec in args.ensemble]
    for files in ensembles:
        missing = [f for f in files if not Path(f).is_file()]
        if missing or len(files) < 2:
            ap.error(f"--ensemble {','.join(files)!r}: " + (f"no such policy file {missing[0]}" if missing else "needs two or more policy files"))
    scenarios = args.scenarios.split(",")
    groups = sorted({g for files in ensembles for g in [files, *((f,) for f in files)]})
    jobs = [(g, name, args.episodes, args.seed) for g in groups for name in scenarios]
    with process_pool(args.jobs) as pool:
        rewards = dict(pool.map(score, jobs))

    def sum_of(g):
        return round(sum(rewards[(g, n)] for n in scenarios), 3)

    out = []
    for files in ensembles:
        members = {f: sum_of((f,)) for f in files}
        mean = float(np.mean(list(members.values())))
        out.append({"members": members, "per_scenario": {n: rewards[(files, n)] for n in scenarios},
                    "sum": sum_of(files), "members_mean_sum": round(mean, 3),
                    "minus_members_mean": round(sum_of(files) - mean, 3)})
    result = {"command": command_line("policy_ensemble.py", argv),
              "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios, "ensembles": out}
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
