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

``--deadbands 0,0.1,0.2`` also scores every LBGP run (with and without curriculum) at each goal dead
band (lbgp.agent.policy.GOAL_DEADBAND_M; the default one keeps the plain variant name, the others
are variants ``<variant>@deadband<d>``): the ablation of that choice over the same seeds.
``--mirror on,off`` likewise scores every run (E2E included) with and without mirror-averaged
acting (lbgp.agent.policy.MIRROR_AVERAGE; the default keeps the plain name, the other is
``<variant>@nomirror`` or ``<variant>@mirror``). The two choices combine: ``LBGP@deadband0@nomirror``
is the actor's own raw answer.

``--last-actor`` also scores, for every run trained with ``--policy-average`` (its folder keeps
``policy_last.pt`` beside the averaged ``policy.pt``), the last actor as variant ``<variant>@last``:
the paired control from the same training, its difference given per seed.

``--runs`` takes several folders and ``--variants`` picks variants, so that runs of another training
choice kept elsewhere are compared with the ablation's LBGP runs on the same episodes, e.g. mirror
augmentation in training (docs/ablations.md):
``--runs results/ablation_runs,results/mirror_augment_runs --variants LBGP,LBGP-mirror-augment``.

Each run (and HC) keeps its episodes' rewards per scenario (``episode_rewards``), so that runs can be
set against each other on the same episodes: per run, its lead over HC summed over the turning
rows, the trajectory rows and all rows (``over_hc``), and with ``--paired-with RUN`` its sum minus
that run's (``minus_RUN``), each with a 95 % interval paired by episode (episode i of every row is
the same for every policy, so the interval holds the episodes' noise, not the spread between
training runs): whether one run's lead over another is more than the episodes' luck.

``--planner-sqp-iterations K`` scores every policy and HC on the planner with that SQP cap per band
(runs trained with ``lbgp train --set planner_sqp_iterations=K``); E2E drives no planner. Without it
every method drives the preset, even a policy whose file names another planner (``lbgp evaluate``
would honour the file), so that all are compared on one planner. ``--planner-changes
max_vel_x=2.0`` (NAME=VALUE pairs as ``lbgp train --set train_planner_changes`` takes them,
``lbgp.planner.config.changes_from_text``) likewise scores every planner-driven method, HC too, on
the Jackal's preset with those settings changed: e.g. a faster planner for policies trained on
the preset, or for runs trained with those settings.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, planner_changes_arg, write_result  # noqa: E402

import numpy as np  # noqa: E402

from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.policy import GOAL_DEADBAND_M, MIRROR_AVERAGE  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.experiments.sim_table import LEAD_ROWS  # noqa: E402
from lbgp.experiments.tables import paired_lead  # noqa: E402
from lbgp.metrics import reward_ci95  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402


def run_policies(runs_dirs, variants: list[str] | None = None) -> dict[str, Path]:
    """``<variant>_s<seed>`` -> its policy file, for every archived run that has one, in one folder
    or several (a run name found twice is an error); only the ``variants`` named, if given."""
    found: dict[str, Path] = {}
    for runs_dir in [runs_dirs] if isinstance(runs_dirs, (str, Path)) else runs_dirs:
        for p in sorted(Path(runs_dir).glob("*/policy.pt")):
            if variants is not None and variant_of(p.parent.name) not in variants:
                continue
            if p.parent.name in found:
                raise ValueError(f"run {p.parent.name} is in two folders: {found[p.parent.name].parent.parent} and {runs_dir}")
            found[p.parent.name] = p
    return found


def variant_of(run: str) -> str:
    """``LBGP-no-curriculum_s2`` -> ``LBGP-no-curriculum``."""
    return run.rsplit("_s", 1)[0]


def seed_of(run: str) -> str:
    """``LBGP-no-curriculum_s2`` -> ``2``."""
    return run.rsplit("_s", 1)[1]


def acting_run_name(run: str, deadband: float | None = None, mirror: bool = MIRROR_AVERAGE, last: bool = False) -> str:
    """``LBGP_s1`` acting with the defaults stays ``LBGP_s1``; at a 0 m dead band it is
    ``LBGP@deadband0_s1``, without mirror averaging ``LBGP@nomirror_s1`` (both:
    ``LBGP@deadband0@nomirror_s1``). ``deadband`` None: the default. ``last``: the run's last actor
    (``policy_last.pt``) instead of its policy file, ``LBGP@last_s1``."""
    tags = "@last" if last else ""
    if deadband is not None and deadband != GOAL_DEADBAND_M:
        tags += f"@deadband{deadband:g}"
    if mirror != MIRROR_AVERAGE:
        tags += "@mirror" if mirror else "@nomirror"
    return f"{variant_of(run)}{tags}_s{seed_of(run)}" if tags else run


def scenario_seed(seed: int, name: str) -> int:
    """The ``evaluate`` seed of scenario ``name``'s episodes, as ``lbgp experiment sim`` seeds the
    full table: every policy scored with it faces the sim table's episodes."""
    return seed + 1000 * scenario_names().index(name)


