"""What the hardware-like robot's loss is made of: each group of its parameters alone.

    python benchmarks/sim2real_decomposition.py --json results/sim2real_decomposition.json [--episodes 6]

For each method (LBGP, HC) the paper's 9 scenarios on the Jackal (observation noise on, the same
seeds throughout) are run on the nominal robot, on the full hardware-like set, on the hardware-like
set with the command calibration identified from it (``benchmarks/sim2real_gap.py``'s column),
and on the nominal robot with one group of the hardware-like parameters at a time: command latency
(with its jitter), motor lag, firmware acceleration limits, mass and inertia, tyre friction, and
the skid-steer track. Reported: reward summed over the scenarios and the loss against nominal.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from sim2real_gap import identified_calibration  # noqa: E402

from lbgp.dynamics import HARDWARE_LIKE, Dynamics  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402


def groups(robot: str) -> dict[str, Dynamics]:
    hw = HARDWARE_LIKE[robot]
    return {
        "latency": Dynamics(latency=hw.latency, latency_jitter=hw.latency_jitter),
        "lag": Dynamics(time_constant=hw.time_constant),
        "acceleration_limits": Dynamics(max_linear_accel=hw.max_linear_accel, max_angular_accel=hw.max_angular_accel),
        "mass_inertia": Dynamics(mass_scale=hw.mass_scale, inertia_scale=hw.inertia_scale),
        "friction": Dynamics(sliding_friction=hw.sliding_friction, torsional_friction=hw.torsional_friction),
        "track": Dynamics(track_scale=hw.track_scale),
    }


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/sim2real_decomposition.json")
    ap.add_argument("--episodes", type=int, default=6, help="episodes per scenario and dynamics set")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--methods", default="lbgp,hc")
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (default: the 9 paper scenarios)")
    args = ap.parse_args(argv)
    robot = "jackal"
    calibration, _drive_model, identified = identified_calibration(robot)
    runs = {"nominal": ("nominal", None), "hardware_like": ("hardware_like", None),
            "hardware_like_calibrated": ("hardware_like", calibration),
            **{f"only_{name}": (dyn, None) for name, dyn in groups(robot).items()}}
    result = {"command": command_line("sim2real_decomposition.py", argv), "robot": robot,
              "episodes": args.episodes, "calibration": identified, "methods": {}}
    t0 = time.perf_counter()
    for method in args.methods.split(","):
        policy = make_policy(method, robot=robot)
        sums = {}
        for name, (dynamics, cal) in runs.items():
            rows = evaluate(policy, method, args.scenarios.split(","), robot=robot, episodes=args.episodes, seed=args.seed,
                            obs_noise=True, dynamics=dynamics, calibration=cal)
            sums[name] = round(sum(r["reward"] for r in rows), 2)
            print(f"{method} {name}: {sums[name]}", file=sys.stderr, flush=True)
        result["methods"][method] = {"reward": sums, "loss_vs_nominal": {k: round(sums["nominal"] - v, 2) for k, v in sums.items()}}
    result["wall_time_s"] = round(time.perf_counter() - t0, 1)
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
