"""``lbgp experiment ablation``: LBGP with and without curriculum, and E2E, over seeds, each run
within the same wall-time budget; the learning-curve figure like the paper's, against wall time
(the methods are compared at equal wall time: an E2E step costs no planner call), mean over the
seeds with a shaded 95 % confidence interval.

The curves are the exploiting actor's returns. Note that with curriculum the early points are on
easier levels (the paper plots it the same way). Runs live in ``runs/ablation`` by default (their
checkpoints hold the replay, ~100 MB each) and resume where they stopped: an interrupted ablation,
or one spread over several sessions, is continued by the same command.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lbgp.files import write_json
from lbgp.metrics import reward_ci95

from lbgp.agent.config import D4PGConfig
from lbgp.agent.train import train
from lbgp.viz.curves import plot_learning_curves

VARIANTS = {
    "LBGP": {"method": "lbgp", "curriculum": True},
    "LBGP-no-curriculum": {"method": "lbgp", "curriculum": False},
    "E2E": {"method": "e2e", "curriculum": True},
}


DEFAULT_RUNS_DIR = Path("runs") / "ablation"


def final_returns(summaries: dict, labels: dict) -> dict:
    """Per variant: each seed's mean exploit return over its last 20 episodes, their mean and the
    95 % confidence interval's half-width (t over the seeds; None with one seed)."""
    out = {}
    for label in dict.fromkeys(labels.values()):
        values = [summaries[run].get("final_exploit_return_mean_last20") for run, lab in labels.items() if lab == label]
        values = [float(v) for v in values if v is not None]
        if not values:
            continue
        half = reward_ci95(values) if len(values) > 1 else None
        out[label] = {"per_seed": values, "mean": float(np.mean(values)), "ci95_half_width": half}
    return out


def run_ablation(out_dir="results", minutes: float = 30.0, seeds=(0, 1, 2), steps: int | None = None, backend: str = "processes",
                 runs_dir=None, command: str = "") -> dict:
    """Train every variant for every seed (``minutes`` wall time each, and at most ``steps``);
    writes ``ablation_curves.png`` and ``ablation.json`` (the runs' summaries and each variant's
    final return over the seeds) in ``out_dir``."""
    out_dir = Path(out_dir)
    runs_dir = Path(runs_dir) if runs_dir else DEFAULT_RUNS_DIR
    dirs, labels, summaries, run_labels = [], [], {}, {}
    for label, variant in VARIANTS.items():
        for seed in seeds:
            run = runs_dir / f"{label}_s{seed}"
            cfg = D4PGConfig(seed=seed, total_steps=steps or D4PGConfig.total_steps, time_limit_s=minutes * 60.0, **variant)
            summaries[run.name] = train(cfg, run, resume=(run / "checkpoint.pt").exists(), backend=backend, progress=False)
            dirs.append(run)
            labels.append(label)
            run_labels[run.name] = label
    plot_learning_curves(dirs, out_dir / "ablation_curves.png", labels=labels, x="wall_time", band="ci95")
    report = {"command": command or "lbgp experiment ablation", "minutes_per_run": minutes, "seeds": list(seeds),
              "final_returns": final_returns(summaries, run_labels), "runs": summaries}
    write_json(out_dir / "ablation.json", report)
    return report
