"""Each method's reward on the nominal robot model vs the held-out hardware-like one (lbgp.dynamics).

    python benchmarks/sim2real_gap.py --json results/sim2real_gap.json [--episodes 10] [--repeats 5]
        [--e2e-randomized runs/e2e_rand/policy.pt] [--lbgp-policy FILE] [--methods lbgp,hc,e2e,e2e_randomized] [--jobs 2]
        [--update]

Two parts, the same seeds for every method and both dynamics:
* the paper's 9 simulation scenarios on the Jackal (``lbgp evaluate``'s episodes, observation noise on);
* the real-world protocol's 12 settings on the TurtleBot 2 through the deploy loop with simulated
  mocap (``lbgp.experiments.real_protocol.run_setting``; Jackal-trained policies zero-shot).

For each method and part: reward summed over scenarios / settings on each dynamics set, and the
share kept on the hardware-like robot. Target (sim2real issue): LBGP keeps >= 85 %.

A third column, ``hardware_like_calibrated``, is the hardware-like robot driven through a command
calibration (``lbgp.calibration``) made the way a user would make it: ``lbgp sysid --excite`` on
that robot (simulated mocap, seed 1), ``lbgp sysid`` on the log, and the identified gains relative
to the simulated robot's. The benchmark runs those two steps itself. Two more, ``nominal_online``
and ``hardware_like_online``, drive through the online calibration (``--calibration online``,
``lbgp.online_calibration``): no identification run; one estimator per robot and column, carried
from run to run in the order below (the first episode starts from nothing), as one robot doing
every run would keep what it learned. One more, ``hardware_like_model``, uses everything the same
identification gives: the sysid calibration and the fitted dynamics as the planner's drive model
(``--drive-model``, ``lbgp.drive_model``: plan within the identified acceleration limits from the
state predicted one latency ahead). ``hardware_like_model_only`` is the drive model without the
calibration. An E2E policy sends its own commands, so for E2E those two columns only repeat the
calibrated and the uncalibrated one's conditions. An E2E policy
trained with domain randomisation (``lbgp train --method e2e --randomize default``) is reported
beside the shipped one when ``--e2e-randomized`` names it.

``--update`` reruns only ``--methods`` and keeps the other methods' entries of the existing JSON
(each entry names the command that made it).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402

from lbgp.calibration import CommandCalibration  # noqa: E402
from lbgp.dynamics import Dynamics  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.metrics import reward_ci95  # noqa: E402
from lbgp.online_calibration import OnlineCalibration  # noqa: E402
from lbgp.experiments.real_protocol import PATHS, SETTINGS, run_setting  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.real.sysid import identify, record_excitation  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402


CALIBRATED = "hardware_like_calibrated"
ONLINE = ("nominal_online", "hardware_like_online")
MODEL = "hardware_like_model"
MODEL_ONLY = "hardware_like_model_only"
COLUMNS = ("nominal", "hardware_like", CALIBRATED, *ONLINE, MODEL, MODEL_ONLY)


def identified_calibration(robot: str) -> tuple[CommandCalibration, Dynamics, dict]:
    """Excite the hardware-like robot, identify it, calibrate against the simulated robot's gains;
    the calibration, the fitted dynamics (the drive model) and a summary."""
    with tempfile.TemporaryDirectory() as folder:
        log = Path(folder) / "excite.mcap"
        record_excitation(robot, log, dynamics="hardware_like", seed=1)
        fit = identify(log, robot)
    calibration = CommandCalibration.from_gains(robot, fit.gain_v, fit.gain_w, f"sysid of the hardware-like {robot}")
    return calibration, fit.dynamics, {"gain_v": round(fit.gain_v, 4), "gain_w": round(fit.gain_w, 4),
                                       "scale_v": round(calibration.scale_v, 4), "scale_w": round(calibration.scale_w, 4),
                                       "drive_model": {k: v for k, v in fit.summary().items() if k not in ("gain_v", "gain_w")}}


def runs_of(identified: tuple, robot: str):
    """(column, dynamics, calibration, drive model) for the seven columns (a fresh online estimator for each)."""
    calibration, drive_model = identified
    return [("nominal", "nominal", None, None), ("hardware_like", "hardware_like", None, None),
            (CALIBRATED, "hardware_like", calibration, None),
            ("nominal_online", "nominal", OnlineCalibration(robot), None),
            ("hardware_like_online", "hardware_like", OnlineCalibration(robot), None),
            (MODEL, "hardware_like", calibration, drive_model),
            (MODEL_ONLY, "hardware_like", None, drive_model)]


def scenario_part(policy, method: str, episodes: int, seed: int, identified: tuple) -> tuple[dict, dict]:
    """Per column: each scenario's mean reward, and the half-width of its 95 % interval."""
    means, half_widths = {}, {}
    for column, dynamics, cal, model in runs_of(identified, "jackal"):
        rows = evaluate(policy, method, scenario_names(), robot="jackal", episodes=episodes, seed=seed, obs_noise=True,
                        dynamics=dynamics, calibration=cal, drive_model=model)
        means[column] = {r["scenario"]: round(r["reward"], 3) for r in rows}
        half_widths[column] = {r["scenario"]: round(r["reward_ci95"], 3) for r in rows}
    return means, half_widths


