"""Each method's mean return on the four training levels as a share of the level's reward ceiling.

    python benchmarks/levels_vs_ceiling.py --json results/levels_vs_ceiling.json [--episodes 20]
        [--lbgp-policy runs/NAME/policy.pt]   # score a candidate LBGP policy instead of the shipped one

Training levels as `lbgp evaluate --scenario levels` plays them: random spawns 1-2.5 m around the
person in a uniformly random direction (half of them behind), observation noise on, seeded episodes
(the same for every method). Ceiling: ``results/reward_ceiling.json`` (benchmarks/reward_ceiling.py,
a relaxed point robot: an upper bound for any policy) at the Jackal's top speed, 2 m/s (``--vmax``),
on the file's finest grid; the share of the bound at the planner's speed (1.5 m/s, which no method
here exceeds: the planner's limit, E2E's 1 m/s) is given beside it. Target (goal-policy issue):
LBGP >= 60 %.

``--planner-changes max_vel_x=2.0`` (NAME=VALUE pairs, ``lbgp.planner.config.changes_from_text``)
scores every planner-driven method on the Jackal's preset with those settings changed (and the
"planner's speed" ceiling follows its ``max_vel_x``).

Per level and method also the episodes that start in front of the person (|alpha| < 90 deg) and
behind, apart: their mean returns, counts and shares of the ceiling's front-half and back-half
bounds (where a level's score is lost).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import TOP_SPEED_VMAX, command_line, level_ceilings, planner_changes_arg, write_result  # noqa: E402

import numpy as np  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import level_names  # noqa: E402


class StartSides:
    """An ``evaluate`` recorder that keeps only whether each episode starts with the robot behind
    the person (|alpha| > 90 deg at its first logged state, the reset), in episode order."""

    def __init__(self):
        self.behind: list[bool] = []
        self._first = False

    def begin_episode(self, name: str, index: int = 0) -> None:
        self._first = True

    def log_step(self, info: dict, reward: float | None = None) -> None:
        if self._first:
            self.behind.append(abs(float(info["alpha"])) > math.pi / 2)
            self._first = False


def by_start(rewards, behind: np.ndarray, ceiling: dict) -> dict:
    """Mean return of the episodes that start in front and behind, with counts and shares of the
    ceiling's front-half and back-half bounds (None where no episode started there)."""
    rewards = np.asarray(rewards, dtype=float)
    out = {}
    for side, mask, bound in (("front", ~behind, ceiling["mean_bound_starts_in_front_half"]),
                              ("behind", behind, ceiling["mean_bound_starts_in_back_half"])):
        mean = float(rewards[mask].mean()) if mask.any() else None
        out[side] = {"episodes": int(mask.sum()), "mean_return": None if mean is None else round(mean, 3),
                     "share_of_ceiling": None if mean is None else round(mean / bound, 3)}
    return out


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/levels_vs_ceiling.json")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--methods", default="lbgp,hc,e2e,scripted")
    ap.add_argument("--ceiling", default="results/reward_ceiling.json")
    ap.add_argument("--vmax", type=float, default=TOP_SPEED_VMAX, help="the ceilings' top speed, m/s (default: the Jackal's, 2.0)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--lbgp-policy", default=None, help="LBGP policy file (default: the shipped one)")
    ap.add_argument("--planner-changes", type=planner_changes_arg, default={}, metavar="NAME=VALUE[,...]",
                    help="every planner-driven method drives the Jackal preset with these settings changed, e.g. max_vel_x=2.0")
    args = ap.parse_args(argv)
    changes = args.planner_changes
    changed = planner_config_for("jackal", changes)
    planner = changed if changes else None  # None: each policy's own planner, as lbgp evaluate drives it
    try:
        bounds = level_ceilings(args.ceiling, args.vmax)
        planner_vmax = changed.max_vel_x
        planner_bounds = level_ceilings(args.ceiling, planner_vmax)
    except ValueError as exc:
        ap.error(str(exc))
    levels = level_names()
    ceilings = {name: bounds[name]["mean_bound"] for name in levels}
    command = command_line("levels_vs_ceiling.py", argv)
    out = {"command": command, "episodes": args.episodes, "ceiling_vmax": args.vmax, "ceilings": ceilings,
           "planner_changes": changes, "planner_vmax": planner_vmax,
           "planner_speed_ceilings": {name: planner_bounds[name]["mean_bound"] for name in levels},
           "methods": {}}
    for method in args.methods.split(","):
        policy_file = args.lbgp_policy if method == "lbgp" else None
        policy = make_policy(method, policy_file=policy_file, robot="jackal")
        sides = StartSides()
        rows = evaluate(policy, method, levels, robot="jackal", episodes=args.episodes, seed=args.seed, recorder=sides,
                        planner_config=planner)
        behind = dict(zip(levels, np.array(sides.behind).reshape(len(levels), args.episodes)))
        out["methods"][method] = {
            r["scenario"]: {"mean_return": round(r["reward"], 3), "ci95": round(r.get("reward_ci95", 0.0), 3),
                            "share_of_ceiling": round(r["reward"] / ceilings[r["scenario"]], 3),
                            "share_of_planner_speed_ceiling": round(r["reward"] / out["planner_speed_ceilings"][r["scenario"]], 3),
                            "collisions": int(r["collisions"]),
                            "by_start": by_start(r["episode_rewards"], behind[r["scenario"]], bounds[r["scenario"]])}
            for r in rows}
        print(method, {k: v["share_of_ceiling"] for k, v in out["methods"][method].items()}, file=sys.stderr, flush=True)
    write_result(args.json, out)
    return out


if __name__ == "__main__":
    main()
