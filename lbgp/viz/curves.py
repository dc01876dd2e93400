"""Learning-curve figure: exploit return against environment steps, mean and a shaded half
standard deviation over the runs that share a label (as in the paper's ablation figure)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def _label(run_dir: Path) -> str:
    cfg = json.loads((run_dir / "config.json").read_text())
    name = cfg["method"].upper()
    if cfg["method"] == "lbgp" and not cfg.get("curriculum", True):
        name += "-no-curriculum"
    return name


def smoothed_curve(run_dir: Path, grid: np.ndarray, window: int = 10) -> np.ndarray:
    """Exploit returns (moving average over ``window`` episodes) interpolated onto ``grid`` steps."""
    from lbgp.agent.train import read_curve

    rows = read_curve(run_dir / "curve.csv")
    if not rows:
        raise ValueError(f"{run_dir}: curve.csv holds no learning-curve points")
    steps = np.array([r["env_steps"] for r in rows], float)
    ret = np.array([r["exploit_return"] for r in rows], float)
    kernel = np.ones(min(window, len(ret))) / min(window, len(ret))
    smooth = np.convolve(ret, kernel, mode="valid")
    steps = steps[len(steps) - len(smooth) :]
    out = np.interp(grid, steps, smooth)
    out[grid > steps[-1]] = np.nan
    return out


def plot_learning_curves(run_dirs, out, labels=None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    dirs = [Path(d) for d in run_dirs]
    for d in dirs:
        if not (d / "curve.csv").is_file() or not (d / "config.json").is_file():
            raise ValueError(f"{d} is not a training run directory (needs config.json and curve.csv)")
    labels = list(labels) if labels else [_label(d) for d in dirs]
    if len(labels) != len(dirs):
        raise ValueError(f"{len(labels)} labels for {len(dirs)} run directories")
    groups: dict[str, list[Path]] = {}
    for d, lab in zip(dirs, labels):
        groups.setdefault(lab, []).append(d)
    from lbgp.agent.train import read_curve

    max_steps = max(read_curve(d / "curve.csv")[-1]["env_steps"] for d in dirs if read_curve(d / "curve.csv"))
    grid = np.linspace(0, max_steps, 200)
    fig, ax = plt.subplots(figsize=(6, 4))
    for lab, ds in groups.items():
        curves = np.array([smoothed_curve(d, grid) for d in ds])
        covered = np.isfinite(curves).any(axis=0)  # grid points some run of this group reached
        mean = np.nanmean(curves[:, covered], axis=0)
        half_std = 0.5 * np.nanstd(curves[:, covered], axis=0)
        ax.plot(grid[covered], mean, label=f"{lab} ({len(ds)} run{'s' if len(ds) > 1 else ''})")
        ax.fill_between(grid[covered], mean - half_std, mean + half_std, alpha=0.25)
    ax.set_xlabel("environment steps")
    ax.set_ylabel("exploit episode return (35 steps)")
    ax.set_title("Learning curves (shaded: half a standard deviation)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
