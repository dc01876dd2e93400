"""How many SQP iterations the planner's bands need: speed, command, smoothness and reward against
the iteration cap (``PlannerConfig.sqp_iterations``).

    python benchmarks/sqp_iterations.py --json results/sqp_iterations.json --iterations 1,3,5 --jobs 2

The planner stops a band's SQP at ``sqp_iterations`` (3; 5 before 2026-12-03) or when no command
moves more than ``step_tolerance``; most bands stop at the cap, short of convergence (docs/planner.md). For
each cap K this measures, with everything else the robot's preset:

- ``speed`` (per robot, N = 20): ``bench_planner.bench``'s call median and p99, SQP iterations and
  QP solves per call, and the goal-driven env rate, run one after the other in this process before
  anything else starts (timings move by 20-40 % between runs on this machine: compare within a file);
- ``command`` (Jackal): how far the command (v, w) is from a converged band's
  (``--reference-iterations``, 30) on the same inputs: planner calls recorded along constant-goal
  (1.5 m ahead) episodes of the 9 paper scenarios driven with the cap ``--record-iterations`` (5,
  the default when results/sqp_iterations.json was made), every third call replayed;
- ``scores`` (Jackal): HC and the shipped LBGP on the 9 paper scenarios as ``lbgp experiment sim``
  scores them (``--episodes`` seeded episodes each, observation noise on, the sim table's seeds),
  with sums over the turning scenarios and the trajectories and LBGP minus HC;
- ``goal_sweep`` (per robot): ``benchmarks/goal_sweep.py``'s summary (smoothness in the goal, loops);
- ``goal_jitter`` (Jackal): ``benchmarks/goal_jitter.py``'s share of HC's reward kept under goal noise.

What it is for: the cap trades the band's convergence for time; this says what the trade costs in
what the robot does and in reward, before a default is changed.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import score  # noqa: E402
from bench_planner import bench  # noqa: E402
from goal_jitter import jitter_rewards  # noqa: E402
from goal_sweep import summarise, sweep  # noqa: E402
from turn_lead_rule import minus, summed_row  # noqa: E402

from lbgp.actions import action_from_goal  # noqa: E402
from lbgp.planner import TebPlanner, planner_config_for  # noqa: E402
from lbgp.sim import make_env, scenario_names  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402

SPEED_KEYS = ("median_ms", "p99_ms", "sqp_iterations_per_call", "qp_solves", "osqp_iterations_per_qp", "goal_env_steps_per_s")


def recorded_calls(robot: str = "jackal", iterations: int = 5, every: int = 3, scenarios=None) -> list[tuple]:
    """The planner's inputs (args, kwargs) along constant-goal episodes driven with this SQP cap,
    every ``every``-th call."""
    calls = []
    action = action_from_goal([1.5, 0.0])
    config = planner_config_for(robot).with_(sqp_iterations=iterations)
    for name in scenarios or scenario_names():
        env = make_env(name, robot=robot, seed=0, planner_config=config)
        planner = env.task.controller.planner
        plan = planner.plan

        def recording(*args, _plan=plan, **kwargs):
            calls.append((args, kwargs))
            return _plan(*args, **kwargs)

        planner.plan = recording
        ts = env.reset()
        while not ts.last():
            ts = env.step(action)
    return calls[::every]


def commands(calls, robot: str, iterations: int) -> tuple[np.ndarray, float]:
    """(v, w) of every call with this cap, and the mean SQP iterations per call."""
    planner = TebPlanner(planner_config_for(robot).with_(sqp_iterations=iterations))
    plans = [planner.plan(*args, **kwargs) for args, kwargs in calls]
    return np.array([[p.v, p.w] for p in plans]), float(np.mean([p.iterations for p in plans]))


def command_deviation(robot: str, caps: list[int], reference: int, record: int = 5) -> dict:
    calls = recorded_calls(robot, record)
    ref, ref_iterations = commands(calls, robot, reference)
    out = {"calls": len(calls), "reference_iterations": reference, "reference_sqp_iterations_per_call": ref_iterations}
    for k in caps:
        u, _ = commands(calls, robot, k)
        d = np.abs(u - ref)
        out[str(k)] = {f"{name}_{stat}": float(f(d[:, j])) for j, name in enumerate(("v", "w"))
                       for stat, f in (("median", np.median), ("p90", lambda x: np.percentile(x, 90)), ("max", np.max))}
    return out


def measure(job: tuple) -> tuple[tuple, dict]:
    """One piece of work in a worker process: ("score", K, method, episodes, seed), ("sweep", K, robot)
    or ("jitter", K)."""
    kind, k = job[0], job[1]
    if kind == "score":
        _, _, method, episodes, seed = job
        _, result = score((method, method, None, scenario_names(), episodes, seed, None, None, {"sqp_iterations": k}))
        return job, summed_row(result)
    if kind == "sweep":
        robot = job[2]
        return job, summarise(sweep(robot, planner_config=planner_config_for(robot).with_(sqp_iterations=k)))
    result = jitter_rewards("jackal", planner_config=planner_config_for("jackal").with_(sqp_iterations=k))
    return job, {key: result[key] for key in ("clean_sum", "noisy_sum", "kept")}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/sqp_iterations.json")
    ap.add_argument("--iterations", default="1,3,5", help="comma-separated SQP iteration caps")
    ap.add_argument("--robots", default="jackal,turtlebot2", help="robots for the speed and the goal sweep")
    ap.add_argument("--calls", type=int, default=500, help="planner calls timed per robot and cap")
    ap.add_argument("--episodes", type=int, default=20, help="seeded episodes per scenario and method")
    ap.add_argument("--reference-iterations", type=int, default=30)
    ap.add_argument("--record-iterations", type=int, default=5,
                    help="SQP cap of the planner driving the episodes whose planner inputs are replayed")
    ap.add_argument("--parts", default="speed,command,scores,goal_sweep,goal_jitter")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    caps = [int(x) for x in args.iterations.split(",")]
    robots = args.robots.split(",")
    parts = set(args.parts.split(","))
    result = {"command": command_line("sqp_iterations.py", argv),
              "iterations": caps, "episodes_per_scenario": args.episodes}
    if "speed" in parts:  # alone on the machine, before the workers start
        result["speed"] = {robot: {str(k): {key: bench(robot, 20, args.calls, sqp_iterations=k)[key] for key in SPEED_KEYS}
                                   for k in caps} for robot in robots}
    if "command" in parts:
        result["command"] = command_deviation("jackal", caps, args.reference_iterations, args.record_iterations)
    jobs = []
    if "scores" in parts:
        jobs += [("score", k, method, args.episodes, args.seed) for k in caps for method in ("hc", "lbgp")]
    if "goal_sweep" in parts:
        jobs += [("sweep", k, robot) for k in caps for robot in robots]
    if "goal_jitter" in parts:
        jobs += [("jitter", k) for k in caps]
    with process_pool(args.jobs) as pool:
        done = dict(pool.map(measure, jobs))
    for job, value in done.items():
        kind, k = job[0], str(job[1])
        if kind == "score":
            result.setdefault("scores", {}).setdefault(k, {})[job[2]] = value
        elif kind == "sweep":
            result.setdefault("goal_sweep", {}).setdefault(job[2], {})[k] = value
        else:
            result.setdefault("goal_jitter", {})[k] = value
    for k, row in result.get("scores", {}).items():
        row["lbgp_minus_hc"] = minus(row["lbgp"], row["hc"])
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
