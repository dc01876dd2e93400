"""``lbgp experiment sim``: the paper's simulation table, the 9 settings x 3 methods (Jackal).

Every method runs the same seeded episodes of each scenario (``lbgp evaluate`` underneath, 20 by
default, with the paper's observation noise); the table puts the paper's numbers beside ours, each
row's reward ceiling (``lbgp.experiments.ceiling``) and each method's share of it, and names the
winner per row by accumulated reward only where the 95 % confidence intervals separate ("tie"
otherwise), and LBGP's lead over HC summed over the turning rows and over the trajectory rows with
its 95 % interval, paired by episode (``LEAD_ROWS``).
One PNG per scenario shows the first episode of each method from above.
"""

from __future__ import annotations

from pathlib import Path

from lbgp.evaluate import evaluate
from lbgp.experiments.ceiling import scenario_ceiling
from lbgp.planner import planner_config_for
from lbgp.experiments import paper
from lbgp.experiments.tables import write_tables
from lbgp.policies import make_policy
from lbgp.sim.tasks import SCENARIOS
from lbgp.stack import planner_notes
from lbgp.viz.trajectory_plot import TrajectoryCollector, plot_trajectories

METHODS = ("lbgp", "hc", "e2e")
# the rows over which LBGP's lead over HC is reported summed, with its interval paired by episode
# (docs/training.md: where a learned goal can anticipate what a constant one cannot)
LEAD_ROWS = {
    "turning": ("turning_ahead", "turning_behind", "turning_inside", "turning_outside"),
    "trajectory": ("trajectory_one", "trajectory_two", "trajectory_three"),
}


def run_sim_table(out_dir="results", episodes: int = 20, seed: int = 0, scenarios=None, methods=METHODS, policies=None,
                  horizon: int = 35, command: str = "", obs_noise: bool = True) -> list[dict]:
    """Evaluate, write ``sim_table.md``, ``sim_table.csv`` and ``figures/sim_<scenario>.png``; returns the rows."""
    out_dir = Path(out_dir)
    scenarios = list(scenarios or SCENARIOS)
    policies = policies or {}
    rows, pictures = [], {s: {} for s in scenarios}
    loaded = {method: make_policy(method, policies.get(method)) for method in methods}
    for method, policy in loaded.items():
        for k, name in enumerate(scenarios):
            collector = TrajectoryCollector()
            # the seed depends on the scenario only, so that all methods face the same episodes
            (row,) = evaluate(policy, method, [name], robot="jackal", episodes=episodes, seed=seed + 1000 * k,
                              recorder=collector, horizon=horizon, obs_noise=obs_noise)
            rows.append(row)
            pictures[name][method.upper()] = collector.episodes[0]
    for name, panels in pictures.items():
        plot_trajectories(panels, out_dir / "figures" / f"sim_{name}.png", title=f"{name} (Jackal, first seeded episode)")
    vmax = planner_config_for("jackal").max_vel_x
    ceilings = {name: scenario_ceiling(name, vmax, steps=horizon) for name in scenarios}
    preamble = (f"Jackal, {episodes} seeded episodes of {horizon} agent steps (0.2 s) per scenario and method, the same "
                f"episodes (seeds) for every method, observation noise {'on (the paper' + chr(39) + 's)' if obs_noise else 'off'}. "
                f"D in m, alpha in degrees (0 = straight in front), reward = mean accumulated reward per episode with the "
                f"half-width of its 95 % confidence interval (the paper's episodes are longer, so compare rankings, not "
                f"absolute rewards). Ceiling: the best return of a relaxed point robot at the planner's {vmax} m/s from the "
                f"scenario's start (lbgp.experiments.ceiling), an upper bound for any method.\n\n"
                + planner_notes(loaded, "jackal")  # evaluate drives the planner a policy was trained on
                + f"Made by: `{command or 'lbgp experiment sim'}`")
    write_tables(rows, ["scenario"], paper.SIM, out_dir / "sim_table.md", out_dir / "sim_table.csv",
                 "Simulation experiment (paper Table: simulation metrics)", preamble, ceilings=ceilings, leads=LEAD_ROWS)
    return rows
