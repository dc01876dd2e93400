"""Each method's mean return on the four training levels as a share of the level's reward ceiling.

    python benchmarks/levels_vs_ceiling.py --json results/levels_vs_ceiling.json [--episodes 20]
        [--lbgp-policy runs/NAME/policy.pt]   # score a candidate LBGP policy instead of the shipped one

Training levels as `lbgp evaluate --scenario levels` plays them: random spawns 1-2.5 m around the
person in a uniformly random direction (half of them behind), observation noise on, seeded episodes
(the same for every method). Ceiling: ``results/reward_ceiling.json`` (benchmarks/reward_ceiling.py,
a relaxed point robot: an upper bound for any policy). Target (goal-policy issue): LBGP >= 60 %.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import level_names  # noqa: E402


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/levels_vs_ceiling.json")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--methods", default="lbgp,hc,e2e,scripted")
    ap.add_argument("--ceiling", default="results/reward_ceiling.json")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--lbgp-policy", default=None, help="LBGP policy file (default: the shipped one)")
    args = ap.parse_args(argv)
    ceilings = {r["level"]: r["mean_bound"] for r in json.loads(Path(args.ceiling).read_text())["results"]}
    command = command_line("levels_vs_ceiling.py", argv)
    out = {"command": command, "episodes": args.episodes, "ceilings": ceilings, "methods": {}}
    for method in args.methods.split(","):
        policy_file = args.lbgp_policy if method == "lbgp" else None
        policy = make_policy(method, policy_file=policy_file, robot="jackal")
        rows = evaluate(policy, method, level_names(), robot="jackal", episodes=args.episodes, seed=args.seed)
        out["methods"][method] = {r["scenario"]: {"mean_return": round(r["reward"], 3), "ci95": round(r.get("reward_ci95", 0.0), 3),
                                                  "share_of_ceiling": round(r["reward"] / ceilings[r["scenario"]], 3),
                                                  "collisions": int(r["collisions"])} for r in rows}
        print(method, {k: v["share_of_ceiling"] for k, v in out["methods"][method].items()}, file=sys.stderr, flush=True)
    write_result(args.json, out)
    return out


if __name__ == "__main__":
    main()
