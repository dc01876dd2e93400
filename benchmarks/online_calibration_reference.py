"""The gains ``lbgp.online_calibration.OnlineCalibration`` estimates on the nominal simulated robots:
its reference (``ONLINE_REFERENCE_GAINS``), measured with corrections switched off.

    python benchmarks/online_calibration_reference.py --json results/online_calibration_reference.json [--episodes 5]

HC drives (the goal method with no learned part; the estimate is of the robot, not the policy):
the Jackal over the paper's 9 scenarios (observation noise on, seeded episodes), the TurtleBot 2 over
the real-world protocol's 12 settings through the deploy loop with simulated mocap. Reported per
robot: the last estimate of each episode (v and w gain), their median (the reference) and quartiles.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.experiments.real_protocol import PATHS, SETTINGS, run_setting  # noqa: E402
from lbgp.online_calibration import OnlineCalibration  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.rollout import run_episode  # noqa: E402
from lbgp.sim import make_env, scenario_names  # noqa: E402

MEASURE_ONLY = 1e9  # a dead band no estimate leaves: the commands are never scaled


def summary(gains: list) -> dict:
    g = np.array(gains, dtype=float)
    out = {}
    for i, name in enumerate(("gain_v", "gain_w")):
        x = g[:, i][np.isfinite(g[:, i])]
        out[name] = {"median": round(float(np.median(x)), 3), "q25": round(float(np.quantile(x, 0.25)), 3),
                     "q75": round(float(np.quantile(x, 0.75)), 3), "episodes_with_estimate": int(len(x))}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/online_calibration_reference.json")
    ap.add_argument("--episodes", type=int, default=5, help="episodes per scenario / runs per protocol setting")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    t0 = time.perf_counter()
    result = {"command": "python benchmarks/online_calibration_reference.py " + " ".join(sys.argv[1:]), "robots": {}}
    gains = []
    policy = make_policy("hc", robot="jackal")
    for scenario in scenario_names():
        for e in range(args.episodes):
            calibration = OnlineCalibration("jackal", deadband=MEASURE_ONLY)
            env = make_env(scenario, robot="jackal", seed=args.seed + e, obs_noise=True, calibration=calibration)
            run_episode(env, policy)
            gains.append(list(calibration.gains))
    result["robots"]["jackal"] = {"where": "paper scenarios", **summary(gains)}
    gains = []
    policy = make_policy("hc", robot="turtlebot2", transfer=True)
    for path in PATHS:
        for setting in SETTINGS[path]:
            for e in range(args.episodes):
                calibration = OnlineCalibration("turtlebot2", deadband=MEASURE_ONLY)
                run_setting(policy, path, setting, 60, args.seed + e, calibration=calibration)
                gains.append(list(calibration.gains))
    result["robots"]["turtlebot2"] = {"where": "real-world protocol, simulated mocap", **summary(gains)}
    result["wall_time_s"] = round(time.perf_counter() - t0, 1)
    write_result(args.json, result)


if __name__ == "__main__":
    main()
