"""How much of HC's reward survives white noise on its goal (mocap jitter, a wavering policy)?

    python benchmarks/goal_jitter.py --json results/goal_jitter.json

HC (``lbgp.policies.make_policy("hc")``) on the four turning scenarios (Jackal, no observation
noise), with and without independent Gaussian noise of ``--std`` m (default 0.1) added to each
coordinate of its goal at every agent step, ``--episodes`` seeded episodes each (noise seeds
0..episodes-1). Target (planner issue): the noisy sum keeps >= 90 % of the noise-free sum.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.actions import action_from_goal, goal_from_action  # noqa: E402
from lbgp.experiments.sim_table import LEAD_ROWS  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.rollout import run_episode  # noqa: E402
from lbgp.sim import make_env  # noqa: E402

TURNING = LEAD_ROWS["turning"]


class JitteredGoal:
    """Wraps a goal policy: its goal plus white noise of ``std`` m per coordinate and step."""

    def __init__(self, policy, std: float, seed: int):
        self.policy, self.std, self.control = policy, std, policy.control
        self.rng = np.random.default_rng(seed)

    def reset(self) -> None:
        self.policy.reset()

    def act(self, observation):
        goal = goal_from_action(self.policy.act(observation)) + self.rng.normal(0.0, self.std, 2)
        return action_from_goal(goal).astype(np.float32)


def jitter_rewards(robot: str = "jackal", std: float = 0.1, episodes: int = 5, scenarios=TURNING, planner_config=None) -> dict:
    """HC's reward with and without goal jitter (``planner_config``: default the robot's preset)."""
    rows = {}
    for scenario in scenarios:
        env = make_env(scenario, robot=robot, seed=0, planner_config=planner_config)
        clean = run_episode(env, make_policy("hc")).total_reward  # scenarios are noise-free: one episode
        noisy = [run_episode(env, JitteredGoal(make_policy("hc"), std, seed)).total_reward for seed in range(episodes)]
        rows[scenario] = {"clean": clean, "noisy_mean": float(np.mean(noisy)), "noisy": noisy}
    clean_sum = sum(r["clean"] for r in rows.values())
    noisy_sum = sum(r["noisy_mean"] for r in rows.values())
    return {"scenarios": rows, "clean_sum": clean_sum, "noisy_sum": noisy_sum,
            "kept": noisy_sum / clean_sum if clean_sum else float("nan")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", required=True)
    parser.add_argument("--std", type=float, default=0.1)
    parser.add_argument("--episodes", type=int, default=5)
    parser.add_argument("--robot", default="jackal")
    args = parser.parse_args()
    result = jitter_rewards(args.robot, args.std, args.episodes)
    write_result(args.json, {"benchmark": "goal_jitter", "robot": args.robot, "std_m": args.std,
                             "episodes": args.episodes, **result})


if __name__ == "__main__":
    main()
