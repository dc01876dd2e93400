"""The turn-aware base goal alone (no learning) on the paper's scenarios, against HC.

    python benchmarks/turn_lead_rule.py --json results/turn_lead_rule.json --leads 0,0.2,0.4,0.6 --jobs 2

LBGP's residual actor starts at its base goal (lbgp/agent/networks.py): the goal 1.5 m ahead of the
person, or with ``turn_lead`` L (``lbgp train --turn-lead L``) that goal moved L metres farther
ahead per rad/s of the person's turn rate seen in the observation. An untrained actor *is* that
rule, so this scores untrained actors (saved as policy files and loaded as every policy is, with
the goal dead band and mirror-averaged acting, which leave a zero residual alone) for each lead,
as ``lbgp experiment sim`` scores methods: Jackal, 20 seeded episodes per scenario with observation
noise on, the same episodes for every policy (benchmarks/ablation_scenarios.py's ``score``). Lead 0
is the constant goal 1.5 m ahead. Reports each scenario's mean reward, the sum over the 9
scenarios, over the four turning scenarios and over the three trajectories, for every lead and HC.
What it is for: the yardstick a learned goal policy must beat, measured before training one.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import score  # noqa: E402
from goal_ceiling import TRAJECTORIES, TURNING  # noqa: E402

from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.learner import make_actor  # noqa: E402
from lbgp.agent.policy import save_policy  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402

GROUPS = {"turning": TURNING, "trajectories": TRAJECTORIES}


def untrained_policy_file(folder: Path, lead: float) -> Path:
    """A policy file of an untrained residual LBGP actor with this turn lead: the rule itself."""
    cfg = D4PGConfig(turn_lead=lead).validate()
    actor = make_actor(cfg, obs_lib.SIZE, 2)
    path = folder / f"turn_lead_{lead:g}.pt"
    save_policy(path, actor, "lbgp", "jackal", cfg.hidden, residual_scale=actor.residual_scale)
    return path


def group_sums(per_scenario: dict) -> dict:
    return {name: round(sum(per_scenario[s] for s in members), 3) for name, members in GROUPS.items()
            if all(s in per_scenario for s in members)}


def summed_row(scored: dict) -> dict:
    """An ``ablation_scenarios.score`` result as a row: per scenario, the sum and the group sums."""
    return {"per_scenario": scored["per_scenario"], "sum": scored["sum"], **group_sums(scored["per_scenario"])}


def minus(row: dict, reference: dict) -> dict:
    """``row``'s sum and group sums minus ``reference``'s (e.g. a method's lead over HC)."""
    return {k: round(row[k] - reference[k], 3) for k in ("sum", *GROUPS) if k in row and k in reference}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/turn_lead_rule.json")
    ap.add_argument("--leads", default="0,0.2,0.4,0.6", help="comma-separated turn leads (m per rad/s)")
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (default: the 9 paper scenarios)")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    leads = [float(x) for x in args.leads.split(",")]
    scenarios = args.scenarios.split(",")
    with tempfile.TemporaryDirectory() as tmp:
        jobs = [("HC", "hc", None, scenarios, args.episodes, args.seed, None, None)]
        jobs += [(f"lead {lead:g}", "lbgp", str(untrained_policy_file(Path(tmp), lead)), scenarios, args.episodes,
                  args.seed, None, None) for lead in leads]
        with process_pool(args.jobs) as pool:
            scored = dict(pool.map(score, jobs))
    rows = {}
    for name, result in scored.items():
        rows[name] = summed_row(result)
    hc = rows["HC"]
    for name, row in rows.items():
        if name != "HC":
            row["minus_hc"] = minus(row, hc)
    result = {"command": command_line("turn_lead_rule.py", argv),
              "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios, "rows": rows}
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
