"""``lbgp experiment real-protocol``: the paper's real-world protocol, run in simulation.

The TurtleBot 2 model, the policy trained on the Jackal (zero-shot, as in the paper), and the very
deployment loop of ``lbgp deploy`` (``lbgp.real``) fed by a simulated motion-capture system with
its disturbances (``MocapDisturbance``: a few mm / 0.5 deg of pose noise, 10-30 ms latency,
2 % dropped frames). Person paths: Straight (7 m), S-shape (7 m long, 0.8 m amplitude) and U-turn
(3 m out, a 1 m radius turn to the right, 3 m back), walked at 0.5 m/s. Each path with the
paper's four initial settings; a constant number of agent steps per setting; a run ends early on
contact or when D > 3 m (the paper's rule).

Angles: the paper gives "Ahead-right" as alpha = +45 deg, i.e. its alpha is positive to the
person's right; ours is positive to the left (docs/architecture.md), so the settings below are
the paper's with the sign of alpha flipped.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from lbgp.calibration import load_calibration
from lbgp.drive_model import load_drive_model
from lbgp.experiments import paper
from lbgp.experiments.tables import write_tables
from lbgp.metrics import aggregate
from lbgp.parallel import process_pool
from lbgp.policies import make_policy
from lbgp.real.loop import DeployConfig, DeployLoop
from lbgp.real.sim_world import MocapDisturbance, SimCommandSink, SimPoseSource, SimWorld
from lbgp.stack import planner_notes
from lbgp.viz.trajectory_plot import TrajectoryCollector, plot_trajectories

METHODS = ("lbgp", "hc", "e2e")
END_DISTANCE = 3.0  # m (the paper's real-world termination)


def _straight() -> np.ndarray:
    return np.stack([np.linspace(0, 7, 71), np.zeros(71)], axis=1)


def _s_shape() -> np.ndarray:
    x = np.linspace(0, 7, 141)
    return np.stack([x, 0.8 * np.sin(2 * math.pi * x / 7)], axis=1)


def _u_turn() -> np.ndarray:
    out = np.stack([np.linspace(0, 3, 31), np.zeros(31)], axis=1)
    a = np.linspace(math.pi / 2, -math.pi / 2, 32)[1:-1]  # turning right: centre at (3, -1)
    turn = np.stack([3 + np.cos(a), -1 + np.sin(a)], axis=1)
    back = np.stack([np.linspace(3, 0, 31), np.full(31, -2.0)], axis=1)
    return np.concatenate([out, turn, back])


PATHS = {"straight": _straight, "s_shape": _s_shape, "u_turn": _u_turn}
# (D m, alpha deg in our convention: + = person's left)
SETTINGS = {
    "straight": {"ahead": (2.0, 0.0), "ahead_right": (1.5, -45.0), "ahead_left": (1.5, 45.0), "behind": (1.2, 180.0)},
    "s_shape": {"ahead": (2.0, 0.0), "ahead_right": (1.5, -45.0), "ahead_left": (1.5, 45.0), "behind": (1.2, 180.0)},
    "u_turn": {"ahead": (1.7, 0.0), "ahead_left": (2.0, 55.0), "ahead_far_left": (3.6, 75.0), "behind": (1.2, 180.0)},
}


DYNAMICS_SETS = ("nominal", "hardware_like")  # lbgp.dynamics: the trained-on model and the held-out "real" one


def protocol_loop(policy, path: str, setting: str, steps: int, seed: int = 0, disturbance=None, collector=None, dynamics=None,
                  calibration=None, drive_model=None, keep_records: bool = False) -> DeployLoop:
    """One run of the protocol, set up and not yet run: the deployment loop on a simulated TurtleBot 2
    with simulated mocap. ``calibration``: the command calibration (``lbgp.calibration``) of the deploy
    loop; ``drive_model``: its planner's model of the drive (``lbgp.drive_model``); ``keep_records``:
    keep every tick's record (``loop.records``)."""
    world = SimWorld(robot="turtlebot2", seed=seed, person_path=PATHS[path](), spawn=SETTINGS[path][setting], dynamics=dynamics)
    source = SimPoseSource(world, disturbance if disturbance is not None else MocapDisturbance(), seed=seed)
    config = DeployConfig(robot="turtlebot2", max_steps=steps, end_distance=END_DISTANCE,
                          calibration=load_calibration(calibration, "turtlebot2"),
                          drive_model=load_drive_model(drive_model, "turtlebot2"))
    return DeployLoop(source, SimCommandSink(world), policy, config,
                      recorder=collector, end_condition=lambda: "contact" if world.contact else None, keep_records=keep_records,
                      name=f"{path}/{setting}")