def protocol_part(policy, repeats: int, steps: int, seed: int, identified: tuple) -> tuple[dict, dict]:
    """Per column: each setting's mean reward over ``repeats`` runs, and its 95 % half-width."""
    means, half_widths = {}, {}
    for column, dynamics, cal, model in runs_of(identified, "turtlebot2"):
        means[column], half_widths[column] = {}, {}
        for path in PATHS:
            for setting in SETTINGS[path]:
                runs = [run_setting(policy, path, setting, steps, seed + r, dynamics=dynamics, calibration=cal, drive_model=model)
                        for r in range(repeats)]
                rewards = [m.total_reward for m in runs]
                means[column][f"{path}/{setting}"] = round(float(np.mean(rewards)), 3)
                half_widths[column][f"{path}/{setting}"] = round(reward_ci95(rewards), 3)
    return means, half_widths


def totals(part: dict, half_widths: dict) -> dict:
    """Each column's sum with the half-width of its 95 % interval (the rows' combined in quadrature),
    and the share of the nominal robot's kept on the hardware-like one: ``kept`` (no calibration),
    ``kept_calibrated`` (sysid's), ``kept_online`` (online, against the nominal robot driven through
    the online calibration too), ``kept_model`` (sysid's calibration and drive model),
    ``kept_model_only`` (sysid's drive model, no calibration), each with a 95 % half-width (``*_ci95``: the two sums' relative
    half-widths in quadrature; conservative, as both columns run the same seeds)."""
    sums = {c: sum(part[c].values()) for c in COLUMNS}
    hw = {c: math.sqrt(sum(h**2 for h in half_widths[c].values())) for c in COLUMNS}
    out = {**{c: round(v, 2) for c, v in sums.items()}, "ci95": {c: round(h, 2) for c, h in hw.items()}}
    for name, a, b in (("kept", "hardware_like", "nominal"), ("kept_calibrated", CALIBRATED, "nominal"),
                       ("kept_online", "hardware_like_online", "nominal_online"), ("kept_model", MODEL, "nominal"),
                       ("kept_model_only", MODEL_ONLY, "nominal")):
        if sums[b] > 0 and sums[a] != 0:
            ratio = sums[a] / sums[b]
            out[name] = round(ratio, 3)
            out[f"{name}_ci95"] = round(abs(ratio) * math.hypot(hw[a] / sums[a], hw[b] / sums[b]), 3)
        else:
            out[name] = out[f"{name}_ci95"] = None
    return out


