"""What the deployment planner budget costs in following quality.

    python benchmarks/bench_planner_budget.py --json results/bench_planner_budget.json

The deployment loop (lock-step simulated TurtleBot 2, no mocap disturbance) runs LBGP and HC for
35 agent steps on five paper scenarios, with the planner's anytime budget of ``lbgp deploy``
(2 ms of SQP per call) and without it. Reports the accumulated reward per scenario and the mean.
The budget is wall time, so the numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.policies import make_policy  # noqa: E402
from lbgp.real.loop import DEPLOY_DEFAULT_BUDGET, DeployConfig, DeployLoop  # noqa: E402
from lbgp.real.sim_world import SimCommandSink, SimPoseSource, SimWorld  # noqa: E402

SCENARIOS = ("straight_ahead", "turning_inside", "turning_outside", "trajectory_one", "trajectory_two")


def run(method: str, scenario: str, budget, steps: int) -> float:
    world = SimWorld(scenario)
    loop = DeployLoop(SimPoseSource(world), SimCommandSink(world), make_policy(method),
                      DeployConfig(max_steps=steps, planner_time_budget=budget), keep_records=False,
                      end_condition=lambda: "contact" if world.contact else None)
    return loop.run().total_reward


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", default="results/bench_planner_budget.json")
    parser.add_argument("--steps", type=int, default=35)
    args = parser.parse_args()
    results = []
    for method in ("lbgp", "hc"):
        for budget in (DEPLOY_DEFAULT_BUDGET, None):
            rewards = {s: run(method, s, budget, args.steps) for s in SCENARIOS}
            results.append({"method": method, "planner_time_budget_ms": None if budget is None else budget * 1e3,
                            "rewards": rewards, "mean_reward": float(np.mean(list(rewards.values())))})
    write_result(args.json, {"benchmark": "planner_budget_quality", "robot": "turtlebot2", "steps": args.steps, "results": results})


if __name__ == "__main__":
    main()
