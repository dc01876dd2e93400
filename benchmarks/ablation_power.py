"""How large a difference the 3-seed ablations can resolve, and how many seeds a smaller one needs.

    python benchmarks/ablation_power.py --json results/ablation_power.json [--results results]
        [--differences 1,2,4.4]

Every training choice of docs/ablations.md was judged by three runs per variant (seeds 0-2), each
run's policy scored on the sim table's episodes (``benchmarks/ablation_scenarios.py``). The runs of
one variant differ only by their seed, so their spread is the training's seed-to-seed noise. This
reads every committed ``*.json`` in the ablation_scenarios format (``variants`` and ``runs`` with
``per_scenario`` rewards), takes each plain variant (no ``@`` acting suffix) of LBGP (name starting
``LBGP``; ``--variants`` names others) with two or more runs once (runs scored in several files,
the same policy files, count once: the first file in name order), and pools the seed-to-seed
variance over them, for three quantities: the 9-row sum, the four turning rows and
the three trajectory rows (their margins over HC move by the same amount, HC being one fixed rule).

From the pooled standard deviation s it gives:

* ``half_width_3v3``: the expected 95 % half-width of a 3-run-vs-3-run difference (t with 4 degrees
  of freedom, ``s * sqrt(2/3)``): a smaller true difference cannot separate, on average;
* ``runs_per_variant``: for each difference in ``--differences``, the smallest number of runs per
  variant for which a two-sided 5 % t-test (equal variances) detects it with 80 % power, from the
  noncentral t distribution. 2 is the trajectory rows' gap to issue #12's target (HC + 5, shipped
  HC + 3.05), 4.4 the turning rows' (HC + 10, shipped HC + 5.60).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from goal_ceiling import TRAJECTORIES, TURNING  # noqa: E402

from lbgp.files import read_json  # noqa: E402

import numpy as np  # noqa: E402
from scipy import stats  # noqa: E402

QUANTITIES = {"sum": None, "turning": TURNING, "trajectories": TRAJECTORIES}
ALPHA = 0.05
POWER = 0.8


def quantity(per_scenario: dict, rows) -> float:
    """The 9-row sum (``rows`` None) or the sum over the named rows."""
    return float(sum(per_scenario.values()) if rows is None else sum(per_scenario[r] for r in rows))


def variant_groups(files, variants=None) -> dict[str, dict]:
    """``"<file>:<variant>"`` -> {"runs": names, <quantity>: per-run values}, one entry per distinct
    plain variant with 2+ runs, LBGP's or those named in ``variants`` (the same policy files seen
    before: skipped as a repeat)."""
    groups: dict[str, dict] = {}
    seen: set[tuple] = set()
    for path in files:
        data = read_json(path, "ablation_scenarios results")
        if not (isinstance(data, dict) and isinstance(data.get("variants"), dict) and isinstance(data.get("runs"), dict)):
            continue
        for variant, info in sorted(data["variants"].items()):
            names = info.get("runs") or []
            wanted = variant.startswith("LBGP") if variants is None else variant in variants
            if not wanted or "@" in variant or len(names) < 2 or not all(n in data["runs"] for n in names):
                continue
            per_run = [data["runs"][n]["per_scenario"] for n in names]
            key = tuple(str(data["runs"][n].get("policy", f"{path}:{n}")) for n in names)
            if key in seen:
                continue
            seen.add(key)
            groups[f"{Path(path).name}:{variant}"] = {"runs": list(names), **{
                q: [quantity(p, rows) for p in per_run] for q, rows in QUANTITIES.items()}}
    return groups


def pooled_sd(samples: list[list[float]]) -> tuple[float, int]:
    """The pooled standard deviation of several samples (each about its own mean) and its degrees of freedom."""
    ss = sum(float(np.sum((np.asarray(x) - np.mean(x)) ** 2)) for x in samples)
    df = sum(len(x) - 1 for x in samples)
    if df < 1:
        raise ValueError("need at least one sample of 2 or more values")
    return math.sqrt(ss / df), df


def t_test_power(difference: float, sd: float, n: int, alpha: float = ALPHA) -> float:
    """Power of a two-sided two-sample t-test (equal variances, n per group) for a true difference."""
    df = 2 * n - 2
    crit = stats.t.ppf(1 - alpha / 2, df)
    nc = difference / (sd * math.sqrt(2.0 / n))
    return float(stats.nct.sf(crit, df, nc) + stats.nct.cdf(-crit, df, nc))


def runs_needed(difference: float, sd: float, power: float = POWER, alpha: float = ALPHA, most: int = 100_000) -> int:
    """The smallest n per group whose t-test detects ``difference`` with at least ``power``."""
    if not (difference > 0 and sd > 0):
        raise ValueError(f"need a positive difference and standard deviation, got {difference}, {sd}")
    n = 2
    while t_test_power(difference, sd, n, alpha) < power:
        n += 1
        if n > most:
            raise ValueError(f"more than {most} runs per group needed")
    return n


def analyse(files, differences, variants=None) -> dict:
    groups = variant_groups(files, variants)
    if not groups:
        raise ValueError("no ablation_scenarios results with 2+ runs per variant found")
    out = {"groups": groups, "quantities": {}}
    for q in QUANTITIES:
        sd, df = pooled_sd([g[q] for g in groups.values()])
        out["quantities"][q] = {
            "pooled_sd": round(sd, 3), "df": df,
            "half_width_3v3": round(float(stats.t.ppf(1 - ALPHA / 2, 4)) * sd * math.sqrt(2 / 3), 2),
            "runs_per_variant": {f"{d:g}": runs_needed(d, sd) for d in differences},
        }
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--results", default="results", help="folder of committed *.json results (default: results)")
    parser.add_argument("--differences", default="1,2,4.4", help="true differences to detect, comma separated")
    parser.add_argument("--variants", help="pool only these variants, comma separated (default: every LBGP variant)")
    parser.add_argument("--json", help="write the result here")
    args = parser.parse_args(argv)
    try:
        differences = [float(x) for x in args.differences.split(",") if x.strip()]
    except ValueError:
        parser.error(f"--differences takes numbers, got {args.differences!r}")
    if not differences or not all(math.isfinite(d) and d > 0 for d in differences):
        parser.error(f"--differences takes positive numbers, got {args.differences!r}")
    files = sorted(Path(args.results).glob("*.json"))
    try:
        result = {"command": command_line("ablation_power.py", argv), "power": POWER, "alpha": ALPHA,
                  **analyse(files, differences, args.variants.split(",") if args.variants else None)}
    except ValueError as exc:
        parser.error(str(exc))
    if args.json:
        write_result(args.json, result)
    else:
        print(json.dumps(result["quantities"], indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
