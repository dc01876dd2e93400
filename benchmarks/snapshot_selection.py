"""Choosing a run's actor by held-out episodes (training levels, or the paper scenarios' fixed starts) instead of the last one.

    python benchmarks/snapshot_selection.py --runs runs/snapshots --json results/snapshot_selection.json --jobs 2
    python benchmarks/snapshot_selection.py --runs DIR --validation scenarios --validation-seed 2000 --from-s 2700 --json OUT --jobs 2
    python benchmarks/snapshot_selection.py --runs DIR2 --reuse OUT --validation scenarios --validation-seed 2000 --from-s 2700 --json OUT2 --jobs 2

A run trained with ``--set snapshot_every_s=S`` keeps its policy file every S seconds in
``<run>/snapshots/`` (lbgp.agent.train). The last actor of a run is one point of an oscillating
actor-critic pair; this asks whether a rule that sees only training-distribution episodes can pick
a better one. Every snapshot and the final ``policy.pt`` of every run is scored twice, acting as
shipped (dead band, mirror averaging):

- **validation**: with ``--validation levels`` (the default) the four training levels (random
  spawns and person motion, observation noise on), ``--validation-episodes`` per level seeded
  ``[validation_seed, k, i]`` as ``lbgp evaluate`` seeds them (``--validation-seed`` 100: not the
  seed-0 episodes of levels_vs_ceiling.py); with ``--validation scenarios`` the test's own kind of
  episode, the paper scenarios' fixed starts, but ``--validation-episodes`` other noisy episodes per
  scenario, seeded by ``--validation-seed`` as the sim table seeds its own (a seed equal to the
  test's is refused: the rule would see the test). The same episodes for every snapshot; summed.
  This is what the selection rule sees.
- **test**: the 9 paper scenarios on the sim table's 20 noisy seeded episodes each, summed
  (ablation_scenarios.py's scoring). The rule never sees it.

Per run the rule picks the policy with the highest validation sum among those written from
``--from-s`` seconds of wall time on (the final one included); the result gives its test sum minus
the final policy's (paired: the same run), and over the runs their mean with a 95 % t interval.
It also gives, per run, Spearman's rank correlation of validation and test sums over the snapshots:
how well the training levels rank the actors of one run for the scenarios.

``--reuse FILE[,FILE]`` adds the runs an earlier result of this script scored (with the same
validation and test episodes) without scoring them again, so runs trained in different sessions
are summarised together; a run both there and under ``--runs`` takes the file's scores.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import run_policies, score  # noqa: E402

import numpy as np  # noqa: E402

from lbgp.agent.policy import load_policy  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.metrics import reward_ci95  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import level_names, scenario_names  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402


def run_files(run_dir: Path) -> dict[str, Path]:
    """A run's snapshots in order of wall time, then its final policy: ``"<seconds>s"`` / ``"final"`` -> file."""
    files = {p.stem.split("_", 1)[1]: p for p in sorted((run_dir / "snapshots").glob("policy_*s.pt"))}
    files["final"] = run_dir / "policy.pt"
    return files


def validate(job: tuple) -> tuple[tuple, dict]:
    """job: (key, policy_file, episodes, seed[, scenarios]) -> (key, mean return per training level
    and their sum); with ``scenarios``, those paper scenarios scored as the test scores them instead."""
    key, policy_file, episodes, seed, *scenarios = job
    if scenarios:
        return test((key, policy_file, scenarios[0], episodes, seed))
    policy = make_policy("lbgp", policy_file, robot="jackal")
    rows = evaluate(policy, "lbgp", level_names(), robot="jackal", episodes=episodes, seed=seed)
    per_level = {r["scenario"]: round(float(r["reward"]), 3) for r in rows}
    return key, {"per_level": per_level, "sum": round(float(sum(per_level.values())), 3)}


def test(job: tuple) -> tuple[tuple, dict]:
    """job: (key, policy_file, scenarios, episodes, seed) -> (key, the scenarios' rewards and their sum,
    as ablation_scenarios scores them)."""
    key, policy_file, scenarios, episodes, seed = job
    _, scored = score(("", "lbgp", str(policy_file), scenarios, episodes, seed, None, None))
    return key, {"per_scenario": scored["per_scenario"], "sum": scored["sum"]}


def wall_seconds(name: str, final_s: float) -> float:
    return final_s if name == "final" else float(name.rstrip("s"))


def spearman(a: list[float], b: list[float]) -> float | None:
    if len(a) < 3 or len(set(a)) == 1 or len(set(b)) == 1:
        return None  # too few, or constant: no rank correlation
    from scipy import stats

    return round(float(stats.spearmanr(a, b).statistic), 3)


def select(run: dict, from_s: float) -> dict:
    """The rule on one run's scored policies: the highest validation sum from ``from_s`` on."""
    eligible = {n: p for n, p in run["policies"].items() if p["wall_time_s"] >= from_s}
    chosen = max(eligible, key=lambda n: eligible[n]["validation"]["sum"])
    final = run["policies"]["final"]
    names = list(run["policies"])
    return {"chosen": chosen, "chosen_wall_time_s": run["policies"][chosen]["wall_time_s"],
            "chosen_test_sum": run["policies"][chosen]["test"]["sum"], "final_test_sum": final["test"]["sum"],
            "chosen_minus_final": round(run["policies"][chosen]["test"]["sum"] - final["test"]["sum"], 3),
            "best_test_sum_in_hindsight": max(p["test"]["sum"] for p in run["policies"].values()),
            "spearman_validation_test": spearman([run["policies"][n]["validation"]["sum"] for n in names],
                                                 [run["policies"][n]["test"]["sum"] for n in names])}


