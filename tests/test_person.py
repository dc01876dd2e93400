"""Person motion models of the curriculum."""

import math

import numpy as np
import pytest

from lbgp.geometry import integrate_unicycle
from lbgp.sim.paths import evaluation_path
from lbgp.sim.person import CircleMotion, PathMotion, SmoothedMotion, StraightMotion


def test_straight_speed_is_constant_per_episode_and_in_range():
    m = StraightMotion()
    rng = np.random.default_rng(1)
    speeds = set()
    for _ in range(20):
        m.reset(rng, np.zeros(3))
        cmds = {m.command(np.zeros(3), 0.2) for _ in range(5)}
        assert len(cmds) == 1
        v, w = cmds.pop()
        assert 0.3 <= v <= 1.0 and w == 0.0
        speeds.add(v)
    assert len(speeds) == 20


def test_circles_ranges_and_both_directions():
    m = CircleMotion()
    rng = np.random.default_rng(2)
    signs = set()
    for _ in range(40):
        m.reset(rng, np.zeros(3))
        v, w = m.command(np.zeros(3), 0.2)
        assert 0.2 <= v <= 0.6 and 0.3 <= abs(w) <= 0.8
        signs.add(math.copysign(1, w))
    assert signs == {-1.0, 1.0}


def test_smoothed_follows_the_papers_recursion():
    m = SmoothedMotion()
    m.reset(np.random.default_rng(3), np.zeros(3))
    v0, w0 = m.v, m.w
    replay = np.random.default_rng(3)
    replay.uniform(0, 1), replay.uniform(-1, 1)  # the two initial draws
    for _ in range(10):
        r1, r2 = replay.uniform(0, 1), replay.uniform(-1, 1)
        v, w = m.command(np.zeros(3), 0.2)
        assert v == pytest.approx(v0 - (v0 - r1) / 3) and w == pytest.approx(w0 - (w0 - r2) / 3)
        assert 0 <= v <= 1 and -1 <= w <= 1
        v0, w0 = v, w


def test_pid_tracker_follows_a_path():
    path = evaluation_path("one")
    m = PathMotion(path, speed=0.6, anchor=False)
    pose = m.reset(np.random.default_rng(0), np.zeros(3))
    errors = []
    for _ in range(200):
        v, w = m.command(pose, 0.2)
        pose = integrate_unicycle(pose, v, w, 0.2)
        errors.append(np.min(np.linalg.norm(path - pose[:2], axis=1)))
    assert max(errors) < 0.25  # stays on the path
    assert np.linalg.norm(pose[:2] - path[-1]) < 0.3  # and walks to its end, then stops
    assert m.command(pose, 0.2) == (0.0, 0.0)


def test_anchored_path_starts_at_the_spawn_pose():
    path = evaluation_path("two")
    m = PathMotion(path, speed=0.5)
    start = np.array([3.0, -1.0, 1.0])
    pose = m.reset(np.random.default_rng(0), start)
    np.testing.assert_allclose(pose, start)
    np.testing.assert_allclose(m.path[0], start[:2])
    d = m.path[3] - m.path[0]
    assert math.atan2(d[1], d[0]) == pytest.approx(1.0, abs=1e-6)
