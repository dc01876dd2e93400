"""The paper's reward at hand-picked points, computed by hand from the formula."""

import math

import pytest

from lbgp.sim.rewards import distance_reward, follow_ahead_reward, follow_ahead_reward_array, orientation_reward, out_of_range

deg = math.radians


@pytest.mark.parametrize(
    "distance, expected",
    [
        (0.4, -1.0),  # too close
        (0.75, -0.25),  # -(1 - D)
        (1.0, 0.0),  # 0.5 (0.5 - 0.5)
        (1.5, 0.25),  # peak
        (1.8, 0.1),  # 0.5 (0.5 - 0.3)
        (2.0, 0.0),  # still the middle branch
        (2.0001, -0.250025),  # the paper's jump at D = 2: -0.25 (D - 1)
        (3.0, -0.5),
        (5.0, -1.0),
        (5.1, -1.0),  # too far
    ],
)
def test_distance_term(distance, expected):
    assert distance_reward(distance) == pytest.approx(expected)


@pytest.mark.parametrize(
    "alpha_deg, expected",
    [(0.0, 0.5), (10.0, 0.3), (-10.0, 0.3), (24.0, 0.02), (30.0, -0.25 * 30 / 180), (180.0, -0.25), (-90.0, -0.125)],
)
def test_orientation_term(alpha_deg, expected):
    assert orientation_reward(deg(alpha_deg)) == pytest.approx(expected)


@pytest.mark.parametrize(
    "distance, alpha_deg, expected",
    [
        (1.5, 0.0, 0.75),  # the best spot
        (1.5, 180.0, 0.0),  # behind: 0.25 - 0.25
        (0.3, 90.0, -1.0),  # clipped: -1 - 0.125
        (1.2, -12.5, 0.1 + 0.25),  # 0.5 (0.5 - 0.3) + 0.5 (25 - 12.5) / 25
        (4.0, 45.0, -0.75 - 0.0625),
    ],
)
def test_total_reward_is_clipped_sum(distance, alpha_deg, expected):
    assert follow_ahead_reward(distance, deg(alpha_deg)) == pytest.approx(expected)


def test_reward_rejects_non_finite_input():
    with pytest.raises(ValueError, match="finite"):
        follow_ahead_reward(float("nan"), 0.0)


def test_termination_range():
    assert out_of_range(0.49) and out_of_range(5.01)
    assert not out_of_range(0.5) and not out_of_range(1.5) and not out_of_range(5.0)


def test_array_reward_matches_the_scalar_one_everywhere():
    import numpy as np

    rng = np.random.default_rng(0)
    d = np.concatenate([rng.uniform(0.0, 6.0, 2000), [0.5, 1.0, 1.5, 2.0, 5.0]])
    a = np.concatenate([rng.uniform(-math.pi, math.pi, 2000), np.radians([0.0, 25.0, -25.0, 180.0, 90.0])])
    expected = [follow_ahead_reward(x, y) for x, y in zip(d, a)]
    assert np.allclose(follow_ahead_reward_array(d, a), expected)
