"""The previous action as a network input (``D4PGConfig.previous_goal``, ``lbgp train --previous-goal``).

The simulator's observation (``lbgp.sim.observation``, 57 numbers) holds the relative states only;
the authors' code also feeds the policy its previous action. With ``previous_goal`` the actor and
critic see the observation followed by the action the agent sent one step before (a goal policy's
previous goal, in action units): the *agent input*, 59 numbers. The action at an episode's first
step is the actor's ``base`` (a residual LBGP's goal 1.5 m ahead; zeros for a plain actor).

It is the only memory the policy gets: the planner is stateless (docs/planner.md), so the previous
goal changes nothing in the world and tells the policy only what it chose. The observation itself,
and so the simulator and the deploy loop's observation, are unchanged; ``lbgp.agent.policy.Policy``
carries the previous action between ``act`` calls and forgets it on ``reset``.
"""

from __future__ import annotations

import numpy as np

from lbgp.actions import mirror_actions
from lbgp.sim import observation as obs_lib

ACTION_SIZE = 2


def agent_input_size(previous_goal: bool) -> int:
    """How many numbers the networks are fed: the observation, plus the previous action if asked."""
    return obs_lib.SIZE + (ACTION_SIZE if previous_goal else 0)


def reads_previous_action(actor) -> bool:
    """Whether an actor (``lbgp.agent.networks.Actor``) was built for agent inputs with the previous action."""
    return actor.obs_size == agent_input_size(True)


def first_previous_action(actor) -> np.ndarray:
    """What an episode's first step feeds back, in training and in acting alike: the actor's base."""
    return actor.base.numpy().astype(np.float32)


def agent_input(observation, previous_action) -> np.ndarray:
    """The observation followed by the previous action (one of each, or batches of both)."""
    obs = np.asarray(observation, np.float32)
    prev = np.asarray(previous_action, np.float32)
    if obs.shape[-1:] != (obs_lib.SIZE,) or prev.shape[-1:] != (ACTION_SIZE,) or obs.shape[:-1] != prev.shape[:-1]:
        raise ValueError(f"agent input: an observation of {obs_lib.SIZE} numbers and an action of {ACTION_SIZE} "
                         f"per row, got shapes {obs.shape} and {prev.shape}")
    return np.concatenate([obs, prev], axis=-1)


def mirror_input(inputs) -> np.ndarray:
    """The mirror image (``lbgp.sim.observation.mirror``) of agent inputs with or without the previous
    action: the observation part mirrored, the previous action's lateral part negated. One or a batch."""
    x = np.asarray(inputs, np.float32)
    if x.shape[-1] == obs_lib.SIZE:
        return obs_lib.mirror(x)
    if x.shape[-1] != agent_input_size(True):
        raise ValueError(f"agent inputs have {obs_lib.SIZE} or {agent_input_size(True)} numbers, got shape {x.shape}")
    obs, prev = x[..., : obs_lib.SIZE], x[..., obs_lib.SIZE :]
    return np.concatenate([obs_lib.mirror(obs), mirror_actions(prev.reshape(-1, ACTION_SIZE)).reshape(prev.shape)], axis=-1)
