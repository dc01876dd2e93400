"""``lbgp experiment ablation``: LBGP with and without curriculum, and E2E, over seeds, each run
within the same wall-time budget; the learning-curve figure like the paper's, against wall time
(the methods are compared at equal wall time: an E2E step costs no planner call), mean over the
seeds with a shaded 95 % confidence interval.

The curves are the exploiting actor's returns. Note that with curriculum the early points are on
easier levels (the paper plots it the same way). Runs live in ``runs/ablation`` by default (their
checkpoints hold the replay, ~100 MB each) and resume where they stopped.

Nine 30-minute runs take 4.5 hours, more than one sitting on a fresh machine whose ``runs/`` is gone
the next time. So every finished run's small files (config.json, curve.csv, summary.json; also its
policy.pt) are kept beside the results, in ``ablation_runs/<run>/``, and a later call with the same
settings reuses them instead of training again; ``max_new_runs`` bounds how many runs one call
trains. Runs go seed by seed (every variant's seed 0 first), so a partial ablation already compares
the variants. Until all runs are there, ``ablation.json`` says ``complete: false`` and lists the
missing ones.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from lbgp.files import atomic_file, write_json, write_text
from lbgp.metrics import reward_ci95

from lbgp.agent.config import D4PGConfig
from lbgp.agent.train import train
from lbgp.viz.curves import plot_learning_curves

VARIANTS = {
    "LBGP": {"method": "lbgp", "curriculum": True},
    "LBGP-no-curriculum": {"method": "lbgp", "curriculum": False},
    # an E2E step costs no planner call: its default 300k-step budget ran out after 20 of the 30
    # minutes (seed 0), so at equal wall time E2E gets a step budget it does not reach
    "E2E": {"method": "e2e", "curriculum": True, "total_steps": 1_000_000},
}


DEFAULT_RUNS_DIR = Path("runs") / "ablation"
ARCHIVE_NAME = "ablation_runs"  # under the results folder: the finished runs' small files
ARCHIVED_FILES = ("config.json", "curve.csv", "summary.json")
POLICY_FILE = "policy.pt"  # also kept (~100 KB) for benchmarks/ablation_scenarios.py; not needed to reuse a run


def archived_run(archive: Path, cfg: D4PGConfig) -> dict | None:
    """The summary of a finished run kept in ``archive`` with exactly this configuration, else None
    (missing files, or a run made with other settings or an older set of defaults)."""
    try:
        if not all((archive / name).is_file() for name in ARCHIVED_FILES):
            return None
        # a setting added after the run was made is read at its default, which every new setting
        # takes as the behaviour from before it existed (e.g. mirror_augment False, turn_lead 0)
        kept = D4PGConfig.from_dict(json.loads((archive / "config.json").read_text()))
        if json.loads(kept.to_json()) != json.loads(cfg.to_json()):
            return None
        return json.loads((archive / "summary.json").read_text())
    except (OSError, ValueError):
        return None


def archive_run(run: Path, archive: Path) -> None:
    """Copy a finished run's small files into ``archive``, each atomically (summary.json last: it
    marks the copy whole)."""
    (archive / "summary.json").unlink(missing_ok=True)
    if (run / POLICY_FILE).is_file():
        with atomic_file(archive / POLICY_FILE, "wb") as f:
            f.write((run / POLICY_FILE).read_bytes())
    for name in ARCHIVED_FILES:
        write_text(archive / name, (run / name).read_text())


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


def variant_config(label: str, seed: int, minutes: float, steps: int | None = None) -> D4PGConfig:
    """The training configuration of one run: the variant's, ``minutes`` of wall time, and ``steps``
    (if given) as every variant's step budget."""
    settings = {"total_steps": D4PGConfig.total_steps, **VARIANTS[label]}
    if steps:
        settings["total_steps"] = steps
    return D4PGConfig(seed=seed, time_limit_s=minutes * 60.0, **settings)


def run_ablation(out_dir="results", minutes: float = 30.0, seeds=(0, 1, 2), steps: int | None = None, backend: str = "processes",
                 runs_dir=None, command: str = "", max_new_runs: int | None = None) -> dict:
    """Train every variant for every seed (``minutes`` wall time each, and at most ``steps``),
    reusing finished runs kept in ``out_dir/ablation_runs`` and training at most ``max_new_runs``
    new ones; writes ``ablation_curves.png`` and ``ablation.json`` (the runs' summaries, each
    variant's final return over the seeds, and which runs are still missing) in ``out_dir``."""
    out_dir = Path(out_dir)
    runs_dir = Path(runs_dir) if runs_dir else DEFAULT_RUNS_DIR
    dirs, labels, summaries, run_labels, missing, trained = [], [], {}, {}, [], 0
    for seed in seeds:
        for label in VARIANTS:
            name = f"{label}_s{seed}"
            run, archive = runs_dir / name, out_dir / ARCHIVE_NAME / name
            cfg = variant_config(label, seed, minutes, steps)
            summary = archived_run(archive, cfg)
            if summary is None:
                if max_new_runs is not None and trained >= max_new_runs:
                    missing.append(name)
                    continue
                summary = train(cfg, run, resume=(run / "checkpoint.pt").exists(), backend=backend, progress=False)
                archive_run(run, archive)
                trained += 1
            summaries[name] = summary
            dirs.append(archive)
            labels.append(label)
            run_labels[name] = label
    if dirs:
        plot_learning_curves(dirs, out_dir / "ablation_curves.png", labels=labels, x="wall_time", band="ci95")
    report = {"command": command or "lbgp experiment ablation", "minutes_per_run": minutes, "seeds": list(seeds),
              "complete": not missing, "missing_runs": missing,
              "final_returns": final_returns(summaries, run_labels), "runs": summaries}
    write_json(out_dir / "ablation.json", report)
    return report
