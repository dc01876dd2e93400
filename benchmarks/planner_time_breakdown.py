"""Where a planner call's time goes: OSQP's parts, Python around it, and per SQP iteration.

    python benchmarks/planner_time_breakdown.py --json results/planner_time_breakdown.json

The planner calls of ``bench_planner.py``'s episodes (the paper's scenarios in turn, seeds 0, 1,
..., a scripted goal 1.5 m ahead of the person) are recorded once per robot (N = 20), then replayed
``--repeats`` times on a fresh planner, timing every call. Reported per call (median and mean, ms):
the whole call, the time inside OSQP's compiled calls and, of that, the value updates
(``update_data_mat`` refactorises the KKT matrix), polishing and the refinement passes; the rest
is Python (rollouts, linearisation, bounds, first guesses, scores). Per QP: ADMM iterations by the
QP's place in its band (first, second, third SQP iteration), how often polishing did not confirm the
solution (the QP is then refined) and what a refinement cost. ``lower_bound_ms`` is the median call's
time inside OSQP: what a call would cost with the Python around it taking no time at all.
Run it alone on an idle machine: timings move by 5-20 % with load.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402
from bench_planner import GOAL, bench_envs  # noqa: E402

from lbgp.actions import action_from_goal  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.planner.teb import TebPlanner  # noqa: E402


def record_calls(robot: str, calls: int) -> list:
    """The (args, kwargs) of ``calls`` planner calls along bench_planner's goal-driven episodes."""
    recorded = []
    action = action_from_goal(GOAL)
    envs = bench_envs(robot, planner_config_for(robot))
    while len(recorded) < calls:
        env = next(envs)
        planner = env.task.controller.planner
        original = planner.plan

        def recording(*args, **kwargs):
            recorded.append((args, kwargs))
            return original(*args, **kwargs)

        planner.plan = recording
        ts = env.reset()
        while not ts.last() and len(recorded) < calls:
            ts = env.step(action)
    return recorded[:calls]


def breakdown(robot: str, calls: list, repeats: int) -> dict:
    planner = TebPlanner(planner_config_for(robot))
    qp = planner._qp
    per_call = {k: [] for k in ("call", "osqp", "update", "polish", "refine")}
    by_place: dict[int, list[int]] = {}
    place = [0]
    original_restart, original_solve = qp.restart, qp.solve

    def restart():
        place[0] = 0
        original_restart()

    def solve(*args):
        before = qp.stats.osqp_iterations - qp.stats.refine_iterations
        status = original_solve(*args)
        by_place.setdefault(place[0], []).append(qp.stats.osqp_iterations - qp.stats.refine_iterations - before)
        place[0] += 1
        return status

    qp.restart, qp.solve = restart, solve
    keys = {"osqp": "solver_seconds", "update": "update_seconds", "polish": "polish_seconds", "refine": "refine_seconds"}
    for _ in range(repeats):
        for args, kwargs in calls:
            before = {k: getattr(qp.stats, v) for k, v in keys.items()}
            t0 = time.perf_counter()
            planner.plan(*args, **kwargs)
            per_call["call"].append(time.perf_counter() - t0)
            for k, v in keys.items():
                per_call[k].append(getattr(qp.stats, v) - before[k])
    ms = {k: np.array(v) * 1000.0 for k, v in per_call.items()}
    ms["python"] = ms["call"] - ms["osqp"]
    stats = qp.stats
    return {
        "calls": len(ms["call"]),
        "per_call_ms": {k: {"median": float(np.median(v)), "mean": float(v.mean()), "p99": float(np.percentile(v, 99))}
                        for k, v in ms.items()},
        "lower_bound_ms": float(np.median(ms["osqp"])),
        "qps_per_call": stats.solves / len(ms["call"]),
        "per_qp_ms": {"osqp": stats.solver_seconds * 1000.0 / stats.solves, "update": stats.update_seconds * 1000.0 / stats.solves,
                      "polish": stats.polish_seconds * 1000.0 / stats.solves},
        "admm_iterations_per_qp_first_pass": {
            f"sqp_iteration_{k + 1}": {"qps": len(v), "mean": float(np.mean(v)), "median": float(np.median(v)),
                                       "p90": float(np.percentile(v, 90))} for k, v in sorted(by_place.items())},
        "refined_share": stats.refined / stats.solves,
        "refine_iterations_per_refined_qp": stats.refine_iterations / max(stats.refined, 1),
        "refine_ms_per_refined_qp": stats.refine_seconds * 1000.0 / max(stats.refined, 1),
        "microseconds_per_admm_iteration": (stats.solver_seconds - stats.update_seconds - stats.polish_seconds) * 1e6
        / max(stats.osqp_iterations, 1),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", required=True)
    parser.add_argument("--calls", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    result = {f"{robot}_N20": breakdown(robot, record_calls(robot, args.calls), args.repeats) for robot in ("jackal", "turtlebot2")}
    write_result(args.json, result)


if __name__ == "__main__":
    main()
