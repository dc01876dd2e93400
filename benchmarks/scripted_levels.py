"""How well hand-written goal policies do on the training levels (a yardstick for learned ones).

    python benchmarks/scripted_levels.py --json results/scripted_levels.json

Policies: a constant goal 1.5 m ahead of the person, and a "side-aware" goal (1.5 m ahead, or,
while the robot is level with or behind the person, a goal beside the person on the robot's side
so the planner goes around rather than through). 20 seeded episodes per level, 35 agent steps,
random spawns and observation noise as in training. Reports the mean and the best episode.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.actions import action_from_goal  # noqa: E402
from lbgp.rollout import ConstantGoalPolicy, run_episode  # noqa: E402
from lbgp.sim import make_env  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402


class SideAwareGoal:
    control = "goal"

    def __init__(self, ahead: float = 1.5, side: float = 1.2):
        self.ahead, self.side = ahead, side

    def act(self, observation):
        x, y = obs_lib.unscale(observation)[:2]  # the robot in the person frame
        if x < 0.5:
            goal = (max(x + 1.0, 0.5), math.copysign(self.side, y if abs(y) > 0.05 else 1.0))
        else:
            goal = (self.ahead, 0.0)
        return action_from_goal(goal).astype(np.float32)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", default="results/scripted_levels.json")
    parser.add_argument("--episodes", type=int, default=20)
    args = parser.parse_args()
    results = []
    for name, policy in (("constant goal 1.5 m ahead", ConstantGoalPolicy((1.5, 0.0))), ("side-aware goal", SideAwareGoal())):
        for level in ("straight", "circles", "trajectories"):
            env = make_env(level, seed=0, control="goal")
            returns = [run_episode(env, policy).total_reward for _ in range(args.episodes)]
            results.append({"policy": name, "level": level, "mean_return": float(np.mean(returns)), "best_return": float(np.max(returns))})
    write_result(args.json, {"benchmark": "scripted_goal_policies_on_levels", "episodes": args.episodes, "results": results})


if __name__ == "__main__":
    main()