def run_setting(policy, path: str, setting: str, steps: int, seed: int = 0, **kwargs):
    """One run of the protocol through the deployment loop (``protocol_loop``'s options); returns its
    EpisodeMetrics."""
    return protocol_loop(policy, path, setting, steps, seed, **kwargs).run()


def method_rows(dynamics: str, method: str, policy_file=None, paths=None, steps: int = 60, seed: int = 0,
                repeats: int = 1) -> tuple[list[dict], dict]:
    """Every setting of ``paths`` for one method on one dynamics set: the table rows, and the first
    run of each setting for the figures (``{path: {setting: episode}}``)."""
    policy = make_policy(method, policy_file, robot="turtlebot2", transfer=True)  # the paper: zero-shot
    rows, pictures = [], {}
    for path in paths or PATHS:
        for setting in SETTINGS[path]:
            collector = TrajectoryCollector()
            runs = [run_setting(policy, path, setting, steps, seed + r, collector=collector, dynamics=dynamics)
                    for r in range(repeats)]
            rows.append({"path": path, "setting": setting, "method": method, "dynamics": dynamics, **aggregate(runs)})
            pictures.setdefault(path, {})[setting] = collector.episodes[0]
    return rows, pictures


def run_real_protocol(out_dir="results", steps: int = 60, seed: int = 0, methods=METHODS, paths=None, policies=None,
                      repeats: int = 1, command: str = "", dynamics_sets=DYNAMICS_SETS, jobs: int = 1) -> list[dict]:
    """The protocol on each dynamics set (nominal: real_protocol_table.md; hardware_like:
    real_protocol_hardware_table.md) and each method's sim-to-real loss (real_protocol_gap.md).
    ``jobs`` > 1 runs the (dynamics set, method) pairs in that many processes: the same runs, the
    same numbers."""
    out_dir = Path(out_dir)
    policies = policies or {}
    paths = list(paths or PATHS)
    unknown = [p for p in paths if p not in PATHS]
    if unknown:
        raise ValueError(f"unknown protocol path {', '.join(map(repr, unknown))}; use {', '.join(PATHS)}")
    bad = [d for d in dynamics_sets if d not in DYNAMICS_SETS]
    if bad or not dynamics_sets:
        raise ValueError(f"unknown dynamics set(s) {bad}; use {', '.join(DYNAMICS_SETS)}")
    work = [(dynamics, method, policies.get(method), paths, steps, seed, repeats) for dynamics in dynamics_sets for method in methods]
    # the deploy loop drives the planner a policy was trained on (said in the tables)
    notes = planner_notes({m: make_policy(m, policies.get(m), robot="turtlebot2", transfer=True) for m in methods}, "turtlebot2")
    if jobs > 1:
        with process_pool(min(jobs, len(work))) as pool:
            done = list(pool.map(method_rows, *zip(*work)))
    else:
        done = [method_rows(*job) for job in work]
    all_rows = {}
    for dynamics in dynamics_sets:
        results = {job[1]: result for job, result in zip(work, done) if job[0] == dynamics}  # method -> (rows, pictures)
        rows = [row for rows_of_method, _ in results.values() for row in rows_of_method]
        all_rows[dynamics] = rows
        suffix = "" if dynamics == "nominal" else "_hardware"
        for path in paths:
            for setting in SETTINGS[path]:
                panels = {method.upper(): pictures[path][setting] for method, (_, pictures) in results.items()}
                plot_trajectories(panels, out_dir / "figures" / f"real_protocol{suffix}_{path}_{setting}.png",
                                  title=f"{path}, {setting} (TurtleBot 2, {dynamics} dynamics, simulated mocap)")
        robot_words = ("the nominal TurtleBot 2 model (the dynamics the simulator trains on)" if dynamics == "nominal" else
                       "the held-out hardware-like TurtleBot 2 (lbgp.dynamics.HARDWARE_LIKE: 0.1 s command latency + up to "
                       "20 ms jitter, 0.12 s motor lag, the Kobuki firmware's 0.5 m/s^2 / 3.5 rad/s^2 limiter, 1.3 x mass "
                       "and inertia, wheel friction 0.6)")
        preamble = (f"The paper's real-world protocol in simulation on {robot_words}: Jackal-trained policies zero-shot, the "
                    f"`lbgp deploy` loop with simulated mocap (noise, 10-30 ms latency, 2 % dropped frames), {steps} agent steps "
                    f"per setting unless it ends early on contact or D > {END_DISTANCE} m, {repeats} run(s) per setting. "
                    f"Paper numbers are from a real TurtleBot 2; their rows are mapped to settings by the order in the text "
                    f"(see lbgp/experiments/paper.py for the caveat).\n\n{notes}Made by: "
                    f"`{command or 'lbgp experiment real-protocol --robot turtlebot2'}`")
        title = "Real-world protocol in simulation (paper Tables: straight, S shape, U-turn)"
        write_tables(rows, ["path", "setting"], paper.REAL, out_dir / f"real_protocol{suffix}_table.md",
                     out_dir / f"real_protocol{suffix}_table.csv", title + ("" if dynamics == "nominal" else ", hardware-like robot"),
                     preamble)
    if len(all_rows) == 2:
        write_gap_table(all_rows["nominal"], all_rows["hardware_like"], out_dir / "real_protocol_gap.md", command)
    return [r for rows in all_rows.values() for r in rows]


