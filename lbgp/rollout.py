"""Run a policy for an episode in a simulated environment and collect metrics (and a recording)."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from lbgp.metrics import EpisodeMetrics, goal_ahead_of_person


class Policy(Protocol):
    def act(self, observation: np.ndarray) -> np.ndarray: ...


class ConstantGoalPolicy:
    """A scripted stand-in: always ask for the same goal in the person frame (default 1.5 m ahead)."""

    control = "goal"

    def __init__(self, goal_xy=None):
        from lbgp.actions import DESIRED_GOAL, action_from_goal

        self.action = action_from_goal(DESIRED_GOAL if goal_xy is None else goal_xy).astype(np.float32)

    def reset(self) -> None:
        pass

    def act(self, observation) -> np.ndarray:
        return self.action


def run_episode(env, policy, recorder=None, episode_index: int = 0) -> EpisodeMetrics:
    """One episode; ``policy.reset()`` (if it has one) is called first, ``policy.act`` every step."""
    if hasattr(policy, "reset"):
        policy.reset()
    timestep = env.reset()
    info = env.info()
    metrics = EpisodeMetrics(setting=info["setting"])
    if recorder is not None:
        recorder.begin_episode(info["setting"], episode_index)
        recorder.log_step(info)
    while not timestep.last():
        timestep = env.step(policy.act(timestep.observation))
        info = env.info()
        metrics.add(info["distance"], info["alpha"], timestep.reward, info["robot_pose"][2], info["person_pose"][2],
                    goal_ahead_of_person(info["goal"], info["person_pose"]))
        metrics.contact = metrics.contact or bool(info["contact"])
        if recorder is not None:
            recorder.log_step(info, timestep.reward)
    metrics.terminated_early = timestep.discount == 0.0
    return metrics
