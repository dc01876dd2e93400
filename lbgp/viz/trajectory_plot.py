"""Static top-down pictures of episodes (for docs and results): person and robot paths with goals.

``TrajectoryCollector`` has the recorder interface of ``run_episode`` (``begin_episode``,
``log_step``) and keeps the poses and goals of every step; ``plot_trajectories`` draws one panel
per method.
"""

from __future__ import annotations

import os
from pathlib import Path

from lbgp.files import atomic_file

import numpy as np


class TrajectoryCollector:
    def __init__(self):
        self.episodes: list[dict] = []

    def begin_episode(self, name: str, index: int = 0) -> None:
        self.episodes.append({"name": name, "robot": [], "person": [], "goal": []})

    def log_step(self, info: dict, reward: float | None = None) -> None:
        ep = self.episodes[-1]
        ep["robot"].append(np.asarray(info["robot_pose"], float).copy())
        ep["person"].append(np.asarray(info["person_pose"], float).copy())
        goal = info.get("goal")
        ep["goal"].append(None if goal is None else np.asarray(goal, float)[:2].copy())


def plot_trajectories(panels: dict[str, dict], out: str | os.PathLike, title: str = "") -> Path:
    """``panels``: method name -> one collected episode. Writes a PNG (atomically)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 4.2), squeeze=False)
    for ax, (method, ep) in zip(axes[0], panels.items()):
        person, robot = np.array(ep["person"]), np.array(ep["robot"])
        goals = np.array([g for g in ep["goal"] if g is not None]).reshape(-1, 2)
        ax.plot(person[:, 0], person[:, 1], "-", color="tab:blue", label="person")
        ax.plot(robot[:, 0], robot[:, 1], "-", color="tab:orange", label="robot")
        if len(goals):
            ax.plot(goals[:, 0], goals[:, 1], ".", color="tab:green", ms=3, label="goal")
        for path, color in ((person, "tab:blue"), (robot, "tab:orange")):
            ax.plot(*path[0, :2], "o", color=color, ms=6)
            ax.quiver(path[::5, 0], path[::5, 1], 0.3 * np.cos(path[::5, 2]), 0.3 * np.sin(path[::5, 2]), color=color,
                      angles="xy", scale_units="xy", scale=1.0, width=0.005)
        ax.set_title(method)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
        ax.set_xlabel("x (m)")
    axes[0][0].set_ylabel("y (m)")
    axes[0][0].legend(loc="best", fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    out = Path(out)
    with atomic_file(out, "wb") as f:
        fig.savefig(f, dpi=90, format="png")
    plt.close(fig)
    return out
