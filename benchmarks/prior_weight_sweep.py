"""What the goal prior weight does: short LBGP training runs on the straight level, one per weight.

    python benchmarks/prior_weight_sweep.py --weights 0,0.3,1,3 --json results/prior_weight_sweep.json

Each run: 15,000 env steps on the straight level only, inline backend (reproducible for its seed),
seed 0. The final policy is scored on straight_ahead and straight_behind (fixed starts, no noise:
one episode each is exact) and on 20 seeded episodes of the straight level itself; a constant goal
1.5 m ahead is scored the same way for scale. About 4 minutes per weight on 2 cores.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT.parent / "tests"))
from _common import write_result  # noqa: E402
from test_learning import straight_level_config  # noqa: E402

from lbgp.agent import load_policy  # noqa: E402
from lbgp.agent.train import train  # noqa: E402
from lbgp.rollout import ConstantGoalPolicy, run_episode  # noqa: E402
from lbgp.sim import make_env  # noqa: E402

JUDGED_ON = (("straight_ahead", 1), ("straight_behind", 1), ("straight", 20))


def score(policy) -> dict:
    result = {}
    for name, episodes in JUDGED_ON:
        env = make_env(name, seed=100, control="goal")
        result[name] = float(np.mean([run_episode(env, policy).total_reward for _ in range(episodes)]))
    return result


def one_weight(weight: float, steps: int, seed: int) -> dict:
    cfg = straight_level_config(seed=seed, total_steps=steps, prior_weight=weight)
    with tempfile.TemporaryDirectory() as tmp:
        train(cfg, Path(tmp) / "run", backend="inline", progress=False)
        return {"prior_weight": weight, **score(load_policy(Path(tmp) / "run" / "policy.pt"))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--weights", default="0,0.3,1,3")
    parser.add_argument("--steps", type=int, default=15_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", default="results/prior_weight_sweep.json")
    args = parser.parse_args()
    runs = [one_weight(float(w), args.steps, args.seed) for w in args.weights.split(",")]
    write_result(args.json, {"benchmark": "prior_weight_sweep", "env_steps": args.steps, "seed": args.seed,
                             "constant_goal_ahead": score(ConstantGoalPolicy()), "runs": runs})


if __name__ == "__main__":
    main()
