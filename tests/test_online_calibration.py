"""Online command calibration: gains estimated from commands and measured poses while driving,
and the commands scaled by them; the simulator and the deploy loop feed it the same way."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lbgp.calibration import MAX_CORRECTION, load_calibration
from lbgp.experiments.real_protocol import run_setting
from lbgp.online_calibration import ONLINE_REFERENCE_GAINS, OnlineCalibration
from lbgp.rollout import ConstantGoalPolicy, run_episode
from lbgp.sim import make_env

DT = 0.1
REF_V, REF_W = ONLINE_REFERENCE_GAINS["jackal"]


def drive(cal: OnlineCalibration, wanted, gain=(1.0, 1.0), delay_ticks: int = 1, pose_noise: float = 0.0, seed: int = 0,
          drop=()):
    """A point robot answering the command sent ``delay_ticks`` ticks before with ``gain`` times it;
    ``wanted`` is a list of (v, w) per tick. Ticks listed in ``drop`` have no pose (a missed frame)."""
    rng = np.random.default_rng(seed)
    pose = np.zeros(3)
    sent = [(0.0, 0.0)] * delay_ticks
    for k, (v, w) in enumerate(wanted):
        measured = pose + rng.normal(0.0, pose_noise, 3)
        if k not in drop:
            cal.observe(k * DT, measured)
        sent.append(cal.apply(v, w))
        av, aw = gain[0] * sent[-1 - delay_ticks][0], gain[1] * sent[-1 - delay_ticks][1]
        mid = pose[2] + 0.5 * aw * DT
        pose = pose + np.array([av * DT * math.cos(mid), av * DT * math.sin(mid), aw * DT])
    return pose


def steady_turn(ticks=60, v=0.8, w=0.6):
    return [(v, w)] * ticks


def test_a_slippery_base_is_identified_and_its_commands_scaled_up():
    cal = OnlineCalibration("jackal")
    drive(cal, steady_turn(), gain=(1.0, 0.45), delay_ticks=2, pose_noise=0.002)
    assert cal.gains[1] == pytest.approx(0.45, rel=0.05)
    assert cal.gains[0] == pytest.approx(1.0, rel=0.05)
    # the correction: reference over gain, shrunk by the dead band (log-space), reached at the rate limit
    expected = math.exp(math.log(REF_W / cal.gains[1]) - math.log1p(cal.deadband))
    assert cal.scale_w == pytest.approx(expected, rel=0.02)
    assert cal.scale_v == 1.0  # v answers like the simulated robot: left alone
    assert cal.apply(1.0, 1.0) == pytest.approx((1.0, cal.scale_w))


def test_a_base_that_answers_like_the_simulated_one_is_left_alone():
    cal = OnlineCalibration("jackal")
    drive(cal, steady_turn(), gain=(REF_V * 1.05, REF_W * 0.95), pose_noise=0.002)
    assert math.isfinite(cal.gains[1])
    assert (cal.scale_v, cal.scale_w) == (1.0, 1.0)


def test_a_fast_turning_base_is_scaled_down_and_corrections_are_bounded():
    cal = OnlineCalibration("jackal")
    drive(cal, steady_turn(w=0.4), gain=(1.0, 1.6))
    assert cal.scale_w < 1.0 / 1.5
    cal = OnlineCalibration("jackal")
    drive(cal, steady_turn(ticks=200, w=0.6), gain=(1.0, 0.12))  # far beyond what calibration may correct
    assert cal.scale_w == pytest.approx(MAX_CORRECTION)


def test_transients_and_straight_driving_say_nothing_about_the_yaw_gain():
    cal = OnlineCalibration("jackal")
    wiggle = [(0.8, 0.8 * math.sin(1.3 * k)) for k in range(80)]  # w changes every tick: never steady
    drive(cal, wiggle, gain=(1.0, 0.4), delay_ticks=2)
    assert math.isnan(cal.gains[1]) and cal.scale_w == 1.0
    cal = OnlineCalibration("jackal")
    drive(cal, steady_turn(w=0.0), gain=(1.0, 0.4))
    assert math.isnan(cal.gains[1]) and cal.scale_w == 1.0
    assert cal.gains[0] == pytest.approx(1.0, rel=0.02)


def test_a_stuck_robot_is_not_taken_for_a_slippery_one():
    cal = OnlineCalibration("jackal")
    drive(cal, steady_turn(), gain=(0.0, 0.0))
    assert (cal.scale_v, cal.scale_w) == (1.0, 1.0)


def test_the_correction_grows_at_a_bounded_rate():
    cal = OnlineCalibration("jackal")
    scales = []
    for n in (16, 18, 20, 22):
        cal.forget()
        drive(cal, steady_turn(ticks=n), gain=(1.0, 0.3))
        scales.append(math.log(cal.scale_w))
    steps = np.diff(scales)
    assert np.all(steps > 0) and np.all(steps <= cal.max_rate * 2 * DT + 1e-9)


def test_missed_frames_and_nan_poses_skip_samples_without_harm():
    cal = OnlineCalibration("jackal")
    drive(cal, steady_turn(ticks=80), gain=(1.0, 0.45), drop=set(range(0, 80, 7)))  # each costs the samples around it
    assert cal.gains[1] == pytest.approx(0.45, rel=0.05)
    cal.observe(9.0, [np.nan, 0.0, 0.0])
    cal.observe(9.1, [0.0, 0.0, 0.0])
    assert cal.gains[1] == pytest.approx(0.45, rel=0.05) and math.isfinite(cal.scale_w)


def test_a_new_run_keeps_what_was_learned_and_forget_starts_over():
    cal = OnlineCalibration("jackal")
    drive(cal, steady_turn(), gain=(1.0, 0.45))
    learned = cal.scale_w
    cal.reset()
    assert cal.scale_w == learned > 1.3
    cal.forget()
    assert cal.scale_w == 1.0 and math.isnan(cal.gains[1])


def test_load_calibration_online_and_bad_settings():
    cal = load_calibration("online", "turtlebot2")
    assert isinstance(cal, OnlineCalibration) and cal.robot == "turtlebot2"
    assert load_calibration(cal, "turtlebot2") is cal
    with pytest.raises(ValueError, match="no online reference gains"):
        OnlineCalibration("roomba")
    with pytest.raises(ValueError, match="must be > 0"):
        OnlineCalibration("jackal", window=0.0)


@pytest.mark.parametrize("dynamics, slippery", [("hardware_like", True), ("nominal", False)])
def test_the_simulated_jackal_feeds_the_estimator(dynamics, slippery):
    """The hardware-like Jackal turns about half as much as commanded (docs/simulation.md): the
    estimate says so and the correction follows; the nominal one is left (almost) alone. 50 agent
    steps (10 s): the turn commands must hold steady before a sample counts, and since the planner
    lets the Jackal turn harder away from the person (2026-12-05) they are steady only late in the
    35-step episode (the estimate is there, 0.38, the correction has made one 0.2 s step of its rate)."""
    cal = OnlineCalibration("jackal")
    env = make_env("turning_outside", robot="jackal", seed=0, dynamics=dynamics, calibration=cal, horizon=50)
    run_episode(env, ConstantGoalPolicy())
    assert math.isfinite(cal.gains[1])
    if slippery:
        assert cal.gains[1] < 0.65 and cal.scale_w > 1.15
    else:
        assert cal.gains[1] > 0.7 and cal.scale_w < 1.1


def test_the_deploy_loop_feeds_the_estimator_from_mocap_poses():
    cal = OnlineCalibration("turtlebot2")
    run_setting(ConstantGoalPolicy(), "straight", "ahead_right", 40, 0, dynamics="hardware_like", calibration=cal)
    # identified from (noisy, dropped) mocap frames: the hardware-like Kobuki reaches the speed it is
    # told, only later (its firmware's acceleration limiter): not to be mistaken for a slow base
    assert cal.gains[0] == pytest.approx(ONLINE_REFERENCE_GAINS["turtlebot2"][0], rel=0.05)
    assert cal.scale_v == 1.0


def test_evaluate_online_carries_one_estimator_over_every_episode(monkeypatch):
    """``lbgp evaluate --calibration online``: one estimator for the whole evaluation (made once,
    then reused by every scenario's environment), so what the first scenario taught it is used
    from the start of the next."""
    from lbgp import cli
    from lbgp.sim import env as env_module

    seen = []
    original = env_module.make_env

    def recording_make_env(*args, **kwargs):
        seen.append(kwargs.get("calibration"))
        return original(*args, **kwargs)

    monkeypatch.setattr("lbgp.evaluate.make_env", recording_make_env)
    assert cli.main(["evaluate", "--method", "hc", "--scenario", "turning_outside,turning_ahead", "--episodes", "1",
                     "--dynamics", "hardware_like", "--calibration", "online"]) == 0
    assert len(seen) == 2 and isinstance(seen[0], OnlineCalibration) and seen[0] is seen[1]
    assert seen[0].scale_w > 1.15  # learned on the slippery hardware-like Jackal


def test_the_reference_gains_are_what_the_estimator_sees_on_the_nominal_jackal():
    """ONLINE_REFERENCE_GAINS come from benchmarks/online_calibration_reference.py; re-measured here
    on three of its episodes (corrections off), they agree within a few per cent."""
    from lbgp.policies import make_policy

    policy = make_policy("hc", robot="jackal")
    gains = []
    for scenario in ("turning_inside", "turning_outside", "trajectory_one"):
        cal = OnlineCalibration("jackal", deadband=1e9)  # measure only: commands never scaled
        run_episode(make_env(scenario, robot="jackal", seed=0, obs_noise=True, calibration=cal), policy)
        assert cal.scale_w == 1.0
        gains.append(cal.gains)
    v, w = np.median(np.array(gains), axis=0)
    assert v == pytest.approx(REF_V, rel=0.03)
    assert w == pytest.approx(REF_W, rel=0.06)


def test_the_deploy_log_records_the_scale_each_command_was_sent_with(tmp_path):
    """--calibration online --log: every tick's /lbgp/status says the scale its /cmd_vel carries,
    from 1 at the start to what the slippery hardware-like Jackal taught the estimator."""
    import json

    from lbgp.real.deploy import deploy
    from lbgp.real.replay import replay_log

    loop = deploy(ConstantGoalPolicy((1.5, 0.0)), source="sim://turning_outside", robot="jackal", steps=50,
                  log=tmp_path / "run.mcap", dynamics="hardware_like", calibration="online")
    _, log = replay_log(tmp_path / "run.mcap")
    statuses = [json.loads(message.data) for _, message in log["/lbgp/status"]]
    scales = [s["command_scale"][1] for s in statuses if "command_scale" in s]
    assert scales[-1] == pytest.approx(loop.cfg.calibration.scale_w) and max(scales) > 1.15
    assert "command_scale" not in statuses[0]  # nothing learned yet: the command went out as planned