def gap_summary(nominal_rows: list[dict], hardware_rows: list[dict]) -> dict:
    """Per method: reward summed over the settings on each dynamics set, and the share kept."""
    out = {}
    for method in dict.fromkeys(r["method"] for r in nominal_rows):
        nom = sum(r["reward"] for r in nominal_rows if r["method"] == method)
        hw = sum(r["reward"] for r in hardware_rows if r["method"] == method)
        wins = sum(1 for a in hardware_rows if a["method"] == method
                   and all(a["reward"] >= b["reward"] for b in hardware_rows if (b["path"], b["setting"]) == (a["path"], a["setting"])))
        out[method] = {"nominal": nom, "hardware_like": hw, "kept": hw / nom if nom > 0 else math.nan, "best_settings_hardware": wins}
    return out


def write_gap_table(nominal_rows, hardware_rows, path: Path, command: str = "") -> None:
    from lbgp.files import write_text

    lines = ["# Sim-to-real loss in the real-world protocol", "",
             "Reward summed over the protocol's settings, on the nominal TurtleBot 2 and on the held-out hardware-like one "
             "(see real_protocol_hardware_table.md); kept = hardware-like / nominal (meaningful where the nominal sum is "
             "positive); best settings = settings where the method has the highest mean reward on the hardware-like robot.",
             "", f"Made by: `{command or 'lbgp experiment real-protocol --robot turtlebot2'}`", "",
             "| method | nominal | hardware-like | kept | best settings (hardware-like) |", "|---|---|---|---|---|"]
    for method, g in gap_summary(nominal_rows, hardware_rows).items():
        kept = "" if math.isnan(g["kept"]) else f"{g['kept']:.0%}"
        lines.append(f"| {method.upper()} | {g['nominal']:.1f} | {g['hardware_like']:.1f} | {kept} | {g['best_settings_hardware']} |")
    write_text(path, "\n".join(lines) + "\n")
