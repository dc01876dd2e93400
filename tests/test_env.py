"""Follow-ahead tasks: every level and scenario, both robots, both control modes."""

import math

import dm_env
import numpy as np
import pytest

from lbgp.actions import action_from_goal
from lbgp.sim import all_names, make_env
from lbgp.sim.rewards import distance_reward, follow_ahead_reward
from lbgp.sim.tasks import CURRICULUM, LEVELS, SCENARIOS

ROBOTS = ["jackal", "turtlebot2"]


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("level", all_names())
def test_every_level_and_scenario_runs_within_its_specs(level, robot):
    env = make_env(level, robot=robot, seed=3, horizon=8)
    obs_spec, act_spec = env.observation_spec(), env.action_spec()
    assert obs_spec.shape == (57,) and act_spec.shape == (2,)
    timestep = env.reset()
    rng = np.random.default_rng(0)
    steps = 0
    while True:
        obs = timestep.observation
        obs_spec.validate(obs)
        assert np.all(np.isfinite(obs)) and np.all(np.abs(obs) <= 1.0)
        if timestep.last():
            break
        timestep = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        steps += 1
        assert -1.0 <= timestep.reward <= 1.0
        info = env.info()
        assert info["distance"] >= 0 and -math.pi <= info["alpha"] <= math.pi
    assert steps <= 8


def test_curriculum_levels_and_scenario_names():
    assert CURRICULUM == ("straight", "circles", "smoothed", "trajectories")
    assert set(SCENARIOS) == {
        "straight_ahead", "straight_behind", "turning_ahead", "turning_behind", "turning_inside",
        "turning_outside", "trajectory_one", "trajectory_two", "trajectory_three",
    }


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("distance", [0.4, 5.2])
def test_termination_when_teleported_too_close_or_too_far(robot, distance):
    env = make_env("straight", robot=robot, seed=0)
    env.reset()
    env.place_robot(distance, 0.0)
    timestep = env.step(np.zeros(2, np.float32))
    assert timestep.last() and timestep.discount == 0.0
    info = env.info()
    assert timestep.reward == pytest.approx(follow_ahead_reward(info["distance"], info["alpha"]))
    assert distance_reward(info["distance"]) == -1.0


def test_horizon_truncates_with_discount_one():
    env = make_env("straight_ahead", seed=0, horizon=5)
    timestep = env.reset()
    n = 0
    while not timestep.last():
        timestep = env.step(action_from_goal([1.5, 0.0]))
        n += 1
    assert n == 5 and timestep.step_type == dm_env.StepType.LAST and timestep.discount == 1.0


def test_default_horizon_is_35():
    env = make_env("straight_ahead", seed=0)
    timestep = env.reset()
    n = 0
    while not timestep.last():
        timestep = env.step(action_from_goal([1.5, 0.0]))
        n += 1
    assert n == 35


@pytest.mark.parametrize("robot", ROBOTS)
def test_contact_with_the_person_is_detected_and_terminates(robot):
    env = make_env("straight", robot=robot, seed=0, control="velocity")
    env.reset()
    env.place_robot(0.3, 0.0, relative_yaw=math.pi)  # overlapping the person's shoulder box
    timestep = env.step(np.zeros(2, np.float32))
    assert env.info()["contact"]
    assert timestep.last() and timestep.discount == 0.0


def test_no_contact_reported_when_close_but_not_touching():
    env = make_env("straight", robot="jackal", seed=0, control="velocity")
    env.reset()
    # beside the person, 0.45 m centre to centre: 6 cm gap between chassis and shoulder box
    env.place_robot(0.45, math.pi / 2)
    timestep = env.step(np.zeros(2, np.float32))
    assert not env.info()["contact"]
    assert timestep.last() and timestep.discount == 0.0  # still too close: D < 0.5 m


def test_spawn_rules():
    env = make_env("circles", seed=1)
    for _ in range(10):
        env.reset()
        d = env.info()["distance"]
        assert 1.0 - 1e-6 <= d <= 2.5 + 1e-6
    for name, setting in SCENARIOS.items():
        env = make_env(name, seed=0)
        env.reset()
        info = env.info()
        assert info["distance"] == pytest.approx(setting.spawn[0], abs=1e-6)
        assert math.degrees(info["alpha"]) == pytest.approx(setting.spawn[1], abs=1e-6) or abs(setting.spawn[1]) == 180
        assert info["robot_pose"][2] == pytest.approx(info["person_pose"][2], abs=1e-6)


