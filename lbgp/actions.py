"""What a policy's action means. Policies act in [-1, 1]^2; these functions give that a metric meaning.

* Goal actions (LBGP, HC): a goal position in the *person frame* (x ahead of the person, y to the
  person's left). ``a = (-1, -1)`` maps to (GOAL_X[0], GOAL_Y[0]) and ``(1, 1)`` to
  (GOAL_X[1], GOAL_Y[1]), linearly: x in [-1, 3] m, y in [-2, 2] m. The desired spot (1.5 m
  straight ahead) is ``a = (0.25, 0)``.
* Velocity actions (E2E, as in the paper): v in [-1, 1] m/s and w in [-2, 2] rad/s.
"""

from __future__ import annotations

import numpy as np

from lbgp.conventions import DESIRED_GOAL  # noqa: F401 - m, person frame: where the reward peaks (re-exported)

GOAL_X = (-1.0, 3.0)  # m, person frame
GOAL_Y = (-2.0, 2.0)  # m, person frame
MAX_V = 1.0  # m/s
MAX_W = 2.0  # rad/s


def _check(action) -> np.ndarray:
    a = np.asarray(action, dtype=float).reshape(-1)
    if a.shape != (2,):
        raise ValueError(f"an action has 2 numbers, got shape {np.shape(action)}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"action is not finite: {a.tolist()}")
    return np.clip(a, -1.0, 1.0)


def goal_from_action(action) -> np.ndarray:
    """[-1, 1]^2 -> goal (x, y) in metres, person frame."""
    a = _check(action)
    lo = np.array([GOAL_X[0], GOAL_Y[0]])
    hi = np.array([GOAL_X[1], GOAL_Y[1]])
    return lo + (a + 1.0) * 0.5 * (hi - lo)


def action_from_goal(goal_xy) -> np.ndarray:
    """Goal (x, y) in metres, person frame -> [-1, 1]^2 (clipped to the range)."""
    g = np.asarray(goal_xy, dtype=float).reshape(2)
    lo = np.array([GOAL_X[0], GOAL_Y[0]])
    hi = np.array([GOAL_X[1], GOAL_Y[1]])
    return np.clip(2.0 * (g - lo) / (hi - lo) - 1.0, -1.0, 1.0)


def mirror_action(action) -> np.ndarray:
    """The action's mirror image about the person's heading line (see
    ``lbgp.sim.observation.mirror``): a goal's y and a velocity command's w change sign; the
    second number in both forms, since both ranges are symmetric about 0."""
    a = _check(action)
    return np.array([a[0], -a[1]])


def mirror_actions(actions: np.ndarray) -> np.ndarray:
    """``mirror_action`` for a batch (N, 2), dtype kept (training data, checked where it was made)."""
    actions = np.asarray(actions)
    if actions.ndim != 2 or actions.shape[1] != 2:
        raise ValueError(f"a batch of actions has shape (N, 2), got {actions.shape}")
    return actions * np.array([1, -1], dtype=actions.dtype)


def velocity_from_action(action) -> tuple[float, float]:
    """[-1, 1]^2 -> (v, w) = (a0 * 1 m/s, a1 * 2 rad/s)."""
    a = _check(action)
    return float(a[0] * MAX_V), float(a[1] * MAX_W)


__all__ = ["DESIRED_GOAL", "GOAL_X", "GOAL_Y", "MAX_V", "MAX_W", "goal_from_action", "action_from_goal", "mirror_action", "mirror_actions", "velocity_from_action"]