def sim_table_episodes(policy, method: str, scenarios, episodes: int, seed: int, planner_config=None) -> dict[str, list[float]]:
    """``policy``'s accumulated reward in each of each scenario's sim-table episodes (``scenario_seed``,
    observation noise on, Jackal), by scenario name, in the episodes' order."""
    rows = [evaluate(policy, method, [name], robot="jackal", episodes=episodes, seed=scenario_seed(seed, name),
                     obs_noise=True, planner_config=planner_config)[0] for name in scenarios]
    return {r["scenario"]: [float(x) for x in r["episode_rewards"]] for r in rows}


def sim_table_rewards(policy, method: str, scenarios, episodes: int, seed: int, planner_config=None) -> dict[str, float]:
    """``policy``'s mean reward (3 decimals) on each scenario's sim-table episodes, by scenario name."""
    return mean_rewards(sim_table_episodes(policy, method, scenarios, episodes, seed, planner_config))


def mean_rewards(per_episode: dict[str, list[float]]) -> dict[str, float]:
    """Each scenario's mean episode reward (3 decimals)."""
    return {name: round(float(np.mean(rewards)), 3) for name, rewards in per_episode.items()}


def sqp_cap(text: str) -> int:
    """``--planner-sqp-iterations``: checked as ``lbgp train --set planner_sqp_iterations`` checks it."""
    try:
        return D4PGConfig.parse_setting(f"planner_sqp_iterations={text}")[1]
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def score(job: tuple) -> tuple[str, dict]:
    """job: (name, method, policy_file, scenarios, episodes, seed, deadband, mirror[, planner_changes]);
    ``planner_changes``: PlannerConfig fields to change from the Jackal's preset (default none). Every
    method drives that planner, whatever planner a policy file says it was trained on."""
    name, method, policy_file, scenarios, episodes, seed, deadband, mirror, *rest = job
    planner = planner_config_for("jackal", rest[0] if rest else None)
    policy = make_policy(method, policy_file, robot="jackal", goal_deadband=deadband, mirror_average=mirror)
    per_episode = sim_table_episodes(policy, method, scenarios, episodes, seed, planner)
    per_scenario = mean_rewards(per_episode)
    return name, {"method": method, "policy": policy_file, "goal_deadband": getattr(policy, "goal_deadband", None),
                  "mirror_average": getattr(policy, "mirror_average", None), "per_scenario": per_scenario,
                  "sum": round(float(sum(per_scenario.values())), 3),
                  "episode_rewards": {name: [round(x, 3) for x in rewards] for name, rewards in per_episode.items()}}


def paired_sum_difference(a: dict, b: dict, scenarios) -> dict | None:
    """Run ``a``'s reward minus run ``b``'s summed over ``scenarios`` (the rows both scored), with the
    95 % half-width paired by episode (``lbgp.experiments.tables.paired_lead``); None where either
    lacks the episodes' rewards (a file from before they were kept) or no named row was scored."""
    if "episode_rewards" not in a or "episode_rewards" not in b:
        return None
    rows = [name for name in scenarios if name in a["episode_rewards"] and name in b["episode_rewards"]]
    if not rows:
        return None
    table = [{"scenario": name, "method": method, "episode_rewards": run["episode_rewards"][name]}
             for name in rows for method, run in (("a", a), ("b", b))]
    lead = paired_lead(table, rows, a="a", b="b")
    half = lead["ci95"]
    return {"difference": round(lead["lead"], 3), "ci95_half_width": round(half, 3) if np.isfinite(half) else None,
            "separated": bool(np.isfinite(half) and abs(lead["lead"]) > half), "episodes": lead["episodes"], "rows": rows}


