"""Shared by the benchmark scripts: the command that made a result; write the result as JSON
(creating folders) and print it."""

from __future__ import annotations

import argparse
import json
import os
import sys


def command_line(script: str, argv: list[str] | None = None) -> str:
    """The command that made a result, as results/README.md gives it: ``python benchmarks/NAME.py ARGS``
    (``argv``: the arguments main() was given; default: this process's own)."""
    return f"python benchmarks/{script} " + " ".join(sys.argv[1:] if argv is None else argv)


def planner_changes_arg(text: str) -> dict:
    """``--planner-changes``: NAME=VALUE pairs of ``PlannerConfig`` fields (``"max_vel_x=2.0"``), checked as
    ``lbgp train --set train_planner_changes`` checks them; argparse names the problem otherwise."""
    from lbgp.planner.config import changes_from_text

    try:
        return changes_from_text(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def write_result(path: str, result: dict) -> None:
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = f"{path}.tmp"
    with open(tmp, "w") as f:
        json.dump(result, f, indent=2)
    os.replace(tmp, path)
    print(json.dumps(result, indent=2))


TOP_SPEED_VMAX = 2.0  # m/s: the Jackal's top speed, the levels' ceilings' speed (the bound for any policy on it)


def level_ceilings(path, vmax: float = TOP_SPEED_VMAX) -> dict[str, dict]:
    """The training levels' point-robot ceilings from ``benchmarks/reward_ceiling.py``'s file, at
    top speed ``vmax``, each level's row on the finest grid the file has for it (the closest to the
    continuous bound): ``{level: row}`` with ``mean_bound``, ``mean_bound_starts_in_front_half`` and
    ``..._back_half``. A missing file, or no row at ``vmax``, is a ValueError that says so."""
    from lbgp.files import read_json

    results = read_json(path, "reward ceiling")["results"]
    rows: dict[str, dict] = {}
    for r in results:
        if abs(float(r["vmax"]) - vmax) < 1e-9 and (r["level"] not in rows or r["grid_m"] < rows[r["level"]]["grid_m"]):
            rows[r["level"]] = r
    if not rows:
        speeds = sorted({float(r["vmax"]) for r in results})
        raise ValueError(f"reward ceiling file {path} has no rows at vmax {vmax} m/s (it has {speeds})")
    return rows
