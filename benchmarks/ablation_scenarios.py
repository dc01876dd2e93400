"""The ablation's trained policies on the paper's scenarios: LBGP vs LBGP-no-curriculum vs E2E.

    python benchmarks/ablation_scenarios.py --json results/ablation_scenarios.json [--jobs 2]

The ablation figure (``lbgp experiment ablation``) compares the variants by the exploiting actor's
training returns: 20 episodes at the end of each run, on random-spawn levels, so its intervals are
wide. This evaluates each run's final policy (``policy.pt``, kept with the run in
``results/ablation_runs/<run>/``) as ``lbgp experiment sim`` does: the 9 paper scenarios, Jackal,
20 seeded episodes each with observation noise on, the same episodes for every policy. Per run:
the mean accumulated reward per scenario and its sum over the scenarios; per variant: the mean of
those sums over the seeds with a 95 % interval (t over the seeds), and each variant's difference to
LBGP with Welch's 95 % interval ("separated" when it excludes 0). HC on the same episodes is the
reference row (a fixed rule: one run).
"""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

import numpy as np  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.metrics import reward_ci95  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402


def run_policies(runs_dir: Path) -> dict[str, Path]:
    """``<variant>_s<seed>`` -> its policy file, for every archived run that has one."""
    return {p.parent.name: p for p in sorted(runs_dir.glob("*/policy.pt"))}


def variant_of(run: str) -> str:
    """``LBGP-no-curriculum_s2`` -> ``LBGP-no-curriculum``."""
    return run.rsplit("_s", 1)[0]


def score(job: tuple[str, str, str | None, list[str], int, int]) -> tuple[str, dict]:
    name, method, policy_file, scenarios, episodes, seed = job
    policy = make_policy(method, policy_file, robot="jackal")
    # scenario k's episodes seeded as lbgp experiment sim seeds them: its rows are the same episodes
    rows = [evaluate(policy, method, [name], robot="jackal", episodes=episodes, seed=seed + 1000 * scenario_names().index(name),
                     obs_noise=True)[0] for name in scenarios]
    per_scenario = {r["scenario"]: round(float(r["reward"]), 3) for r in rows}
    return name, {"method": method, "policy": policy_file, "per_scenario": per_scenario,
                  "sum": round(float(sum(per_scenario.values())), 3)}


def welch_difference(a: list[float], b: list[float]) -> tuple[float, float | None]:
    """mean(a) - mean(b) and the half-width of its 95 % interval (Welch's t: unequal variances;
    None with fewer than two values on a side)."""
    from scipy import stats

    a, b = np.asarray(a, float), np.asarray(b, float)
    diff = float(a.mean() - b.mean())
    if a.size < 2 or b.size < 2:
        return diff, None
    va, vb = a.var(ddof=1) / a.size, b.var(ddof=1) / b.size
    se2 = va + vb
    if se2 == 0.0:
        return diff, 0.0
    dof = se2**2 / (va**2 / (a.size - 1) + vb**2 / (b.size - 1))
    return diff, float(stats.t.ppf(0.975, dof) * np.sqrt(se2))


def summarise(scored: dict[str, dict], reference: str = "LBGP") -> dict[str, dict]:
    """Per variant: its runs, their scenario sums, the mean sum and the 95 % half-width over the
    seeds, and (other variants) its difference to ``reference`` with Welch's 95 % interval."""
    variants: dict[str, dict] = {}
    for name, result in scored.items():
        v = variants.setdefault(variant_of(name), {"runs": [], "sums": []})
        v["runs"].append(name)
        v["sums"].append(result["sum"])
    for v in variants.values():
        v["mean_sum"] = round(float(np.mean(v["sums"])), 3)
        v["ci95_half_width"] = round(reward_ci95(v["sums"]), 3) if len(v["sums"]) > 1 else None
    for name, v in variants.items():
        if name != reference and reference in variants:
            diff, half = welch_difference(v["sums"], variants[reference]["sums"])
            v[f"minus_{reference}"] = {"difference": round(diff, 3), "ci95_half_width": None if half is None else round(half, 3),
                                       "separated": half is not None and abs(diff) > half}
    return variants


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/ablation_scenarios.json")
    ap.add_argument("--runs", default="results/ablation_runs", help="folder of the ablation's runs (<variant>_s<seed>/policy.pt)")
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (default: the 9 paper scenarios)")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    scenarios = args.scenarios.split(",")
    policies = run_policies(Path(args.runs))
    if not policies:
        sys.exit(f"no <run>/policy.pt under {args.runs}: run `lbgp experiment ablation` first")
    jobs = [("HC", "hc", None, scenarios, args.episodes, args.seed)]
    for name, path in policies.items():
        jobs.append((name, "e2e" if variant_of(name) == "E2E" else "lbgp", str(path), scenarios, args.episodes, args.seed))
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        scored = dict(pool.map(score, jobs))
    hc = scored.pop("HC")
    result = {
        "command": "python benchmarks/ablation_scenarios.py " + " ".join(sys.argv[1:] if argv is None else argv),
        "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios,
        "hc": hc, "variants": summarise(scored), "runs": scored,
    }
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