def paired_comparisons(scored: dict[str, dict], hc: dict, paired_with: str | None = None) -> None:
    """Adds to every run in ``scored`` its lead over ``hc`` (``over_hc``: the turning rows, the
    trajectory rows and all rows) and, with ``paired_with`` (a run's name), its sum minus that
    run's (``minus_<run>``), each paired by episode (``paired_sum_difference``)."""
    if paired_with is not None and paired_with not in scored:
        raise ValueError(f"--paired-with {paired_with}: no such run scored (runs: {', '.join(scored)})")
    for name, run in scored.items():
        everything = list(run.get("per_scenario", {}))
        groups = {**LEAD_ROWS, "all": everything}
        over_hc = {group: paired_sum_difference(run, hc, rows) for group, rows in groups.items()}
        run["over_hc"] = {group: lead for group, lead in over_hc.items() if lead is not None}
        if paired_with is not None and name != paired_with:
            run[f"minus_{paired_with}"] = paired_sum_difference(run, scored[paired_with], everything)


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
    seeds, and (other variants) its difference to ``reference`` with Welch's 95 % interval. An acting
    variant (``X@deadband<d>``, ``X@nomirror``) is the same trained policies as ``X``: its difference to ``X`` is
    also given paired by seed (``minus_X_paired``: mean of the per-seed differences, t interval)."""
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
        base = name.split("@", 1)[0]
        if base != name and base in variants:
            v[f"minus_{base}_paired"] = paired_difference(dict(zip(v["runs"], v["sums"])),
                                                          dict(zip(variants[base]["runs"], variants[base]["sums"])))
    return variants


def paired_difference(sums: dict[str, float], base_sums: dict[str, float]) -> dict:
    """Per seed ``sums[X@..._s<k>] - base_sums[X_s<k>]``: their mean and the 95 % t half-width (None
    with fewer than two seeds in common)."""
    base_by_seed = {seed_of(r): x for r, x in base_sums.items()}
    diffs = [x - base_by_seed[seed_of(r)] for r, x in sums.items() if seed_of(r) in base_by_seed]
    half = round(reward_ci95(diffs), 3) if len(diffs) > 1 else None
    mean = round(float(np.mean(diffs)), 3) if diffs else None
    return {"per_seed": [round(d, 3) for d in diffs], "difference": mean, "ci95_half_width": half,
            "separated": half is not None and abs(mean) > half}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/ablation_scenarios.json")
    ap.add_argument("--runs", default="results/ablation_runs",
                    help="comma-separated folders of training runs (<variant>_s<seed>/policy.pt)")
    ap.add_argument("--variants", help="comma-separated variants to score (default: every run found)")
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (default: the 9 paper scenarios)")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--planner-sqp-iterations", type=sqp_cap, default=0,
                    help="score every planner-driven method (HC too) with this SQP cap per band (0: the preset; "
                         "for runs trained with --set planner_sqp_iterations=K)")
    ap.add_argument("--planner-changes", type=planner_changes_arg, default={}, metavar="NAME=VALUE[,...]",
                    help="score every planner-driven method (HC too) on the preset with these settings changed, "
                         "e.g. max_vel_x=2.0 (default: none)")
    ap.add_argument("--deadbands", default=str(GOAL_DEADBAND_M), help="comma-separated goal dead bands (m) for the LBGP runs")
    ap.add_argument("--mirror", default="on" if MIRROR_AVERAGE else "off",
                    help="comma-separated on/off: score every run with and/or without mirror-averaged acting")
    ap.add_argument("--last-actor", action="store_true",
                    help="also score each run's policy_last.pt (runs trained with --policy-average) as <variant>@last")
    ap.add_argument("--paired-with", metavar="RUN",
                    help="a scored run's name (e.g. LBGP-front09-2h_s0): every other run's sum minus its, paired by episode")
    ap.add_argument("--resummarise", action="store_true",
                    help="no scoring: summarise the runs already in --json again (after a change to the summary only)")
    args = ap.parse_args(argv)
    if args.resummarise:
        result = json.loads(Path(args.json).read_text())
        result["variants"] = summarise(result["runs"])
        try:
            paired_comparisons(result["runs"], result["hc"], args.paired_with)
        except ValueError as error:
            ap.error(str(error))
        write_result(args.json, result)
        return result
    scenarios = args.scenarios.split(",")
    deadbands = [float(d) for d in args.deadbands.split(",")]
    mirrors = [{"on": True, "off": False}.get(m) for m in args.mirror.split(",")]
    if None in mirrors:
        ap.error(f"--mirror takes a comma-separated list of on and off, got {args.mirror!r}")
    policies = run_policies(args.runs.split(","), args.variants.split(",") if args.variants else None)
    if not policies:
        sys.exit(f"no <run>/policy.pt under {args.runs}: run `lbgp experiment ablation` first")
    planner = D4PGConfig(planner_sqp_iterations=args.planner_sqp_iterations).planner_changes()
    if "sqp_iterations" in args.planner_changes and planner:
        ap.error("--planner-changes sets sqp_iterations, which --planner-sqp-iterations sets too: give it once")
    planner = {**planner, **args.planner_changes}
    jobs = [("HC", "hc", None, scenarios, args.episodes, args.seed, None, None, planner)]
    for name, path in policies.items():
        e2e = variant_of(name) == "E2E"
        files = {False: path}
        if args.last_actor and (path.parent / "policy_last.pt").is_file():
            files[True] = path.parent / "policy_last.pt"
        for last, file in files.items():
            for d in [None] if e2e else deadbands:
                for m in mirrors:
                    jobs.append((acting_run_name(name, d, m, last), "e2e" if e2e else "lbgp", str(file), scenarios,
                                 args.episodes, args.seed, d, m, planner))
    names = [job[0] for job in jobs[1:]]  # the runs as scored, acting variants included
    if args.paired_with is not None and args.paired_with not in names:
        ap.error(f"--paired-with {args.paired_with}: no such run among {', '.join(names)}")
    with process_pool(args.jobs) as pool:
        scored = dict(pool.map(score, jobs))
    hc = scored.pop("HC")
    paired_comparisons(scored, hc, args.paired_with)
    result = {
        "command": command_line("ablation_scenarios.py", argv),
        "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios, "planner_changes": planner,
        "hc": hc, "variants": summarise(scored), "runs": scored,
    }
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
