"""An upper bound on the mean 35-step return any policy can reach on each training level.

    python benchmarks/reward_ceiling.py --json results/reward_ceiling.json

The bound comes from a relaxed robot that is easier to drive than any real one: a point that may
move in any direction at up to ``vmax`` (no heading, no turning, no acceleration limit, no
footprint) and that only has to respect the episode's end conditions at the 5 Hz agent steps.
Whatever a real robot with the same top speed does, this point can do too, so the best return of
the point is at least the best return of any policy.

For one episode's person motion (straight at v; a circle with v and w; or, on the smoothed and
trajectories levels, the (v, w) sequence of a sampled episode of the level's own motion model) the
best return of the point from every start is a dynamic program over a grid of person-frame
positions (``h`` metres apart), 35 steps back from the end:

    V_k(p) = max over |u| <= vmax of  R(p') + [p' not terminal] * V_{k+1}(p'),
    p' = Rot(-w dt) (p + u dt - d),   d = the person's displacement during the step.

The max over the disc of u is a grey dilation (``scipy.ndimage.maximum_filter`` with a disc
footprint, radius rounded up), V_{k+1} at p' is read by linear interpolation, R and the end
conditions at p' are exact. V_0 is then averaged over the level's start distribution (distance
uniform in [1, 2.5] m, direction uniform) and person motions (straight and circles: speeds on a
midpoint grid over their ranges; smoothed and trajectories: 40 sampled episodes).
Grid effects are reported by running two grid sizes.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy import ndimage

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.experiments.ceiling import Grid, best_returns, person_commands  # noqa: E402
from lbgp.sim.tasks import DEFAULT_HORIZON, LEVELS, SPAWN_DISTANCE  # noqa: E402

def start_points(n: int, rng: np.random.Generator):
    distance = rng.uniform(*SPAWN_DISTANCE, n)
    alpha = rng.uniform(-math.pi, math.pi, n)
    return distance * np.cos(alpha), distance * np.sin(alpha), alpha


def midpoints(lo: float, hi: float, n: int) -> np.ndarray:
    return lo + (np.arange(n) + 0.5) * (hi - lo) / n


def level_ceiling(grid: Grid, level: str, vmax: float, starts: int = 4000, bins: int = 6, episodes: int = 40) -> dict:
    rng = np.random.default_rng(0)
    x, y, alpha = start_points(starts, rng)
    steps = DEFAULT_HORIZON
    model = LEVELS[level].motion()  # the level's own ranges of person speeds
    if level == "straight":
        motions = [[(v, 0.0)] * steps for v in midpoints(*model.speed_range, bins)]
    elif level == "circles":  # w < 0 is the mirror image of w > 0, same start distribution
        motions = [[(v, w)] * steps for v in midpoints(*model.v_range, bins // 2 + 1) for w in midpoints(*model.w_range, bins // 2 + 1)]
    else:  # a sample of episodes of the level's own person motion
        motions = [person_commands(level, rng) for _ in range(episodes)]
    per_start = []
    for motion in motions:
        value = best_returns(grid, motion, vmax)
        per_start.append(ndimage.map_coordinates(value, grid.index(x, y), order=1))
    per_start = np.mean(per_start, axis=0)
    behind = np.abs(alpha) > math.pi / 2
    return {
        "level": level,
        "vmax": vmax,
        "grid_m": grid.h,
        "mean_bound": float(per_start.mean()),
        "mean_bound_starts_in_front_half": float(per_start[~behind].mean()),
        "mean_bound_starts_in_back_half": float(per_start[behind].mean()),
        "person_motions": len(motions),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", default="results/reward_ceiling.json")
    parser.add_argument("--grids", default="0.06,0.046", help="grid spacings in metres (comma separated; 1.5 m ahead should be a grid point)")
    parser.add_argument("--vmax", default="1.5,2.0", help="top speeds in m/s (Jackal planner limit, Jackal spec)")
    parser.add_argument("--levels", default="straight,circles,smoothed,trajectories")
    args = parser.parse_args()
    results = []
    for h in (float(g) for g in args.grids.split(",")):
        grid = Grid(h)
        for vmax in (float(v) for v in args.vmax.split(",")):
            for level in args.levels.split(","):
                t0 = time.perf_counter()
                row = level_ceiling(grid, level, vmax)
                row["seconds"] = round(time.perf_counter() - t0, 1)
                print(row, flush=True)
                results.append(row)
    write_result(args.json, {
        "benchmark": "reward_ceiling_relaxed_point_robot",
        "horizon_steps": DEFAULT_HORIZON,
        "max_reward_per_step": 0.75,
        "results": results,
    })


if __name__ == "__main__":
    main()
