"""``lbgp experiment ablation``: LBGP with and without curriculum, and E2E, over seeds, each run
within a wall-time budget; the learning-curve figure like the paper's (mean, shaded half std).

The curves are the exploiting actor's returns. Note that with curriculum the early points are on
easier levels (the paper plots it the same way).
"""

from __future__ import annotations

from pathlib import Path

from lbgp.files import write_json

from lbgp.agent.config import D4PGConfig
from lbgp.agent.train import train
from lbgp.viz.curves import plot_learning_curves

VARIANTS = {
    "LBGP": {"method": "lbgp", "curriculum": True},
    "LBGP-no-curriculum": {"method": "lbgp", "curriculum": False},
    "E2E": {"method": "e2e", "curriculum": True},
}


def run_ablation(out_dir="results", minutes: float = 10.0, seeds=(0, 1), steps: int | None = None, backend: str = "processes",
                 runs_dir=None, command: str = "") -> dict:
    """Train every variant for every seed (``minutes`` wall time each, and at most ``steps``);
    writes ``ablation_curves.png`` and ``ablation.json`` (the runs' summaries) in ``out_dir``."""
    out_dir = Path(out_dir)
    runs_dir = Path(runs_dir) if runs_dir else out_dir / "ablation_runs"
    dirs, labels, summaries = [], [], {}
    for label, variant in VARIANTS.items():
        for seed in seeds:
            run = runs_dir / f"{label}_s{seed}"
            cfg = D4PGConfig(seed=seed, total_steps=steps or D4PGConfig.total_steps, time_limit_s=minutes * 60.0, **variant)
            summaries[run.name] = train(cfg, run, resume=(run / "checkpoint.pt").exists(), backend=backend, progress=False)
            dirs.append(run)
            labels.append(label)
    plot_learning_curves(dirs, out_dir / "ablation_curves.png", labels=labels)
    report = {"command": command or "lbgp experiment ablation", "minutes_per_run": minutes, "seeds": list(seeds), "runs": summaries}
    write_json(out_dir / "ablation.json", report)
    return report
