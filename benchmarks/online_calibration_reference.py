"""The gains ``lbgp.online_calibration.OnlineCalibration`` estimates on the nominal simulated robots:
its reference (``ONLINE_REFERENCE_GAINS``), measured with corrections switched off.

    python benchmarks/online_calibration_reference.py --json results/online_calibration_reference.json [--episodes 5]

HC drives (the goal method with no learned part; the estimate is of the robot, not the policy):
each robot over the paper's 9 scenarios (observation noise on, seeded episodes) and the TurtleBot 2
also over the real-world protocol's 12 settings through the deploy loop with simulated mocap.
Reported per robot: the last estimate of each episode (v and w gain), their median (the reference),
quartiles and 10th/90th percentiles (how much the gain moves with the manoeuvre: the dead band).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402

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
                     "q75": round(float(np.quantile(x, 0.75)), 3), "q10": round(float(np.quantile(x, 0.1)), 3),
                     "q90": round(float(np.quantile(x, 0.9)), 3), "episodes_with_estimate": int(len(x))}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/online_calibration_reference.json")
    ap.add_argument("--episodes", type=int, default=5, help="episodes per scenario / runs per protocol setting")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    t0 = time.perf_counter()
    result = {"command": command_line("online_calibration_reference.py"), "robots": {}}
    for robot in ("jackal", "turtlebot2"):
        result["robots"][robot] = {"where": "paper scenarios" + (" and real-world protocol (simulated mocap)" if robot == "turtlebot2" else ""),
                                   **summary(scenario_gains(robot, args.episodes, args.seed)
                                             + (protocol_gains(args.episodes, args.seed) if robot == "turtlebot2" else []))}
    result["wall_time_s"] = round(time.perf_counter() - t0, 1)
    write_result(args.json, result)


def scenario_gains(robot: str, episodes: int, seed: int) -> list:
    gains = []
    policy = make_policy("hc", robot=robot, transfer=True)
    for scenario in scenario_names():
        for e in range(episodes):
            calibration = OnlineCalibration(robot, deadband=MEASURE_ONLY)
            env = make_env(scenario, robot=robot, seed=seed + e, obs_noise=True, calibration=calibration)
            run_episode(env, policy)
            gains.append(list(calibration.gains))
    return gains


def protocol_gains(episodes: int, seed: int) -> list:
    gains = []
    policy = make_policy("hc", robot="turtlebot2", transfer=True)
    for path in PATHS:
        for setting in SETTINGS[path]:
            for e in range(episodes):
                calibration = OnlineCalibration("turtlebot2", deadband=MEASURE_ONLY)
                run_setting(policy, path, setting, 60, seed + e, calibration=calibration)
                gains.append(list(calibration.gains))
    return gains


if __name__ == "__main__":
    main()
