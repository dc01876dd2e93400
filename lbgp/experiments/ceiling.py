"""The reward ceiling: an upper bound on the return any policy can reach, by dynamic programming
over a relaxed robot (see benchmarks/reward_ceiling.py for the derivation and the training levels).

The relaxed robot is a point that may move in any direction at up to ``vmax`` (no heading, no
acceleration limit, no footprint) and only has to respect the episode's end conditions at the 5 Hz
agent steps: whatever a real robot with the same top speed does, this point can do too. For one
episode's person motion, its best return from every start is a dynamic program over a grid of
person-frame positions, 35 steps back from the end (``best_returns``). ``scenario_ceiling`` reads it
at a paper scenario's fixed start for the scenario's own person motion.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from lbgp.geometry import integrate_unicycle
from lbgp.sim.rewards import MAX_DISTANCE, MIN_DISTANCE, follow_ahead_reward_array
from lbgp.sim.tasks import ALL_SETTINGS, CONTROL_PERIOD, DEFAULT_HORIZON

EXTENT = 5.4  # m (1.5 m ahead is a grid point for h = 0.06, 0.046, 0.03): the grid covers [-EXTENT, EXTENT]^2
# in the person frame (D > 5 ends an episode)


class Grid:
    def __init__(self, h: float):
        self.h = h
        self.axis = np.arange(-EXTENT, EXTENT + h / 2, h)
        self.x, self.y = np.meshgrid(self.axis, self.axis, indexing="ij")

    def index(self, x, y):
        return np.stack([(x + EXTENT) / self.h, (y + EXTENT) / self.h])


class StepModel:
    """One agent step of a person walking at (v, w): where each grid point lands, its reward and end."""

    def __init__(self, grid: Grid, v: float, w: float, dt: float):
        dx, dy, turn = integrate_unicycle(np.zeros(3), v, w, dt)  # the person's move, in its old frame
        c, s = math.cos(turn), math.sin(turn)
        qx, qy = grid.x - dx, grid.y - dy
        px, py = c * qx + s * qy, -s * qx + c * qy  # where a point at q (after the robot's move) lands
        distance = np.hypot(px, py)
        self.reward = follow_ahead_reward_array(distance, np.arctan2(py, px))
        self.ends = (distance < MIN_DISTANCE) | (distance > MAX_DISTANCE)
        self.coords = grid.index(px, py)


def best_returns(grid: Grid, motions, vmax: float, dt: float = CONTROL_PERIOD):
    """V_0 on the grid: the relaxed robot's best return from each start, for a person who walks
    ``motions[k] = (v, w)`` during step k (one entry per agent step of the episode)."""
    models: dict[tuple, StepModel] = {}
    radius = vmax * dt / grid.h
    r = int(math.ceil(radius))
    ox, oy = np.mgrid[-r : r + 1, -r : r + 1]
    footprint = ox**2 + oy**2 <= (radius + 0.5) ** 2  # rounded up: never smaller than the true disc
    value = np.zeros_like(grid.x)
    for v, w in reversed(motions):
        key = (round(v, 9), round(w, 9))
        if key not in models:
            models[key] = StepModel(grid, v, w, dt)
        m = models[key]
        after = m.reward + np.where(m.ends, 0.0, ndimage.map_coordinates(value, m.coords, order=1, mode="nearest"))
        value = ndimage.maximum_filter(after, footprint=footprint, mode="nearest")
    return value


def person_commands(setting_name: str, rng: np.random.Generator, steps: int = DEFAULT_HORIZON, dt: float = CONTROL_PERIOD):
    """The (v, w) the person of a level or scenario walks in each step of one episode (the
    simulator's own motion model)."""
    motion = ALL_SETTINGS[setting_name].motion()
    pose = motion.reset(rng, np.zeros(3))
    commands = []
    for _ in range(steps):
        v, w = motion.command(pose, dt)
        commands.append((float(v), float(w)))
        pose = integrate_unicycle(pose, v, w, dt)
    return commands


def scenario_ceiling(name: str, vmax: float, h: float = 0.06, steps: int = DEFAULT_HORIZON) -> float:
    """The relaxed robot's best return on a paper scenario: its fixed start (D, alpha) and the
    scenario's deterministic person motion, ``steps`` agent steps."""
    setting = ALL_SETTINGS[name]
    if setting.spawn is None:
        raise ValueError(f"{name!r} has no fixed start (a training level): use the level ceiling")
    grid = Grid(h)
    value = best_returns(grid, person_commands(name, np.random.default_rng(0), steps), vmax)
    distance, alpha_deg = setting.spawn
    a = math.radians(alpha_deg)
    x, y = np.array([distance * math.cos(a)]), np.array([distance * math.sin(a)])
    return float(ndimage.map_coordinates(value, grid.index(x, y), order=1)[0])
