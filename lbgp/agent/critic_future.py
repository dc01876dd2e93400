"""The critic's hindsight of the episode's next second (``D4PGConfig.critic_future``).

An asymmetric actor-critic (Pinto et al. 2017, "Asymmetric Actor Critic for Image-Based Robot
Learning"): in simulation the learner may judge an action with knowledge the policy never has. The
value of a goal depends most on where the person walks next (a turn in the next second decides
whether the robot stays in front); the actor cannot see it, so the critic has to average over every
future its observation allows, and its targets are noisy where a turn begins. With
``critic_future`` the critic also sees, for each step of an episode, read after the episode ended:

    index  0..2              the robot's true (noise-free) pose in the person's current frame
    index  3k .. 3k+2        the person's true pose k agent steps (0.2 s each) later in that
                             frame, k = 1..``STEPS``

scaled as the observation is (``lbgp.sim.observation.scale``). Where an episode ends before k steps
the person's last step is continued at its last twist (a truncated episode's final value is
bootstrapped; a terminated one's is not used).

The features follow the agent input in the replay and in the critic's input (the learner's ``critic_inputs``);
the actor reads only the agent input before them, so the policy file, the deploy loop and the
observation are unchanged. Its gradient is that of the hindsight value, whose mean over the futures
the observation allows is the policy's own value.
"""

from __future__ import annotations

import numpy as np

from lbgp.geometry import from_frame, to_frame
from lbgp.sim import observation as obs_lib

STEPS = 5  # 1 s of the person's future at the agent's 5 Hz
SIZE = 3 * (STEPS + 1)


def continue_path(person_poses: np.ndarray, steps: int) -> np.ndarray:
    """``person_poses`` (T+1, 3) followed by ``steps`` more poses at the last step's twist (the
    last pose's offset from the one before, repeated in its own frame); one pose stays put."""
    poses = np.asarray(person_poses, float)
    step = to_frame(poses[-1], poses[-2]) if len(poses) > 1 else np.zeros(3)
    out, last = [poses], poses[-1]
    for _ in range(steps):
        last = from_frame(step, last)
        out.append(last[None])
    return np.concatenate(out)


def hindsight_features(robot_poses, person_poses) -> np.ndarray:
    """(T+1, ``SIZE``) float32: the features above for every step 0..T of an episode whose true
    world poses were ``robot_poses`` and ``person_poses`` (T+1, 3 each: after reset and after each step)."""
    robots = np.asarray(robot_poses, float)
    persons = np.asarray(person_poses, float)
    if robots.shape != persons.shape or robots.ndim != 2 or robots.shape[1] != 3 or len(robots) < 1:
        raise ValueError(f"hindsight features need (T+1, 3) robot and person poses, got {robots.shape} and {persons.shape}")
    if not (np.all(np.isfinite(robots)) and np.all(np.isfinite(persons))):
        raise ValueError("hindsight features: a pose is not finite")
    path = continue_path(persons, STEPS)
    rows = []
    for t in range(len(robots)):
        frame = persons[t]
        rel = np.concatenate([to_frame(robots[t], frame)[None], to_frame(path[t + 1 : t + 1 + STEPS], frame)])
        rows.append(obs_lib.scale(rel))
    return np.stack(rows).astype(np.float32)
