"""What a planner setting does to HC and to LBGP's lead over it: the trade between the planner
issue's "HC no lower" and the goal-policy issue's leads.

    python benchmarks/planner_trade.py --json results/planner_trade.json --seeds 0,500 --jobs 2 \
        --variants "preset;weight_heading_track=0.1;weight_track_start=0.2"

A variant is a list of ``PlannerConfig`` fields changed from the Jackal's preset (``name=value``,
comma-separated; ``preset`` changes nothing). For each variant this measures:

- ``scores[seed]``: HC and the shipped LBGP (not retrained) on the 9 paper scenarios as
  ``lbgp experiment sim`` scores them (``--episodes`` seeded episodes each, observation noise on;
  seed 0 gives the sim table's episodes, any other seed held-out ones), with the sums over the
  turning and the trajectory scenarios and LBGP minus HC;
- ``hc_original_protocol``: HC on the planner issue's own protocol (``lbgp evaluate --method hc
  --scenario all --episodes 5``: noise-free, seed 0), per scenario, which its "no regression"
  target compares with the values at filing.

What it is for: a planner change that lets HC score more leaves the shipped policy's lead where it
was only if LBGP gains as much; this says whether it does, on held-out episodes as well as the
table's, before a default is changed (docs/planner.md, "Planner weights against the leads").
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import score  # noqa: E402
from turn_lead_rule import minus, summed_row  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.planner.config import changes_from_text  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402


def parse_variant(text: str) -> dict:
    """``"a=1.5,b=none"`` -> {"a": 1.5, "b": None}, checked against ``PlannerConfig`` (``preset``: {})."""
    return {} if text.strip() in ("", "preset") else changes_from_text(text)


def variant_name(changes: dict) -> str:
    return ",".join(f"{k}={v}" for k, v in changes.items()) or "preset"


def measure(job: tuple) -> tuple[tuple, dict]:
    """One piece of work in a worker: ("score", variant, method, episodes, seed) or ("original", variant)."""
    changes = dict(job[1])
    if job[0] == "score":
        _, _, method, episodes, seed = job
        _, result = score((method, method, None, scenario_names(), episodes, seed, None, None, changes))
        return job, summed_row(result)
    rows = evaluate(make_policy("hc"), "hc", scenario_names(), robot="jackal", episodes=5, seed=0,
                    planner_config=planner_config_for("jackal", changes))
    per_scenario = {row["scenario"]: round(row["reward"], 3) for row in rows}
    return job, {"per_scenario": per_scenario, "sum": round(sum(per_scenario.values()), 3)}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/planner_trade.json")
    ap.add_argument("--variants", default="preset", help="';'-separated variants, each comma-separated NAME=VALUE")
    ap.add_argument("--seeds", default="0,500", help="comma-separated episode seeds (0: the sim table's episodes)")
    ap.add_argument("--episodes", type=int, default=20, help="seeded episodes per scenario and method")
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    try:
        variants = [parse_variant(text) for text in args.variants.split(";")]
        seeds = [int(s) for s in args.seeds.split(",")]
    except ValueError as error:
        ap.error(str(error))
    keys = [tuple(sorted(v.items())) for v in variants]
    jobs = [("score", key, method, args.episodes, seed) for key in keys for seed in seeds for method in ("hc", "lbgp")]
    jobs += [("original", key) for key in keys]
    with process_pool(args.jobs) as pool:
        done = dict(pool.map(measure, jobs))
    result = {"command": command_line("planner_trade.py", argv), "episodes_per_scenario": args.episodes, "variants": {}}
    for key in keys:
        entry = {"changes": dict(key), "scores": {}, "hc_original_protocol": done[("original", key)]}
        for seed in seeds:
            hc, lbgp = (done[("score", key, method, args.episodes, seed)] for method in ("hc", "lbgp"))
            entry["scores"][str(seed)] = {"hc": hc, "lbgp": lbgp, "lbgp_minus_hc": minus(lbgp, hc)}
        result["variants"][variant_name(dict(key))] = entry
    write_result(args.json, result)
    for name, entry in result["variants"].items():
        for seed, s in entry["scores"].items():
            lead = s["lbgp_minus_hc"]
            print(f"{name:50s} seed {seed:>4s}: HC {s['hc']['sum']:7.2f} LBGP {s['lbgp']['sum']:7.2f}  lead turning "
                  f"{lead['turning']:+.2f} trajectories {lead['trajectories']:+.2f}")
        original = entry["hc_original_protocol"]
        print(f"{name:50s} HC, the planner issue's protocol: {original['sum']:.2f}, trajectory_three "
              f"{original['per_scenario']['trajectory_three']:.2f}")
    return result


if __name__ == "__main__":
    main()
