"""Where each numeric target of the open issues stands, read from the committed results (no simulation).

    python benchmarks/target_status.py --json results/target_status.json --markdown results/target_status.md
        [--results DIR]   # another results folder laid out as results/ (default: the repository's)

One row per target of the planner issue (#11: speed, smoothness, accuracy, jitter) and the goal-policy
issue (#12: the simulation table's rows and leads, the training levels, the real-world protocol,
safety): the committed value, whether it meets the target, and, where one has been measured, a bound
on what the target's quantity can reach with this planner and reward, read from the file that
measured it:
- the leads over HC and the levels' shares: the best goal sequences found by the hindsight search
  (`benchmarks/goal_ceiling.py`) on noise-free episodes, knowing the person's future. In such a
  deterministic episode every policy's goals are one such sequence, so the best sequence bounds
  every policy there; the search is not exhaustive, so what it found is a low estimate of that
  bound, not a proof (on the turning rows six times the rollouts found 2.1 more);
- the planner's call time: the time spent inside OSQP alone (the Python around it taking none).
Nothing here reruns a measurement: regenerate the files with their own commands (results/README.md)
and run this again. A missing or malformed file is named, and nothing is written.
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402

from lbgp.experiments.sim_table import LEAD_ROWS  # noqa: E402
from lbgp.sim import level_names  # noqa: E402

RESULTS = Path(__file__).resolve().parents[1] / "results"
TURNING, TRAJECTORIES = LEAD_ROWS["turning"], LEAD_ROWS["trajectory"]


class ResultsError(ValueError):
    """A results file is missing or does not hold what this script reads from it."""


def _json(folder: Path, name: str) -> dict:
    path = folder / name
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise ResultsError(f"{path}: missing (made by the command results/README.md gives for it)") from None
    except json.JSONDecodeError as error:
        raise ResultsError(f"{path}: not valid JSON ({error})") from None


def _rows(folder: Path, name: str, columns: tuple[str, ...]) -> list[dict]:
    path = folder / name
    if not path.is_file():
        raise ResultsError(f"{path}: missing (made by the command results/README.md gives for it)")
    with path.open(newline="") as f:
        reader = csv.DictReader(f)
        absent = [c for c in columns if c not in (reader.fieldnames or ())]
        if absent:
            raise ResultsError(f"{path}: has no column {', '.join(absent)}")
        return list(reader)


def _get(data: dict, *keys, source: str):
    for key in keys:
        if not isinstance(data, dict) or key not in data:
            raise ResultsError(f"{source}: has no {'/'.join(keys)}")
        data = data[key]
    return data


def _row(issue, target, value, met, source, bound=None, bound_source=None, note="", beyond=None):
    """``beyond``: whether the target lies past the measured bound (None where there is no bound)."""
    return {"issue": issue, "target": target, "value": value, "met": bool(met), "bound": bound,
            "bound_source": bound_source, "beyond_bound": beyond, "source": source, "note": note}


def _lead_half_width(folder: Path, rows_name: str) -> float | None:
    """The 95 % half-width of LBGP - HC summed over a group of rows, as sim_table.md states it
    (paired by episode; the CSV holds the rows' means only)."""
    path = folder / "sim_table.md"
    if not path.is_file():
        return None
    match = re.search(rf"summed over the {rows_name} rows \([^)]*\): [+-][0-9.]+ ± ([0-9.]+)", path.read_text())
    return float(match.group(1)) if match else None


def simulation_table(folder: Path) -> list[dict]:
    rows = _rows(folder, "sim_table.csv", ("scenario", "method", "reward", "winner_ours"))
    reward = {(r["scenario"], r["method"]): float(r["reward"]) for r in rows}
    winner = {r["scenario"]: r["winner_ours"] for r in rows}
    source = "sim_table.csv"
    for scenario in TURNING + TRAJECTORIES:
        for method in ("lbgp", "hc"):
            if (scenario, method) not in reward:
                raise ResultsError(f"{folder / source}: has no {method} row for {scenario}")
    out = []
    lost = sorted(s for s, w in winner.items() if w not in ("lbgp", "tie"))
    outright = sum(w == "lbgp" for s, w in winner.items() if s != "straight_ahead")
    others = sum(s != "straight_ahead" for s in winner)
    out.append(_row(12, "LBGP wins or ties every row of the simulation table", f"{len(winner) - len(lost)} of {len(winner)}",
                    not lost, source, note=f"lost: {', '.join(lost)}" if lost else ""))
    out.append(_row(12, "LBGP wins outright >= 6 of the rows other than straight_ahead", f"{outright} of {others}",
                    outright >= 6, source))
    ceiling = {"turning": ("goal_ceiling_turning_long.json", "turning"),
               "trajectory": ("goal_ceiling_trajectories_react5.json", "trajectories")}
    for group, scenarios, goal in (("turning", TURNING, 10.0), ("trajectory", TRAJECTORIES, 5.0)):
        lead = sum(reward[(s, "lbgp")] - reward[(s, "hc")] for s in scenarios)
        half = _lead_half_width(folder, group)
        name, key = ceiling[group]
        sums = _get(_json(folder, name), "sums", key, source=name)
        bound = float(_get(sums, "best", source=name)) - float(_get(sums, "hc", source=name))
        kind = ("the best goal sequence found with the person's future known (noise-free)" if group == "turning" else
                "the best goal sequence found that follows LBGP's goals until the person has turned 5 deg (noise-free)")
        out.append(_row(12, f"LBGP - HC summed over the {group} rows >= +{goal:g}",
                        round(lead, 2) if half is None else f"{lead:+.2f} ± {half:.2f}", lead >= goal, source,
                        bound=round(bound, 2), bound_source=name, note=f"bound: {kind}", beyond=goal > bound))
    return out


LEVEL_SEARCH = "goal_ceiling_levels_20.json"  # the hindsight search on the same 20 seeded episodes per level


def training_levels(folder: Path) -> list[dict]:
    name = "levels_vs_ceiling.json"
    lbgp = _get(_json(folder, name), "methods", "lbgp", source=name)
    searched = _get(_json(folder, LEVEL_SEARCH), "levels", source=LEVEL_SEARCH)
    out = []
    for level in level_names():
        share = float(_get(lbgp, level, "share_of_ceiling", source=name))
        found = _get(searched, level, "share_of_ceiling", source=LEVEL_SEARCH)
        bound, noise_free = (float(_get(found, key, source=LEVEL_SEARCH)) for key in ("best_known", "lbgp"))
        out.append(_row(12, f"LBGP's return on the {level} level >= 60 % of its ceiling", f"{share:.0%}", share >= 0.6, name,
                        bound=f"{bound:.0%}", bound_source=LEVEL_SEARCH, beyond=0.6 > bound,
                        note="bound: per episode the best of the goal sequences found with the person's future known, "
                             f"HC and LBGP, on the same seeded episodes noise-free (LBGP there: {noise_free:.0%})"))
    return out


def real_protocol(folder: Path) -> list[dict]:
    rows = _rows(folder, "real_protocol_table.csv", ("path", "setting", "method", "reward"))
    reward = {(r["path"], r["setting"], r["method"]): float(r["reward"]) for r in rows}
    settings = sorted({(p, s) for p, s, _ in reward})
    missing = [f"{p}/{s}" for p, s in settings if (p, s, "lbgp") not in reward or (p, s, "hc") not in reward]
    if missing:
        raise ResultsError(f"{folder / 'real_protocol_table.csv'}: no LBGP or HC row for {', '.join(missing)}")
    at_least = sum(reward[(p, s, "lbgp")] >= reward[(p, s, "hc")] for p, s in settings)
    return [_row(12, "real-world protocol in simulation: LBGP >= HC (mean) in >= 10 of 12 settings",
                 f"{at_least} of {len(settings)}", at_least >= 10, "real_protocol_table.csv")]


def safety(folder: Path) -> list[dict]:
    name = "safety_sweep.json"
    data = _json(folder, name)
    episodes, contacts, loops = (int(_get(data, key, source=name)) for key in ("episodes", "contacts", "loops"))
    return [_row(12, ">= 1,000 seeded episodes with 0 robot-person contacts and 0 loops",
                 f"{episodes} episodes, {contacts} contacts, {loops} loops", episodes >= 1000 and contacts == 0 and loops == 0, name)]


def planner(folder: Path) -> list[dict]:
    bench, env, sweep = (_json(folder, name) for name in ("bench_planner.json", "bench_env.json", "goal_sweep.json"))
    out = []
    for robot in ("jackal", "turtlebot2"):
        def calls(*keys):
            return float(_get(bench, f"{robot}_N20", *keys, source="bench_planner.json"))

        median, p99, osqp_median, osqp_p99 = (calls(*k) for k in (("median_ms",), ("p99_ms",), ("osqp_ms", "median"),
                                                                   ("osqp_ms", "p99")))
        out.append(_row(11, f"{robot}: planner call median <= 0.5 ms (N = 20)", round(median, 2), median <= 0.5, "bench_planner.json",
                        bound=round(osqp_median, 2), bound_source="bench_planner.json", beyond=0.5 < osqp_median,
                        note="bound: the median call's time inside OSQP alone (a lower bound on the call with today's QPs)"))
        out.append(_row(11, f"{robot}: planner call p99 <= 1.5 ms (N = 20)", round(p99, 1), p99 <= 1.5, "bench_planner.json",
                        bound=round(osqp_p99, 1), bound_source="bench_planner.json", note="bound: OSQP's own p99",
                        beyond=1.5 < osqp_p99))
        hits, solves = int(calls("osqp_iteration_cap_hits")), int(calls("qp_solves"))
        out.append(_row(11, f"{robot}: OSQP never stops at its iteration cap", f"{hits} of {solves} QPs", hits == 0,
                        "bench_planner.json"))
        if "accuracy_vs_tight_reference_m" in bench[f"{robot}_N20"]:
            worst, qps = calls("accuracy_vs_tight_reference_m", "max"), int(calls("accuracy_vs_tight_reference_m", "qps"))
            out.append(_row(11, f"{robot}: each QP's step within 1 cm of a tightly solved reference",
                            f"max {worst * 100:.2f} cm over {qps} QPs", worst <= 0.01, "bench_planner.json"))
        goal_rate, raw_rate = (float(_get(env, "robots", robot, key, source="bench_env.json"))
                               for key in ("task_goal_steps_per_s", "raw_mj_step_agent_steps_per_s"))
        share = goal_rate / raw_rate
        out.append(_row(11, f"{robot}: goal-driven env >= 40 % of the raw-physics agent-step rate", f"{share:.1%}", share >= 0.4,
                        "bench_env.json"))

        def summary(key):
            return float(_get(sweep, robot, "summary", key, source="goal_sweep.json"))

        change = summary("largest_neighbour_change_goals_to_1_9")
        out.append(_row(11, f"{robot}: goal sweep, largest reward change between goals 5 cm apart <= 3 (goals up to 1.9 m)",
                        round(change, 2), change <= 3, "goal_sweep.json",
                        note=f"over the whole sweep to 2.2 m: {summary('largest_neighbour_change'):.2f}, where the reward "
                             "itself steps at D = 2 m (docs/planner.md)"))
        lowest = summary("straight_ahead_min_1_2_to_1_8")
        out.append(_row(11, f"{robot}: goal sweep, straight_ahead >= 20 for every goal 1.2-1.8 m ahead", round(lowest, 1),
                        lowest >= 20, "goal_sweep.json"))
        loops = int(summary("loops"))
        out.append(_row(11, f"{robot}: goal sweep, 0 loops", loops, loops == 0, "goal_sweep.json"))
    kept = float(_get(_json(folder, "goal_jitter.json"), "kept", source="goal_jitter.json"))
    out.append(_row(11, "HC with 0.1 m goal jitter keeps >= 90 % of its turning-row reward", f"{kept:.1%}", kept >= 0.9,
                    "goal_jitter.json"))
    return out


def status(folder: Path) -> list[dict]:
    return planner(folder) + simulation_table(folder) + training_levels(folder) + real_protocol(folder) + safety(folder)


def markdown(rows: list[dict], command: str) -> str:
    lines = ["# Where the open issues' targets stand", "",
             "Read from the committed results by `benchmarks/target_status.py` (no simulation); each row names the file it "
             "is read from, and the bound, where one was measured, what the target's quantity can reach with this planner "
             "and reward (see the notes and docs/ceilings.md).", "", f"Made by: `{command}`", "",
             "| issue | target | committed | met | bound | target past the bound | from | note |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        bound = "" if r["bound"] is None else f"{r['bound']} ({r['bound_source']})"
        beyond = {None: "", True: "**yes**", False: "no"}[r["beyond_bound"]]
        lines.append(f"| #{r['issue']} | {r['target']} | {r['value']} | {'yes' if r['met'] else '**no**'} | {bound} | "
                     f"{beyond} | {r['source']} | {r['note']} |")
    missed = [r for r in rows if not r["met"]]
    past = [r for r in missed if r["beyond_bound"]]
    lines += ["", f"{len(rows) - len(missed)} of {len(rows)} targets met; missed: "
              + ("; ".join(f"#{r['issue']} {r['target']}" for r in missed) if missed else "none") + ".",
              "", f"Of the missed ones, {len(past)} lie past their measured bound: "
              + ("; ".join(f"#{r['issue']} {r['target']}" for r in past) if past else "none") + "."]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, default=RESULTS, help="the results folder to read (default: results/)")
    parser.add_argument("--json", help="write the rows here")
    parser.add_argument("--markdown", help="write the table here")
    args = parser.parse_args(argv)
    try:
        rows = status(args.results)
    except ResultsError as error:
        parser.exit(2, f"target_status: {error}\n")
    command = command_line("target_status.py", argv)
    result = {"command": command, "rows": rows, "met": sum(r["met"] for r in rows), "targets": len(rows)}
    if args.markdown:
        path = Path(args.markdown)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(markdown(rows, command))
        tmp.replace(path)
    if args.json:
        write_result(args.json, result)
    else:
        print(markdown(rows, command))
    return result


if __name__ == "__main__":
    main()
