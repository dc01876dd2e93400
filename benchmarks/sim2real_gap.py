"""Each method's reward on the nominal robot model vs the held-out hardware-like one (lbgp.dynamics).

    python benchmarks/sim2real_gap.py --json results/sim2real_gap.json [--episodes 10] [--repeats 5]
        [--e2e-randomized runs/e2e_rand/policy.pt] [--lbgp-policy FILE] [--methods lbgp,hc,e2e,e2e_randomized]

Two parts, the same seeds for every method and both dynamics:
* the paper's 9 simulation scenarios on the Jackal (``lbgp evaluate``'s episodes, observation noise on);
* the real-world protocol's 12 settings on the TurtleBot 2 through the deploy loop with simulated
  mocap (``lbgp.experiments.real_protocol.run_setting``; Jackal-trained policies zero-shot).

For each method and part: reward summed over scenarios / settings on each dynamics set, and the
share kept on the hardware-like robot. Target (sim2real issue): LBGP keeps >= 85 %.

A third column, ``hardware_like_calibrated``, is the hardware-like robot driven through a command
calibration (``lbgp.calibration``) made the way a user would make it: ``lbgp sysid --excite`` on
that robot (simulated mocap, seed 1), ``lbgp sysid`` on the log, and the identified gains relative
to the simulated robot's. The benchmark runs those two steps itself. An E2E policy
trained with domain randomisation (``lbgp train --method e2e --randomize default``) is reported
beside the shipped one when ``--e2e-randomized`` names it.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.calibration import CommandCalibration  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.experiments.real_protocol import PATHS, SETTINGS, run_setting  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.real.sysid import identify, record_excitation  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402


CALIBRATED = "hardware_like_calibrated"


def identified_calibration(robot: str) -> tuple[CommandCalibration, dict]:
    """Excite the hardware-like robot, identify it, calibrate against the simulated robot's gains."""
    with tempfile.TemporaryDirectory() as folder:
        log = Path(folder) / "excite.mcap"
        record_excitation(robot, log, dynamics="hardware_like", seed=1)
        fit = identify(log, robot)
    calibration = CommandCalibration.from_gains(robot, fit.gain_v, fit.gain_w, f"sysid of the hardware-like {robot}")
    return calibration, {"gain_v": round(fit.gain_v, 4), "gain_w": round(fit.gain_w, 4),
                         "scale_v": round(calibration.scale_v, 4), "scale_w": round(calibration.scale_w, 4)}


def runs_of(calibration: CommandCalibration):
    """(column, dynamics, calibration) for the three columns."""
    return [("nominal", "nominal", None), ("hardware_like", "hardware_like", None), (CALIBRATED, "hardware_like", calibration)]


def scenario_part(policy, method: str, episodes: int, seed: int, calibration: CommandCalibration) -> dict:
    out = {}
    for column, dynamics, cal in runs_of(calibration):
        rows = evaluate(policy, method, scenario_names(), robot="jackal", episodes=episodes, seed=seed, obs_noise=True,
                        dynamics=dynamics, calibration=cal)
        out[column] = {r["scenario"]: round(r["reward"], 3) for r in rows}
    return out


def protocol_part(policy, repeats: int, steps: int, seed: int, calibration: CommandCalibration) -> dict:
    out = {}
    for column, dynamics, cal in runs_of(calibration):
        rewards = {}
        for path in PATHS:
            for setting in SETTINGS[path]:
                runs = [run_setting(policy, path, setting, steps, seed + r, dynamics=dynamics, calibration=cal) for r in range(repeats)]
                rewards[f"{path}/{setting}"] = round(float(np.mean([m.total_reward for m in runs])), 3)
        out[column] = rewards
    return out


def totals(part: dict) -> dict:
    nominal, hardware, calibrated = (sum(part[c].values()) for c in ("nominal", "hardware_like", CALIBRATED))
    return {"nominal": round(nominal, 2), "hardware_like": round(hardware, 2), CALIBRATED: round(calibrated, 2),
            "kept": round(hardware / nominal, 3) if nominal > 0 else None,
            "kept_calibrated": round(calibrated / nominal, 3) if nominal > 0 else None}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/sim2real_gap.json")
    ap.add_argument("--episodes", type=int, default=10, help="episodes per scenario and dynamics set")
    ap.add_argument("--repeats", type=int, default=5, help="runs per protocol setting and dynamics set")
    ap.add_argument("--steps", type=int, default=60, help="agent steps per protocol run")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--e2e-randomized", help="an E2E policy trained with --randomize, reported as e2e_randomized")
    ap.add_argument("--lbgp-policy", help="LBGP policy file (default: the shipped one)")
    ap.add_argument("--methods", default="lbgp,hc,e2e,e2e_randomized",
                    help="comma-separated subset of lbgp,hc,e2e,e2e_randomized (default: all; e2e_randomized needs --e2e-randomized)")
    args = ap.parse_args()

    wanted = [m.strip() for m in args.methods.split(",") if m.strip()]
    unknown = set(wanted) - {"lbgp", "hc", "e2e", "e2e_randomized"}
    if unknown:
        ap.error(f"unknown methods {sorted(unknown)}: use lbgp, hc, e2e, e2e_randomized")
    methods = {"lbgp": args.lbgp_policy, "hc": None, "e2e": None}
    if args.e2e_randomized:
        methods["e2e_randomized"] = args.e2e_randomized
    methods = {name: path for name, path in methods.items() if name in wanted}
    result = {"command": "python benchmarks/sim2real_gap.py " + " ".join(sys.argv[1:]), "episodes": args.episodes,
              "repeats": args.repeats, "methods": {}}
    t0 = time.perf_counter()
    calibrations, identified = {}, {}
    for robot in ("jackal", "turtlebot2"):
        calibrations[robot], identified[robot] = identified_calibration(robot)
    result["calibration"] = identified
    print(f"calibration: {identified}", file=sys.stderr, flush=True)
    for name, path in methods.items():
        method = "e2e" if name.startswith("e2e") else name
        scen = scenario_part(make_policy(method, path, robot="jackal"), method, args.episodes, args.seed, calibrations["jackal"])
        proto = protocol_part(make_policy(method, path, robot="turtlebot2", transfer=True), args.repeats, args.steps, args.seed,
                              calibrations["turtlebot2"])
        result["methods"][name] = {"scenarios": {**totals(scen), "per_scenario": scen},
                                   "real_protocol": {**totals(proto), "per_setting": proto}}
        print(f"{name}: scenarios {totals(scen)}, protocol {totals(proto)}", file=sys.stderr, flush=True)
    result["wall_time_s"] = round(time.perf_counter() - t0, 1)
    if not args.e2e_randomized and "e2e_randomized" in wanted:
        result["e2e_randomized"] = "not run: no randomised E2E policy given (--e2e-randomized)"
    write_result(args.json, result)


if __name__ == "__main__":
    main()
