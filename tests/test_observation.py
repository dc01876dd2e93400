"""The observation: relative states in the current person frame, 10 frames, scaled."""

import math

import numpy as np
import pytest

from lbgp.geometry import distance_and_alpha, to_frame
from lbgp.sim import observation as obs


def test_layout_on_a_hand_computed_case():
    stack = obs.ObservationStack(frames=3)
    # person walks along +y (yaw 90 deg); robot 2 m ahead of it, facing the same way
    for k in range(3):
        stack.push(robot_pose=[0.0, 2.0 + k, math.pi / 2], person_pose=[0.0, float(k), math.pi / 2])
    raw = obs.unscale(stack.vector())
    # z^r_t: robot 2 m straight ahead in the current person frame
    np.testing.assert_allclose(raw[0:3], [2.0, 0.0, 0.0], atol=1e-9)
    # z^h_{t-1}: the person 1 m behind its current pose; z^r_{t-1}: robot 1 m ahead
    np.testing.assert_allclose(raw[3:6], [-1.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(raw[6:9], [1.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(raw[9:12], [-2.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(raw[12:15], [0.0, 0.0, 0.0], atol=1e-9)
    assert stack.size == 15 == len(raw)


def test_full_size_scaling_and_clipping():
    stack = obs.ObservationStack()
    stack.reset([100.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    v = stack.vector()
    assert v.shape == (57,) == (obs.SIZE,)
    assert v.dtype == np.float32
    assert v[0] == 1.0  # 100 m is clipped at the 6 m scale
    assert np.all(np.abs(v) <= 1.0)


def test_relative_state_matches_the_papers_rotation():
    person = np.array([1.0, 2.0, 0.7])
    robot = np.array([2.5, 1.0, -0.4])
    rel = to_frame(robot, person)
    c, s = math.cos(person[2]), math.sin(person[2])
    # the paper's matrix applied to the world difference is the transpose rotation (world -> person)
    dx, dy = robot[0] - person[0], robot[1] - person[1]
    np.testing.assert_allclose(rel[:2], [c * dx + s * dy, -s * dx + c * dy])
    assert rel[2] == pytest.approx(-1.1)
    d, a = distance_and_alpha(robot, person)
    assert d == pytest.approx(math.hypot(dx, dy)) and a == pytest.approx(math.atan2(rel[1], rel[0]))


def test_noise_is_added_only_when_configured():
    clean = obs.ObservationStack(noise_std=None)
    noisy = obs.ObservationStack(noise_std=(0.05, 0.05))
    for s in (clean, noisy):
        s.reset([1.5, 0.0, 0.0], [0.0, 0.0, 0.0])
    rng = np.random.default_rng(0)
    a = clean.vector(rng)
    b = noisy.vector(rng)
    assert np.array_equal(a, clean.vector(np.random.default_rng(1)))
    assert not np.allclose(a, b)
    assert np.abs(a - b).max() < 0.1


def test_non_finite_frames_are_rejected():
    stack = obs.ObservationStack()
    with pytest.raises(ValueError, match="non-finite"):
        stack.push([0.0, float("nan"), 0.0], [0.0, 0.0, 0.0])


def test_mirror_is_the_observation_of_the_world_reflected_about_any_line():
    """Reflect a random walk of both poses about a line through the world (x -> x, y -> -y after
    moving and turning the world): the observation of the reflected world is mirror() of the
    original's, frame by frame; the wrong sign on x, y or phi in any frame would break it."""
    rng = np.random.default_rng(3)
    robots = np.cumsum(rng.normal(0, 0.3, (12, 3)), axis=0) + [1.5, 0.2, 0.1]
    persons = np.cumsum(rng.normal(0, 0.3, (12, 3)), axis=0)
    c, s, shift = math.cos(0.8), math.sin(0.8), np.array([2.0, -1.0])

    def reflect(pose):  # rotate the world by 0.8 rad and move it, then reflect it about its x axis
        x, y = c * pose[0] - s * pose[1] + shift[0], s * pose[0] + c * pose[1] + shift[1]
        return np.array([x, -y, -(pose[2] + 0.8)])

    plain, mirrored = obs.ObservationStack(), obs.ObservationStack()
    for r, p in zip(robots, persons):
        plain.push(r, p)
        mirrored.push(reflect(r), reflect(p))
    a, b = plain.vector(), mirrored.vector()
    assert not np.allclose(a, obs.mirror(a), atol=1e-3)  # the walk is not symmetric by itself
    np.testing.assert_allclose(b, obs.mirror(a), atol=1e-5)
    np.testing.assert_array_equal(obs.mirror(obs.mirror(a)), a)
    np.testing.assert_array_equal(obs.mirror(np.stack([a, b])), np.stack([obs.mirror(a), obs.mirror(b)]))
    with pytest.raises(ValueError, match="57 numbers"):
        obs.mirror(a[:-3])
