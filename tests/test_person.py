"""Person motion models of the curriculum."""

import math

import numpy as np
import pytest

from lbgp.geometry import integrate_unicycle
from lbgp.sim.paths import draw_path, evaluation_path, path_length, resample_path
from lbgp.sim.person import CircleMotion, DrawnPathMotion, PathMotion, SmoothedMotion, StraightMotion


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


def test_drawn_path_motion_walks_a_fresh_path_each_episode_and_the_seed_repeats_them():
    def layouts(seed, episodes=4):
        m, rng = DrawnPathMotion(5.0), np.random.default_rng(seed)
        out = []
        for _ in range(episodes):
            start = np.array([1.0, 2.0, 0.5])
            np.testing.assert_allclose(m.reset(rng, start), start)
            np.testing.assert_allclose(m.path[0], start[:2])  # anchored at the spawn pose, as PathMotion
            out.append(m.path.copy())
        return out

    first, again, other = layouts(0), layouts(0), layouts(1)
    for a, b in zip(first, again):
        np.testing.assert_array_equal(a, b)
    shapes = [np.round(p - p[0], 6).tobytes() for p in first + other]
    assert len(set(shapes)) == len(shapes)  # no layout twice: not a library
    for p in first:  # each is a drawn path of the library's length (start share 0: whole)
        assert path_length(p) == pytest.approx(path_length(resample_path(draw_path(7, 5.0))), abs=0.1)


def test_drawn_paths_replace_only_the_trajectories_levels_library():
    from lbgp.agent.actors import EnvCache
    from lbgp.agent.config import D4PGConfig
    from lbgp.sim import make_env

    assert type(make_env("trajectories", seed=0, drawn_paths=True).task.motion) is DrawnPathMotion
    assert type(make_env("trajectories", seed=0).task.motion) is PathMotion
    with pytest.raises(ValueError, match="trajectories"):
        make_env("circles", drawn_paths=True)
    envs = EnvCache(D4PGConfig(drawn_paths=True), np.random.default_rng(0))
    assert type(envs("trajectories").task.motion) is DrawnPathMotion
    assert type(envs("circles").task.motion) is CircleMotion
    assert type(EnvCache(D4PGConfig(), np.random.default_rng(0))("trajectories").task.motion) is PathMotion
    assert D4PGConfig.parse_setting("drawn_paths=on") == ("drawn_paths", True)
