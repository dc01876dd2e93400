"""The loop detector: a robot circling while its goal is ahead counts, following a U-turn does not."""

import math

import numpy as np
import pytest

from lbgp.metrics import EpisodeMetrics, LoopDetector, aggregate, goal_ahead_of_person


def feed(robot_yaws, person_yaws, goal_ahead=True):
    detector = LoopDetector()
    for r, p in zip(robot_yaws, person_yaws):
        detector.add(r, p, goal_ahead)
    return detector.loops


def test_a_full_circle_with_the_goal_ahead_is_a_loop():
    yaws = np.linspace(0.0, 2.0 * math.pi, 30)  # 0.2 rad per step, wrapped by the detector
    assert feed(np.mod(yaws, 2 * math.pi), np.zeros(30)) == 1


def test_turning_with_the_person_is_not_a_loop():
    yaws = np.linspace(0.0, 1.5 * math.pi, 30)  # a person's U-turn and more, robot alongside
    assert feed(yaws + 0.1 * np.sin(np.arange(30)), yaws) == 0


def test_half_a_turn_is_not_a_loop_and_a_goal_behind_resets_the_count():
    assert feed(np.linspace(0.0, 0.95 * math.pi, 20), np.zeros(20)) == 0
    assert feed(np.linspace(0.0, 2.0 * math.pi, 30), np.zeros(30), goal_ahead=False) == 0


def test_loops_reach_the_summary_and_the_aggregate():
    m = EpisodeMetrics(setting="x")
    for yaw in np.linspace(0.0, 2.5 * math.pi, 40):
        m.add(1.5, 0.0, 0.5, yaw, 0.0, True)
    assert m.summary()["loops"] == 2  # 450 degrees: two half turns beyond the first
    assert aggregate([m, m, EpisodeMetrics()])["loops"] == 2  # episodes with a loop


def test_goal_ahead_of_person():
    person = np.array([1.0, 1.0, math.pi / 2])  # facing +y
    assert goal_ahead_of_person([1.0, 2.5], person)
    assert not goal_ahead_of_person([1.0, 0.5], person)
    assert goal_ahead_of_person(None, person)


def test_summary_reports_mean_abs_alpha_over_the_second_half():
    from lbgp.metrics import EpisodeMetrics

    m = EpisodeMetrics()
    for alpha in (3.0, -3.0, 0.1, -0.3):  # radians: the first half is far off, the second close
        m.add(1.5, alpha, 0.0)
    assert m.summary()["abs_alpha_second_half_deg"] == pytest.approx(math.degrees(0.2))