def test_noise_defaults_on_for_levels_off_for_scenarios():
    assert all(s.noise for s in LEVELS.values()) and not any(s.noise for s in SCENARIOS.values())
    env = make_env("straight_ahead", seed=0, obs_noise=True)
    a = env.reset().observation
    b = make_env("straight_ahead", seed=0, obs_noise=False).reset().observation
    assert not np.allclose(a, b) and np.abs(a - b).max() < 0.1


def test_seeding_is_reproducible():
    def rollout(seed):
        env = make_env("smoothed", seed=seed, horizon=6)
        ts = env.reset()
        out = [ts.observation]
        while not ts.last():
            ts = env.step(action_from_goal([1.5, 0.5]))
            out.append(ts.observation)
        return np.array(out)

    np.testing.assert_array_equal(rollout(7), rollout(7))
    assert not np.array_equal(rollout(7), rollout(8))


def test_velocity_control_drives_the_robot():
    env = make_env("straight_ahead", seed=0, control="velocity")
    env.reset()
    x0 = env.info()["robot_pose"][0]
    for _ in range(5):
        env.step(np.array([0.5, 0.0], np.float32))  # 0.5 m/s
    assert env.info()["robot_pose"][0] - x0 == pytest.approx(0.5 * 1.0, abs=0.15)


def test_person_path_from_csv(tmp_path):
    f = tmp_path / "walk.csv"
    f.write_text("x,y\n0,0\n2,0\n4,1\n")
    env = make_env("trajectory_one", seed=0, person_path=f)
    env.reset()
    for _ in range(10):
        env.step(action_from_goal([1.5, 0.0]))
    person = env.info()["person_pose"]
    assert person[0] == pytest.approx(1.0, abs=0.2) and abs(person[1]) < 0.3  # 2 s at 0.5 m/s


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(level="stairs"), "unknown level or scenario 'stairs'"),
        (dict(level="straight", robot="r2d2"), "unknown robot 'r2d2'"),
        (dict(level="straight", control="teleport"), "unknown control mode 'teleport'"),
        (dict(level="straight", horizon=0), "horizon must be at least 1"),
    ],
)
def test_bad_arguments_name_the_problem(kwargs, message):
    with pytest.raises(ValueError, match=message):
        make_env(**kwargs)


def test_bad_person_path_names_the_problem(tmp_path):
    from lbgp.sim.paths import PathError

    f = tmp_path / "bad.csv"
    f.write_text("x,y\n0,0\n")
    with pytest.raises(PathError, match="at least two points"):
        make_env("straight", person_path=f)


@pytest.mark.parametrize("level", ["straight_ahead", "turning_ahead"])
def test_the_planner_sees_the_persons_true_speed_and_turn_rate_at_every_call(level):
    """Both planner calls of an agent step (at its start and in its middle) get the person's
    velocity over the same 0.2 s window, as the deploy loop computes it. (The middle call once
    divided 0.3 s of motion by 0.2 s: the person seemed 1.5 x as fast every other call, and the
    robot closed in on a person it overtook.)"""
    env = make_env(level, robot="jackal", seed=0)
    task = env.task
    seen = []
    command = task.controller.command

    def spy(state):
        seen.append((float(np.hypot(*state.person_velocity)), state.person_turn_rate))
        return command(state)

    task.controller.command = spy
    env.reset()
    for _ in range(6):
        env.step(np.zeros(2))
    v_true, w_true = task.person_cmd
    assert len(seen) == 12  # two planner calls per agent step
    speeds, turns = np.array(seen[3:]).T  # after the first 0.2 s window has filled
    chord = np.sinc(w_true * 0.2 / (2 * np.pi))  # a turning person's 0.2 s chord is a little shorter than its arc
    np.testing.assert_allclose(speeds, v_true * chord, rtol=1e-6)
    np.testing.assert_allclose(turns, w_true, rtol=1e-6, atol=1e-9)
    assert seen[0] == (0.0, 0.0)  # nothing to difference at the episode's first call
