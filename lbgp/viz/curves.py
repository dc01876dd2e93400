"""Learning-curve figure: exploit return against environment steps (or wall time), mean over the
runs that share a label with a shaded band: half a standard deviation (as in the paper's ablation
figure) or the 95 % confidence interval of the mean (t distribution over the runs)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np


def _label(run_dir: Path) -> str:
    cfg = json.loads((run_dir / "config.json").read_text())
    name = cfg["method"].upper()
    if cfg["method"] == "lbgp" and not cfg.get("curriculum", True):
        name += "-no-curriculum"
    return name


X_AXES = {"env_steps": ("env_steps", "environment steps"), "wall_time": ("wall_time_s", "wall time (s)")}  # curve.csv column, label
BANDS = ("half_std", "ci95")


def smoothed_curve(run_dir: Path, grid: np.ndarray, window: int = 10, x: str = "env_steps") -> np.ndarray:
    """Exploit returns (moving average over ``window`` episodes) interpolated onto ``grid`` (in
    environment steps, or seconds of wall time with ``x="wall_time"``); NaN past the run's end."""
    from lbgp.agent.train import read_curve

    rows = read_curve(run_dir / "curve.csv")
    if not rows:
        raise ValueError(f"{run_dir}: curve.csv holds no learning-curve points")
    steps = np.array([r[X_AXES[x][0]] for r in rows], float)
    ret = np.array([r["exploit_return"] for r in rows], float)
    kernel = np.ones(min(window, len(ret))) / min(window, len(ret))
    smooth = np.convolve(ret, kernel, mode="valid")
    steps = steps[len(steps) - len(smooth) :]
    out = np.interp(grid, steps, smooth)
    out[grid > steps[-1]] = np.nan
    return out


def curve_band(curves: np.ndarray, band: str = "half_std") -> tuple[np.ndarray, np.ndarray]:
    """Mean over runs (rows; NaN where a run had ended) and the band's half-width at each point:
    half the standard deviation, or the 95 % confidence interval of the mean (Student t with
    n - 1 degrees of freedom; 0 where only one run reached the point)."""
    if band not in BANDS:
        raise ValueError(f"band must be one of {BANDS}, got {band!r}")
    curves = np.atleast_2d(np.asarray(curves, float))
    n = np.isfinite(curves).sum(axis=0)
    mean = np.nanmean(curves, axis=0)
    if band == "half_std":
        return mean, 0.5 * np.nanstd(curves, axis=0)
    from scipy import stats

    with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)  # points only one run reached: no spread (band 0)
        sem = np.nanstd(curves, axis=0, ddof=1) / np.sqrt(n)
        half = stats.t.ppf(0.975, np.maximum(n - 1, 1)) * sem
    return mean, np.where(n > 1, half, 0.0)


def plot_learning_curves(run_dirs, out, labels=None, x: str = "env_steps", band: str = "half_std") -> None:
    """One line per label (mean over its runs) with a shaded ``band`` (``half_std`` or ``ci95``),
    against environment steps or wall time (``x``)."""
    if x not in X_AXES:
        raise ValueError(f"x must be one of {tuple(X_AXES)}, got {x!r}")
    if band not in BANDS:
        raise ValueError(f"band must be one of {BANDS}, got {band!r}")
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

    column, axis_label = X_AXES[x]
    longest = max(read_curve(d / "curve.csv")[-1][column] for d in dirs if read_curve(d / "curve.csv"))
    grid = np.linspace(0, longest, 200)
    fig, ax = plt.subplots(figsize=(6, 4))
    for lab, ds in groups.items():
        curves = np.array([smoothed_curve(d, grid, x=x) for d in ds])
        covered = np.isfinite(curves).any(axis=0)  # grid points some run of this group reached
        mean, half = curve_band(curves[:, covered], band)
        ax.plot(grid[covered], mean, label=f"{lab} ({len(ds)} run{'s' if len(ds) > 1 else ''})")
        ax.fill_between(grid[covered], mean - half, mean + half, alpha=0.25)
    ax.set_xlabel(axis_label)
    ax.set_ylabel("exploit episode return (35 steps)")
    shade = "half a standard deviation" if band == "half_std" else "95 % confidence interval of the mean"
    ax.set_title(f"Learning curves (shaded: {shade})")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