def method_result(job) -> tuple[str, dict]:
    """Both parts for one method (a process of its own with ``--jobs``)."""
    name, path, args, identified = job
    method = "e2e" if name.startswith("e2e") else name
    scen, scen_hw = scenario_part(make_policy(method, path, robot="jackal"), method, args.episodes, args.seed, identified["jackal"])
    proto, proto_hw = protocol_part(make_policy(method, path, robot="turtlebot2", transfer=True), args.repeats, args.steps,
                                    args.seed, identified["turtlebot2"])
    scen_totals, proto_totals = totals(scen, scen_hw), totals(proto, proto_hw)
    print(f"{name}: scenarios {scen_totals}, protocol {proto_totals}", file=sys.stderr, flush=True)
    return name, {"command": args.command, "scenarios": {**scen_totals, "per_scenario": scen, "per_scenario_ci95": scen_hw},
                  "real_protocol": {**proto_totals, "per_setting": proto, "per_setting_ci95": proto_hw}}


def carried_over(earlier: dict, rerun) -> dict:
    """``--update``: the methods of an earlier result not in ``rerun``, each naming the command that
    made it (an entry without one was made by the earlier file's command)."""
    return {name: {**entry, "command": entry.get("command", earlier.get("command"))}
            for name, entry in earlier.get("methods", {}).items() if name not in rerun}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default="results/sim2real_gap.json")
    ap.add_argument("--episodes", type=int, default=10, help="episodes per scenario and dynamics set")
    ap.add_argument("--repeats", type=int, default=5, help="runs per protocol setting and dynamics set")
    ap.add_argument("--steps", type=int, default=60, help="agent steps per protocol run")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--e2e-randomized", help="an E2E policy trained with --randomize, reported as e2e_randomized")
    ap.add_argument("--jobs", type=int, default=1, help="methods run in parallel processes (one core each)")
    ap.add_argument("--lbgp-policy", help="LBGP policy file (default: the shipped one)")
    ap.add_argument("--methods", default="lbgp,hc,e2e,e2e_randomized",
                    help="comma-separated subset of lbgp,hc,e2e,e2e_randomized (default: all; e2e_randomized needs --e2e-randomized)")
    ap.add_argument("--update", action="store_true", help="keep the other methods' entries of the existing --json file")
    args = ap.parse_args()
    args.command = command_line("sim2real_gap.py")

    wanted = [m.strip() for m in args.methods.split(",") if m.strip()]
    unknown = set(wanted) - {"lbgp", "hc", "e2e", "e2e_randomized"}
    if unknown:
        ap.error(f"unknown methods {sorted(unknown)}: use lbgp, hc, e2e, e2e_randomized")
    methods = {"lbgp": args.lbgp_policy, "hc": None, "e2e": None}
    if args.e2e_randomized:
        methods["e2e_randomized"] = args.e2e_randomized
    methods = {name: path for name, path in methods.items() if name in wanted}
    result = {"command": args.command, "episodes": args.episodes, "repeats": args.repeats, "methods": {}}
    if args.update and Path(args.json).is_file():
        result["methods"].update(carried_over(json.loads(Path(args.json).read_text()), methods))
    t0 = time.perf_counter()
    identified, summaries = {}, {}
    for robot in ("jackal", "turtlebot2"):
        calibration, drive_model, summaries[robot] = identified_calibration(robot)
        identified[robot] = (calibration, drive_model)
    result["calibration"] = summaries
    print(f"calibration: {summaries}", file=sys.stderr, flush=True)
    jobs = [(name, path, args, identified) for name, path in methods.items()]
    if args.jobs > 1:
        with process_pool(min(args.jobs, len(jobs))) as pool:
            done = list(pool.map(method_result, jobs))
    else:
        done = [method_result(job) for job in jobs]
    for name, entry in done:
        result["methods"][name] = entry
    result["wall_time_s"] = round(time.perf_counter() - t0, 1)
    if not args.e2e_randomized and "e2e_randomized" in wanted and "e2e_randomized" not in result["methods"]:
        result["e2e_randomized"] = "not run: no randomised E2E policy given (--e2e-randomized)"
    write_result(args.json, result)


if __name__ == "__main__":
    main()
