"""Planner solve time per call along real simulated episodes, and the goal-driven env step rate.

    python benchmarks/bench_planner.py --json results/bench_planner.json

For each robot and band size (N = 20 and 30 poses): goal-driven episodes of the evaluation
scenarios are run in MuJoCo with a scripted goal 1.5 m ahead of the person until 1,000 planner calls
were made; each call's wall time is recorded (median, p99, max, and which share of the calls
re-initialised the band). The env rate is agent steps per second of the goal-driven task (one
process, two planner calls per agent step).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.actions import action_from_goal  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.sim import make_env, scenario_names  # noqa: E402


def bench(robot: str, n_poses: int, calls: int) -> dict:
    cfg = planner_config_for(robot).with_(n_poses=n_poses)
    times, statuses = [], []
    action = action_from_goal([1.5, 0.0])
    steps, t_env = 0, 0.0
    scenarios = scenario_names()
    i = 0
    while len(times) < calls:
        env = make_env(scenarios[i % len(scenarios)], robot=robot, seed=i, planner_config=cfg)
        planner = env.task.controller.planner
        original = planner.plan

        def timed(*a, **kw):
            t0 = time.perf_counter()
            plan = original(*a, **kw)
            times.append(time.perf_counter() - t0)
            statuses.append(plan.status)
            return plan

        planner.plan = timed
        ts = env.reset()
        t0 = time.perf_counter()
        while not ts.last() and len(times) < calls:
            ts = env.step(action)
            steps += 1
        t_env += time.perf_counter() - t0
        i += 1
    ms = np.array(times[:calls]) * 1000.0
    return {
        "calls": int(len(ms)),
        "median_ms": float(np.median(ms)),
        "p99_ms": float(np.percentile(ms, 99)),
        "max_ms": float(ms.max()),
        "status_counts": {s: statuses.count(s) for s in sorted(set(statuses))},
        "goal_env_steps_per_s": steps / t_env,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", required=True)
    parser.add_argument("--calls", type=int, default=1000)
    args = parser.parse_args()
    result = {
        f"{robot}_N{n}": bench(robot, n, args.calls) for robot in ("jackal", "turtlebot2") for n in (20, 30)
    }
    write_result(args.json, result)


if __name__ == "__main__":
    main()
