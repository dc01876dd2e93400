"""HC baseline: the EKF on synthetic tracks, and the goal it picks."""

import math

import numpy as np
import pytest

from lbgp.baselines.ekf import PersonEKF
from lbgp.baselines.hc import HCPolicy
from lbgp.geometry import integrate_unicycle
from lbgp.sim.observation import ObservationStack


def track(v, w, n, dt=0.2, start=(0.0, 0.0, 0.3)):
    poses = [np.array(start)]
    for _ in range(n - 1):
        poses.append(integrate_unicycle(poses[-1], v, w, dt))
    return np.array(poses)


def test_ekf_converges_on_a_straight_walk():
    rng = np.random.default_rng(0)
    ekf = PersonEKF()
    truth = track(0.8, 0.0, 40)
    estimates = np.array([ekf.step(pose + rng.normal(0, [0.03, 0.03, 0.03]), 0.2) for pose in truth])
    late = estimates[-15:]  # after convergence: unbiased speed, no turn rate, on the track
    assert late[:, 3].mean() == pytest.approx(0.8, abs=0.05) and abs(late[:, 4].mean()) < 0.05
    assert np.linalg.norm(late[:, :2] - truth[-15:, :2], axis=1).mean() < 0.05
    assert abs(estimates[0, 3]) < 1e-9  # it started knowing nothing about the speed


def test_ekf_follows_a_circle():
    rng = np.random.default_rng(1)
    ekf = PersonEKF()
    truth = track(0.5, 0.6, 50)
    for pose in truth:
        est = ekf.step(pose + rng.normal(0, [0.02, 0.02, 0.02]), 0.2)
    assert est[3] == pytest.approx(0.5, abs=0.07) and est[4] == pytest.approx(0.6, abs=0.1)
    # and predicts the turn: 1 s ahead lands near the true continuation
    future = integrate_unicycle(truth[-1], 0.5, 0.6, 1.0)
    assert np.linalg.norm(ekf.forecast(1.0)[:2] - future[:2]) < 0.12


def test_ekf_handles_dropped_measurements():
    ekf = PersonEKF()
    truth = track(0.6, 0.0, 30)
    for k, pose in enumerate(truth):
        est = ekf.step(None if 15 <= k < 20 else pose, 0.2)
        if k == 19:
            p_dropped = ekf.P[0, 0]
            assert np.linalg.norm(est[:2] - truth[k, :2]) < 0.1  # predicted through the gap
    assert ekf.P[0, 0] < p_dropped  # and tightens again when data returns
    assert est[3] == pytest.approx(0.6, abs=0.05)
    nan_pose = np.array([np.nan, 0.0, 0.0])
    before = ekf.state.copy()
    ekf.update(nan_pose)
    np.testing.assert_array_equal(ekf.state, before)


def test_hc_goal_is_ahead_of_the_predicted_person():
    stack = ObservationStack()
    poses = track(0.6, 0.0, 10, start=(0.0, 0.0, 0.0))
    stack.reset(np.array([2.0, 0.0, 0.0]), poses[0])
    for p in poses[1:]:
        stack.push(np.array([p[0] + 1.5, 0.0, 0.0]), p)
    goal = HCPolicy(distance=1.5, horizon=1.0).goal(stack.vector())
    # walking straight at 0.6 m/s: 0.6 m ahead in 1 s, plus 1.5 m
    assert goal == pytest.approx([2.1, 0.0], abs=0.08)
    turning = track(0.5, 0.5, 10, start=(0.0, 0.0, 0.0))
    stack.reset(np.array([2.0, 0.0, 0.0]), turning[0])
    for p in turning[1:]:
        stack.push(np.array([0.0, 0.0, 0.0]), p)
    goal = HCPolicy(horizon=1.0).goal(stack.vector())
    assert goal[1] > 0.5  # a left turn puts the goal to the person's left
    assert math.isfinite(goal[0])


def test_ctrv_jacobian_matches_finite_differences_on_both_branches():
    from lbgp.baselines.ekf import ctrv, ctrv_jacobian

    rng = np.random.default_rng(0)
    states = [np.array([*rng.normal(0, 2, 2), rng.uniform(-np.pi, np.pi), rng.uniform(0, 2), rng.uniform(-1.5, 1.5)]) for _ in range(50)]
    states += [np.array([0.3, -0.2, 0.7, 1.2, 0.0]), np.array([0.0, 0.0, -2.0, 0.8, 5e-7])]  # straight branch
    for state in states:
        for dt in (0.2, 1.0):
            numeric = np.zeros((5, 5))
            for i in range(5):
                d = np.zeros(5)
                d[i] = 1e-5
                if i == 4 and abs(state[4]) <= 1e-6:  # finite differences across the branch: use the turning side
                    numeric[:, i] = (ctrv(state + 2 * d, dt) - ctrv(state + d, dt)) / 1e-5
                else:
                    numeric[:, i] = (ctrv(state + d, dt) - ctrv(state - d, dt)) / 2e-5
            np.testing.assert_allclose(ctrv_jacobian(state, dt), numeric, atol=2e-5 * max(1.0, dt * state[3]) * 10)
