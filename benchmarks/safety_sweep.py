"""Contacts and loops over many seeded evaluation episodes.

    python benchmarks/safety_sweep.py --json results/safety_sweep.json [--episodes 1000] [--method lbgp]
    python benchmarks/safety_sweep.py --levels --json results/safety_sweep_levels.json   # the training levels

The paper's 9 scenarios (Jackal), observation noise on, episodes spread evenly over them (each with
its own seed, as `lbgp experiment sim` seeds them). Counts robot-person contacts and loops
(``lbgp.metrics.LoopDetector``: the robot's heading turning through > 180 deg while its goal stays
ahead of the person). Target (goal-policy issue): 0 contacts and 0 loops in 1,000 episodes.
``--levels``: the four training levels instead (random spawns 1-2.5 m around the person, half of
them behind, random person motion; seeded as ``lbgp evaluate`` seeds them), where no target is set.
``--planner-changes max_vel_x=2.0`` (NAME=VALUE pairs, ``lbgp.planner.config.changes_from_text``):
a planner-driven method drives the Jackal preset with those settings changed.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, planner_changes_arg, write_result  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import level_names, scenario_names  # noqa: E402


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/safety_sweep.json")
    ap.add_argument("--episodes", type=int, default=1000, help="episodes in all, spread evenly over the scenarios")
    ap.add_argument("--method", default="lbgp", choices=["lbgp", "hc", "e2e"])
    ap.add_argument("--policy", help="policy file (default: the shipped one)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--levels", action="store_true", help="the four training levels instead of the paper's scenarios")
    ap.add_argument("--planner-changes", type=planner_changes_arg, default={}, metavar="NAME=VALUE[,...]",
                    help="drive the Jackal preset with these settings changed, e.g. max_vel_x=2.0 (default: none)")
    args = ap.parse_args(argv)
    changes = args.planner_changes
    names = level_names() if args.levels else scenario_names()
    per = -(-args.episodes // len(names))
    policy = make_policy(args.method, args.policy, robot="jackal")
    t0 = time.perf_counter()
    rows = evaluate(policy, args.method, names, robot="jackal", episodes=per, seed=args.seed, obs_noise=True,
                    planner_config=planner_config_for("jackal", changes) if changes else None)
    per_scenario = {r["scenario"]: {"episodes": per, "contacts": int(r["collisions"]), "loops": int(r.get("loops", 0)),
                                    "early_ends": int(r["terminated_early"]), "reward": round(r["reward"], 3)} for r in rows}
    result = {
        "command": command_line("safety_sweep.py", argv),
        "method": args.method, "policy": args.policy or "shipped", "planner_changes": changes,
        "settings": "training levels" if args.levels else "paper scenarios", "episodes": per * len(names),
        "contacts": sum(v["contacts"] for v in per_scenario.values()),
        "loops": sum(v["loops"] for v in per_scenario.values()),
        "per_scenario": per_scenario, "wall_time_s": round(time.perf_counter() - t0, 1),
    }
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
