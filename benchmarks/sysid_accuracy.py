"""How well ``lbgp sysid`` recovers known dynamics: excitation logs recorded in the simulator with
non-default drive parameters (the deploy loop, mocap noise, 10-30 ms mocap latency and 2 % dropped
frames on), fitted, and compared with the truth.

    python benchmarks/sysid_accuracy.py --json results/sysid_accuracy.json --seeds 0-5 --jobs 2

Grid: both robots; command latency 0.1 s; lag (time constant) 0.1 / 0.15 / 0.25 s; an angular
limiter of 2.0 rad/s^2; with and without a linear limiter (TurtleBot 2 0.5 m/s^2, the Kobuki's;
Jackal 2.0 m/s^2); each seed a different mocap noise, latency and drop pattern. Reported per fit:
the fitted latency, lag, limiters and gains, the lag's relative error, and per robot how many fits
have the lag within 10 % and the limiters' ranges. The latency is expected above 0.1 s by the mocap
delay the log sees (docs/deploy.md, "What the fit can and cannot do").
"""

from __future__ import annotations

import argparse
import itertools
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.dynamics import nominal  # noqa: E402
from lbgp.real.sysid import identify, record_excitation  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402

LATENCY = 0.1
LAGS = (0.1, 0.15, 0.25)
ANGULAR_LIMIT = 2.0
LINEAR_LIMIT = {"turtlebot2": 0.5, "jackal": 2.0}


def one_fit(job: tuple) -> dict:
    robot, lag, linear, seed = job
    dynamics = nominal(robot).replace(latency=LATENCY, time_constant=lag, max_angular_accel=ANGULAR_LIMIT)
    if linear:
        dynamics = dynamics.replace(max_linear_accel=LINEAR_LIMIT[robot])
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "excite.mcap"
        record_excitation(robot, path, dynamics=dynamics, seed=seed)
        fitted = identify(path, robot)
    return {"robot": robot, "lag": lag, "linear_limit": LINEAR_LIMIT[robot] if linear else None, "seed": seed,
            "fit": fitted.summary(), "lag_error": fitted.time_constant / lag - 1.0, "pose_topic": fitted.pose_topic}


def summarise(fits: list[dict]) -> dict:
    out = {}
    for robot in sorted({f["robot"] for f in fits}):
        mine = [f for f in fits if f["robot"] == robot]
        errors = [f["lag_error"] for f in mine]
        angular = [f["fit"]["max_angular_accel"] for f in mine]
        linear = [f["fit"]["max_linear_accel"] for f in mine if f["linear_limit"] is not None]
        spurious = [f["fit"]["max_linear_accel"] for f in mine if f["linear_limit"] is None and f["fit"]["max_linear_accel"] is not None]
        out[robot] = {
            "fits": len(mine),
            "lag_within_10_percent": sum(1 for e in errors if abs(e) <= 0.1),
            "lag_error_min": min(errors), "lag_error_max": max(errors),
            "latency_range_s": [min(f["fit"]["latency_s"] for f in mine), max(f["fit"]["latency_s"] for f in mine)],
            "angular_limit_range": [min(a for a in angular if a is not None), max(a for a in angular if a is not None)] if any(angular) else None,
            "angular_limit_missed": sum(1 for a in angular if a is None),
            "linear_limit_range": [min(a for a in linear if a is not None), max(a for a in linear if a is not None)] if any(linear) else None,
            "linear_limit_missed": sum(1 for a in linear if a is None),
            "linear_limit_where_none": len(spurious),
        }
    return out


def parse_seeds(text: str) -> list[int]:
    if "-" in text:
        low, high = (int(x) for x in text.split("-"))
        return list(range(low, high + 1))
    return [int(x) for x in text.split(",")]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", required=True)
    ap.add_argument("--seeds", default="0-2", help="e.g. 0-5 or 0,3")
    ap.add_argument("--robots", default="turtlebot2,jackal")
    ap.add_argument("--jobs", type=int, default=1, help="fits in parallel processes (one core each)")
    args = ap.parse_args()
    jobs = list(itertools.product(args.robots.split(","), LAGS, (False, True), parse_seeds(args.seeds)))
    start = time.time()
    if args.jobs > 1:
        with process_pool(args.jobs) as pool:
            fits = list(pool.map(one_fit, jobs))
    else:
        fits = [one_fit(job) for job in jobs]
    write_result(args.json, {"benchmark": "sysid_accuracy", "command": "python " + " ".join(sys.argv),
                             "true": {"latency_s": LATENCY, "lags_s": LAGS, "angular_limit": ANGULAR_LIMIT, "linear_limit": LINEAR_LIMIT},
                             "summary": summarise(fits), "fits": fits, "wall_time_s": round(time.time() - start, 1)})


if __name__ == "__main__":
    main()