def over_runs(differences: list[float]) -> dict:
    """The runs' differences, their mean and its 95 % t half-width (None with fewer than two runs)."""
    mean = round(float(np.mean(differences)), 3) if differences else None
    half = round(reward_ci95(differences), 3) if len(differences) >= 2 else None
    return {"per_run": [round(d, 3) for d in differences], "mean": mean, "ci95_half_width": half,
            "separated": None if half is None else bool(abs(mean) > half)}


def reused_runs(files: list[str], validation: dict, test_episodes: dict) -> dict[str, dict]:
    """The scored runs of earlier results of this script, each checked to have been scored on the
    same validation and test episodes as this command's (a ValueError naming the file otherwise)."""
    from lbgp.files import read_json

    runs: dict[str, dict] = {}
    for path in files:
        earlier = read_json(path, "snapshot selection result")
        if not isinstance(earlier, dict) or not isinstance(earlier.get("runs"), dict):
            raise ValueError(f"{path} is not a result of snapshot_selection.py (no runs)")
        for part, ours in (("validation", validation), ("test", test_episodes)):
            if earlier.get(part) != ours:
                raise ValueError(f"{path} was scored on other {part} episodes ({earlier.get(part)}) than this command's ({ours})")
        for name, run in earlier["runs"].items():
            if name in runs:
                raise ValueError(f"run {name} is in two reused files")
            runs[name] = {"policies": run["policies"]}
    return runs


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", help="comma-separated folders of runs (<variant>_s<seed>/policy.pt and snapshots/)")
    ap.add_argument("--reuse", help="comma-separated earlier results of this script whose runs are summarised too, not scored again")
    ap.add_argument("--json", default="results/snapshot_selection.json")
    ap.add_argument("--validation", choices=("levels", "scenarios"), default="levels",
                    help="what the rule sees: the training levels' random episodes, or other noisy episodes of the test's scenarios")
    ap.add_argument("--validation-episodes", type=int, default=20, help="episodes per training level (or scenario)")
    ap.add_argument("--validation-seed", type=int, default=100)
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (the test; default: the 9 paper scenarios)")
    ap.add_argument("--episodes", type=int, default=20, help="episodes per paper scenario (the test)")
    ap.add_argument("--seed", type=int, default=0, help="the sim table's seed (the test)")
    ap.add_argument("--from-s", type=float, default=0.0, help="choose only among policies written from this wall time (s) on")
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    scenarios = args.scenarios.split(",")
    if args.validation == "scenarios" and args.validation_seed == args.seed:
        ap.error(f"--validation scenarios with --validation-seed {args.seed}, the test's --seed: the rule would see the test's episodes")
    if not args.runs and not args.reuse:
        ap.error("give --runs, --reuse or both")
    validation = ({"levels": level_names(), "episodes_per_level": args.validation_episodes, "seed": args.validation_seed}
                  if args.validation == "levels" else
                  {"scenarios": scenarios, "episodes_per_scenario": args.validation_episodes, "seed": args.validation_seed})
    test_episodes = {"scenarios": scenarios, "episodes_per_scenario": args.episodes, "seed": args.seed}
    try:
        runs = reused_runs(args.reuse.split(",") if args.reuse else [], validation, test_episodes)
    except ValueError as e:
        ap.error(str(e))
    policies = run_policies(args.runs.split(",")) if args.runs else {}
    if args.runs and not policies:
        sys.exit(f"no <run>/policy.pt under {args.runs}")
    jobs_v, jobs_t = [], []
    for run, final in policies.items():
        if run in runs:
            continue
        final_s = float(load_policy(final).meta.get("extra", {}).get("wall_time_s", float("inf")))
        files = run_files(final.parent)
        if len(files) == 1:
            sys.exit(f"{final.parent} has no snapshots/: train it with --set snapshot_every_s=SECONDS")
        runs[run] = {"policies": {n: {"file": str(f), "wall_time_s": wall_seconds(n, final_s)} for n, f in files.items()}}
        for n, f in files.items():
            jobs_v.append(((run, n), str(f), args.validation_episodes, args.validation_seed)
                          + ((scenarios,) if args.validation == "scenarios" else ()))
            jobs_t.append(((run, n), str(f), scenarios, args.episodes, args.seed))
    with process_pool(args.jobs) as pool:
        validated = dict(pool.map(validate, jobs_v))
        tested = dict(pool.map(test, jobs_t))
    for (run, n), v in validated.items():
        runs[run]["policies"][n]["validation"] = v
        runs[run]["policies"][n]["test"] = tested[(run, n)]
    for run in runs.values():
        run["selection"] = select(run, args.from_s)
    result = {
        "command": command_line("snapshot_selection.py", argv),
        "validation": validation,
        "test": test_episodes,
        "from_s": args.from_s,
        "reused": args.reuse.split(",") if args.reuse else [],
        "chosen_minus_final": over_runs([r["selection"]["chosen_minus_final"] for r in runs.values()]),
        "runs": runs,
    }
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
