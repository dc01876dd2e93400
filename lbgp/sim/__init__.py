"""Simulation: MuJoCo robots and person, follow-ahead tasks (dm_env) and a Gymnasium wrapper.

``from lbgp.sim import make_env`` is the entry point. Names are imported lazily, so that importing a
light module of the package (e.g. ``lbgp.sim.observation``) does not load MuJoCo.
"""

import importlib

_EXPORTS = {
    "FollowAheadEnv": "lbgp.sim.env",
    "make_env": "lbgp.sim.env",
    "all_names": "lbgp.sim.env",
    "level_names": "lbgp.sim.env",
    "scenario_names": "lbgp.sim.env",
    "PathError": "lbgp.sim.paths",
    "load_path_csv": "lbgp.sim.paths",
    "follow_ahead_reward": "lbgp.sim.rewards",
    "ROBOTS": "lbgp.robots",
    "get_robot": "lbgp.robots",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'lbgp.sim' has no attribute {name!r}")
