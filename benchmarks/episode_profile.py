"""Where in an episode the methods gain or lose: per-step reward, D and alpha, averaged over episodes.

    python benchmarks/episode_profile.py --scenario trajectory_three --episodes 20 \
        --json results/episode_profile_trajectory_three.json

The sim table gives one number per scenario and method. This scores the shipped LBGP and E2E
policies and HC on one scenario's sim-table episodes (``lbgp evaluate`` with the table's seeds,
observation noise on, Jackal), through the same ``evaluate`` call, and keeps every step: for each
method and agent step the mean reward, distance D (m) and angle alpha (deg, 0 = straight in front),
and the person's mean heading (deg) beside them. The per-step rewards of a method add up to its
mean episode reward (the table's number) when no episode ends early.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import scenario_seed  # noqa: E402

import numpy as np  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402

METHODS = ("lbgp", "hc", "e2e")


class StepLog:
    """An ``evaluate`` recorder that keeps each step's reward, D, alpha and person heading."""

    def __init__(self):
        self.episodes: list[dict[str, list[float]]] = []

    def begin_episode(self, setting, index: int) -> None:
        self.episodes.append({"reward": [], "distance": [], "alpha_deg": [], "person_yaw_deg": []})

    def log_step(self, info: dict, reward: float | None = None) -> None:
        if reward is None:
            return  # the reset state: no action taken yet
        step = self.episodes[-1]
        step["reward"].append(float(reward))
        step["distance"].append(float(info["distance"]))
        step["alpha_deg"].append(math.degrees(float(info["alpha"])))
        step["person_yaw_deg"].append(math.degrees(float(info["person_pose"][2])))

    def means(self) -> dict[str, list[float]]:
        """Per step, the mean over the episodes that reached it."""
        longest = max(len(e["reward"]) for e in self.episodes)
        out = {}
        for key in self.episodes[0]:
            columns = [[e[key][t] for e in self.episodes if len(e[key]) > t] for t in range(longest)]
            out[key] = [round(float(np.mean(c)), 4) for c in columns]
        return out


def profile(scenario: str, episodes: int, seed: int = 0, methods=METHODS) -> dict:
    out = {}
    for method in methods:
        log = StepLog()
        row = evaluate(make_policy(method, robot="jackal"), method, [scenario], robot="jackal", episodes=episodes,
                       seed=scenario_seed(seed, scenario), recorder=log, obs_noise=True)[0]
        out[method] = {"reward": round(float(row["reward"]), 3), "terminated_early": row["terminated_early"],
                       "per_step": log.means()}
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenario", default="trajectory_three", choices=scenario_names())
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0, help="the sim table's seed (lbgp experiment sim --seed)")
    parser.add_argument("--methods", default=",".join(METHODS), help="comma separated, from lbgp, hc, e2e")
    parser.add_argument("--json", help="write the result here")
    args = parser.parse_args(argv)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    if not methods or any(m not in METHODS for m in methods):
        parser.error(f"--methods takes names from {', '.join(METHODS)}, got {args.methods!r}")
    if args.episodes < 1:
        parser.error(f"--episodes must be at least 1, got {args.episodes}")
    result = {"command": command_line("episode_profile.py", argv), "scenario": args.scenario,
              "episodes": args.episodes, "seed": args.seed, "methods": profile(args.scenario, args.episodes, args.seed, methods)}
    if args.json:
        write_result(args.json, result)
    else:
        rows = result["methods"]
        print("step " + "".join(f"{m:>26s}" for m in rows) + "  person yaw")
        for t in range(len(rows[methods[0]]["per_step"]["reward"])):
            cells = "".join(f"   r {p['reward'][t]:5.2f} D {p['distance'][t]:4.2f} a {p['alpha_deg'][t]:6.1f}"
                            for p in (rows[m]["per_step"] for m in methods))
            print(f"{t:4d} {cells}  {rows[methods[0]]['per_step']['person_yaw_deg'][t]:7.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
