"""Planner solve time per call along real simulated episodes, QP accuracy, and the goal-driven env rate.

    python benchmarks/bench_planner.py --json results/bench_planner.json
    python benchmarks/bench_planner.py --json /tmp/tight.json --osqp-eps 1e-4 --osqp-rho 0.01 --sizes 20   # the accuracy trade-off
    python benchmarks/bench_planner.py --json /tmp/norefine.json --osqp-refine-eps 0 --sizes 20     # without refinement

For each robot and band size (N = 20 and 30 poses): goal-driven episodes of the evaluation
scenarios are run in MuJoCo with a scripted goal 1.5 m ahead of the person until ``--calls``
planner calls were made; each call's wall time is recorded (median, p99, max), with the OSQP
iterations per QP, how often the iteration cap was hit (and whether a fresh solver then solved the
QP), how often polishing failed (the QP is then refined to ``osqp_refine_eps``, or, without
refinement, accurate to ``osqp_eps`` only), the SQP iterations per call and which candidate bands won.

Accuracy (N = 20): ``--accuracy`` QPs recorded along those episodes are solved again from scratch
to a tight tolerance (eps 1e-9, polished); reported is how far the planner's returned step of the
band's poses (metres) is from that reference: median, p99 and max.

BLAS is pinned to one thread by lbgp itself (see lbgp/__init__.py).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import osqp
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.actions import action_from_goal  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.sim import make_env, scenario_names  # noqa: E402


GOAL = (1.5, 0.0)  # the scripted goal in the person's frame (m), every episode


def bench_envs(robot: str, planner_config=None):
    """The benchmark's goal-driven episodes in order, endlessly: the paper's scenarios in turn,
    seeded 0, 1, 2, ... (drive each with ``action_from_goal(GOAL)``)."""
    scenarios = scenario_names()
    i = 0
    while True:
        yield make_env(scenarios[i % len(scenarios)], robot=robot, seed=i, planner_config=planner_config)
        i += 1


def bench(robot: str, n_poses: int, calls: int, accuracy: int = 0, **overrides) -> dict:
    """``overrides``: PlannerConfig fields to change (e.g. osqp_eps, osqp_rho)."""
    cfg = planner_config_for(robot).with_(n_poses=n_poses, **overrides)
    times, solver_times, statuses, iterations, candidates, recorded = [], [], [], [], [], []
    action = action_from_goal(GOAL)
    steps, t_env = 0, 0.0
    envs = bench_envs(robot, cfg)
    totals = {"solves": 0, "osqp_iterations": 0, "max_iter_hits": 0, "rescues": 0, "rescue_failures": 0, "unpolished": 0, "refined": 0, "refine_capped": 0, "refine_fallbacks": 0}
    while len(times) < calls:
        env = next(envs)
        planner = env.task.controller.planner
        original_plan, original_step = planner.plan, planner._sqp_step

        def timed(*a, **kw):
            solver_before = planner._qp.stats.solver_seconds
            t0 = time.perf_counter()
            plan = original_plan(*a, **kw)
            times.append(time.perf_counter() - t0)
            solver_times.append(planner._qp.stats.solver_seconds - solver_before)
            statuses.append(plan.status)
            iterations.append(plan.iterations)
            candidates.append(plan.candidate)
            return plan

        def recording_step(problem, u, *rest):
            step, status = original_step(problem, u, *rest)
            if step is not None and len(recorded) < accuracy and len(times) % 7 == 0:
                qp = planner._qp
                recorded.append((qp._P.copy(), planner._q.copy(),
                                 sp.csc_matrix((planner._Ax.copy(), *qp._A_pattern), shape=(qp.m, qp.n)), planner._lo.copy(),
                                 planner._hi.copy(), qp.x[: 2 * planner.M].copy()))
            return step, status

        planner.plan = timed
        if accuracy:
            planner._sqp_step = recording_step
        ts = env.reset()
        t0 = time.perf_counter()
        while not ts.last() and len(times) < calls:
            ts = env.step(action)
            steps += 1
        t_env += time.perf_counter() - t0
        for k in totals:
            totals[k] += planner.stats[k]
    ms = np.array(times[:calls]) * 1000.0
    solver_ms = np.array(solver_times[:calls]) * 1000.0
    result = {
        "calls": int(len(ms)),
        "median_ms": float(np.median(ms)),
        "p99_ms": float(np.percentile(ms, 99)),
        "max_ms": float(ms.max()),
        # the part of each call spent inside OSQP's compiled calls (updates, solves, rescues, refinement),
        # and the rest (Python: rollouts, linearisation, bounds, first guesses, scoring)
        "osqp_ms": {"median": float(np.median(solver_ms)), "p99": float(np.percentile(solver_ms, 99)),
                    "share_of_call_time": float(solver_ms.sum() / ms.sum())},
        "outside_osqp_ms": {"median": float(np.median(ms - solver_ms)), "p99": float(np.percentile(ms - solver_ms, 99))},
        "status_counts": {s: statuses.count(s) for s in sorted(set(statuses))},
        "candidate_counts": {c or "none": candidates.count(c) for c in sorted(set(candidates))},
        "sqp_iterations_per_call": float(np.mean(iterations)),
        "qp_solves": totals["solves"],
        "osqp_iterations_per_qp": totals["osqp_iterations"] / max(totals["solves"], 1),
        "osqp_iteration_cap_hits": totals["max_iter_hits"],
        "rescued_qps": totals["rescues"] - totals["rescue_failures"],  # cap hits solved by a fresh solver (SparseQP._rescue)
        "rescue_failures": totals["rescue_failures"],
        "unpolished_qps": totals["unpolished"],
        "refined_qps": totals["refined"],  # polishing failed, continued to osqp_refine_eps (when set)
        "refine_capped": totals["refine_capped"],  # ... whose refinement stopped at its cap, closer than the first pass
        "refine_fallbacks": totals["refine_fallbacks"],
        "goal_env_steps_per_s": steps / t_env,
    }
    if accuracy:
        result["accuracy_vs_tight_reference_m"] = qp_accuracy(recorded)
    return result


def qp_accuracy(recorded) -> dict:
    """Pose-step error (m) of the planner's QP solutions against tightly solved references."""
    errors = []
    for P, q, A, lo, hi, x_planner in recorded:
        solver = osqp.OSQP()
        solver.setup(P, q, A, lo, hi, verbose=False, eps_abs=1e-9, eps_rel=1e-9, max_iter=200_000, polishing=True)
        reference = solver.solve(raise_error=False).x
        errors.append(float(np.max(np.abs(np.asarray(reference[: len(x_planner)]) - x_planner))))
    e = np.array(errors)
    return {"qps": int(len(e)), "median": float(np.median(e)), "p99": float(np.percentile(e, 99)), "max": float(e.max())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", required=True)
    parser.add_argument("--calls", type=int, default=1000)
    parser.add_argument("--accuracy", type=int, default=200, help="QPs checked against a tight reference (N = 20)")
    parser.add_argument("--osqp-eps", type=float, default=None, help="override PlannerConfig.osqp_eps (default: the robot's config)")
    parser.add_argument("--osqp-rho", type=float, default=None, help="override PlannerConfig.osqp_rho")
    parser.add_argument("--osqp-refine-eps", type=float, default=None, help="override PlannerConfig.osqp_refine_eps (0: no refinement)")
    parser.add_argument("--osqp-refine-max-iter", type=int, default=None, help="override PlannerConfig.osqp_refine_max_iter")
    parser.add_argument("--sizes", default="20,30", help="band sizes N to measure, comma-separated")
    args = parser.parse_args()
    overrides = {k: v for k, v in (("osqp_eps", args.osqp_eps), ("osqp_rho", args.osqp_rho), ("osqp_refine_eps", args.osqp_refine_eps),
                                          ("osqp_refine_max_iter", args.osqp_refine_max_iter)) if v is not None}
    if overrides.get("osqp_refine_eps") == 0:
        overrides["osqp_refine_eps"] = None
    result = {
        f"{robot}_N{n}": bench(robot, n, args.calls, args.accuracy if n == 20 else 0, **overrides)
        for robot in ("jackal", "turtlebot2") for n in (int(x) for x in args.sizes.split(","))
    }
    result["osqp_settings"] = {k: getattr(planner_config_for("jackal").with_(**overrides), k) for k in ("osqp_eps", "osqp_rho", "osqp_max_iter", "osqp_refine_eps", "osqp_refine_max_iter")}
    write_result(args.json, result)


if __name__ == "__main__":
    main()
