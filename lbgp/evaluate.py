"""Seeded, viewer-free evaluation of a policy over levels or scenarios.

The JSON written by ``lbgp evaluate --json`` is a list with one entry per scenario:
``scenario, method, distance_mean, distance_std (m), alpha_mean_deg, alpha_std_deg, reward (mean
accumulated reward per episode), reward_std, reward_ci95 (half-width of the 95 % interval of the
mean), episode_rewards (each episode's, in seed order), collisions, terminated_early (episode
counts), steps (mean episode length), episodes, loops (episodes in which the robot's heading turned
through more than 180 degrees relative to the person's while its goal stayed ahead of the person:
see ``lbgp.metrics.LoopDetector``)``.
"""

from __future__ import annotations

from lbgp.calibration import load_calibration
from lbgp.metrics import aggregate
from lbgp.rollout import run_episode
from lbgp.sim import make_env
from lbgp.sim.tasks import LEVELS, SCENARIOS
from lbgp.stack import policy_planner


def resolve_names(spec: str) -> list[str]:
    """'all' -> every paper scenario, 'levels' -> every curriculum level, else a comma list."""
    if spec == "all":
        return list(SCENARIOS)
    if spec == "levels":
        return list(LEVELS)
    names = [n.strip() for n in spec.split(",") if n.strip()]
    unknown = [n for n in names if n not in SCENARIOS and n not in LEVELS]
    if unknown or not names:
        raise ValueError(f"unknown scenario {', '.join(map(repr, unknown)) or repr(spec)}; use all, levels, or names from: {', '.join(list(LEVELS) + list(SCENARIOS))}")
    return names


def evaluate(policy, method: str, names: list[str], robot: str = "jackal", episodes: int = 10, seed: int = 0,
             recorder=None, person_path=None, horizon: int = 35, obs_noise: bool | None = None, dynamics=None,
             calibration=None, drive_model=None, planner_config=None) -> list[dict]:
    """Episode i of scenario k is seeded with (seed, k, i): every method faces the same episodes.
    ``obs_noise``: the observation noise on/off (default: on for levels, off for scenarios).
    ``dynamics``: the robot's dynamics (``lbgp.dynamics``: a name, a JSON file or a ``Dynamics``; default nominal).
    ``calibration``: the command calibration (``lbgp.calibration``; default none); ``"online"``: one
    online estimator (``lbgp.online_calibration``) for all the episodes, in order, as one robot
    doing every run keeps what it learned.
    ``drive_model``: the planner's model of the drive (``lbgp.drive_model``; default none).
    ``planner_config``: the planner's ``PlannerConfig`` (default: the robot's preset with the changes
    the policy was trained with, ``lbgp.stack.policy_planner``)."""
    calibration = load_calibration(calibration, robot)
    planner_config = policy_planner(policy, robot, planner_config)
    results = []
    for k, name in enumerate(names):
        env = make_env(name, robot=robot, seed=seed + 1000 * k, control=policy.control, person_path=person_path,
                       horizon=horizon, obs_noise=obs_noise, dynamics=dynamics, calibration=calibration,
                       drive_model=drive_model, planner_config=planner_config)
        runs = []
        for i in range(episodes):
            env.reseed([seed, k, i])
            runs.append(run_episode(env, policy, recorder, episode_index=i))
        results.append({"scenario": name, "method": method, **aggregate(runs)})
    return results
