"""``lbgp experiment sim``: the paper's simulation table, the 9 settings x 3 methods (Jackal).

Every method runs the same seeded episodes of each scenario (``lbgp evaluate`` underneath); the
table puts the paper's numbers beside ours and names the winner per row by accumulated reward.
One PNG per scenario shows the first episode of each method from above.
"""

from __future__ import annotations

from pathlib import Path

from lbgp.evaluate import evaluate
from lbgp.experiments import paper
from lbgp.experiments.tables import write_tables
from lbgp.policies import make_policy
from lbgp.sim.tasks import SCENARIOS
from lbgp.viz.trajectory_plot import TrajectoryCollector, plot_trajectories

METHODS = ("lbgp", "hc", "e2e")


def run_sim_table(out_dir="results", episodes: int = 5, seed: int = 0, scenarios=None, methods=METHODS, policies=None,
                  horizon: int = 35, command: str = "") -> list[dict]:
    """Evaluate, write ``sim_table.md``, ``sim_table.csv`` and ``figures/sim_<scenario>.png``; returns the rows."""
    out_dir = Path(out_dir)
    scenarios = list(scenarios or SCENARIOS)
    policies = policies or {}
    rows, pictures = [], {s: {} for s in scenarios}
    for method in methods:
        policy = make_policy(method, policies.get(method))
        for k, name in enumerate(scenarios):
            collector = TrajectoryCollector()
            # the seed depends on the scenario only, so that all methods face the same episodes
            (row,) = evaluate(policy, method, [name], robot="jackal", episodes=episodes, seed=seed + 1000 * k,
                              recorder=collector, horizon=horizon)
            rows.append(row)
            pictures[name][method.upper()] = collector.episodes[0]
    for name, panels in pictures.items():
        plot_trajectories(panels, out_dir / "figures" / f"sim_{name}.png", title=f"{name} (Jackal, first seeded episode)")
    preamble = (f"Jackal, {episodes} seeded episodes of {horizon} agent steps (0.2 s) per scenario and method, the same "
                f"episodes for every method. D in m, alpha in degrees (0 = straight in front), reward = mean accumulated "
                f"reward per episode (the paper's episodes are longer, so compare rankings, not absolute rewards).\n\n"
                f"Made by: `{command or 'lbgp experiment sim'}`")
    write_tables(rows, ["scenario"], paper.SIM, out_dir / "sim_table.md", out_dir / "sim_table.csv",
                 "Simulation experiment (paper Table: simulation metrics)", preamble)
    return rows
