"""Robot dynamics (lbgp.dynamics, lbgp.drive_train, lbgp.sim.drive): named parameters applied to the MuJoCo model and
the drive train, domain randomisation, and the simulator's default staying what it was."""

import json
import math

import numpy as np
import pytest

from lbgp.dynamics import HARDWARE_LIKE, Dynamics, Randomization, load_dynamics, load_randomization
from lbgp.sim import make_env
from lbgp.drive_train import DriveTrain, simulate_setpoints


def test_drive_train_delays_limits_and_lags_a_step_command():
    drive = DriveTrain(Dynamics(latency=0.1, max_linear_accel=1.0, max_angular_accel=2.0, time_constant=0.0))
    drive.command(0.0, 0.5, 1.0)
    out = [drive.advance(0.01) for _ in range(100)]
    v = np.array([o[0] for o in out])
    assert np.all(v[:9] == 0.0)  # nothing before the latency
    assert v[19] == pytest.approx(0.1, abs=0.011)  # 0.1 s of ramping at 1 m/s^2
    assert v[-1] == pytest.approx(0.5)
    lag = DriveTrain(Dynamics(time_constant=0.2))
    lag.command(0.0, 1.0, 0.0)
    after_tau = [lag.advance(0.005) for _ in range(40)][-1][0]
    assert after_tau == pytest.approx(1 - math.exp(-1), abs=0.02)


def test_simulated_setpoints_match_a_stepped_drive_train():
    dyn = Dynamics(latency=0.05, time_constant=0.1, max_linear_accel=0.8, max_angular_accel=3.0)
    times = np.arange(0, 3, 0.1)
    cmds = np.stack([0.4 * np.sin(times), np.sign(np.sin(2 * times))], axis=1)
    samples = np.arange(0.02, 3.0, 0.02)
    got = simulate_setpoints(dyn, times, cmds, samples, dt=0.005)
    drive, ref, k, t = DriveTrain(dyn), [], 0, 0.0
    for ts in samples:
        while t + 0.005 <= ts + 1e-12:
            while k < len(times) and times[k] <= t + 1e-12:
                drive.command(times[k], *cmds[k])
                k += 1
            last = drive.advance(0.005)
            t += 0.005
        ref.append(last)
    assert np.allclose(got, ref)


def test_nominal_dynamics_keep_todays_simulator_bit_identical():
    a = make_env("turning_ahead", seed=1, control="velocity")
    b = make_env("turning_ahead", seed=1, control="velocity", dynamics="nominal")
    for env in (a, b):
        env.reset()
    assert a.physics.drivetrain is None  # the ideal drive: commands reach the servos at once
    for k in range(10):
        ta, tb = a.step([0.5, 0.3]), b.step([0.5, 0.3])
        assert np.array_equal(ta.observation, tb.observation)


def test_hardware_like_dynamics_reach_the_model_and_slow_the_response():
    env = make_env("turning_ahead", robot="turtlebot2", seed=0, control="velocity", dynamics="hardware_like")
    env.reset()
    m, md = env.physics.model.ptr, env.physics.model_dynamics
    hw = HARDWARE_LIKE["turtlebot2"]
    assert np.allclose(m.body_mass[md.bodies], md.mass * hw.mass_scale)
    assert np.allclose(m.geom_friction[md.wheel_geoms, 0], hw.sliding_friction)
    ideal = make_env("turning_ahead", robot="turtlebot2", seed=0, control="velocity")
    speeds = []
    for e in (ideal, env):
        e.reset()
        e.step([0.6, 0.0])  # 0.2 s of full speed ahead
        speeds.append(e.physics.robot_velocity()[0])
    assert speeds[1] < 0.5 * speeds[0]  # latency 0.1 s + lag + the Kobuki's 0.5 m/s^2 limiter


def test_randomisation_draws_per_episode_within_ranges_and_is_seeded():
    def draws(seed):
        env = make_env("circles", seed=seed, randomize="default")
        out = []
        for _ in range(6):
            env.reset()
            d = env.task.episode_dynamics
            out.append((d.latency, d.mass_scale, env.task.stack.noise_std[0]))
        return np.array(out)

    a, b = draws(4), draws(4)
    assert np.array_equal(a, b)  # seeded
    assert len(set(a[:, 0])) == 6  # a fresh draw every episode
    r = load_randomization("default")
    assert np.all((a[:, 0] >= r.latency[0]) & (a[:, 0] <= r.latency[1]))
    assert np.all((a[:, 1] >= r.mass_scale[0]) & (a[:, 1] <= r.mass_scale[1]))
    assert make_env("circles", seed=4).task.randomization is None  # off unless asked for


def test_dynamics_files_and_bad_input(tmp_path):
    good = tmp_path / "d.json"
    good.write_text(json.dumps({"dynamics": {"latency": 0.07, "max_linear_accel": None}}))
    d = load_dynamics(good, "turtlebot2")
    assert d.latency == 0.07 and math.isinf(d.max_linear_accel) and d.mass_scale == 1.0
    for text, match in (('{"latency": -1}', "latency"), ('{"warp": 1}', "unknown dynamics"), ('{"latency": "x"}', "number"),
                        ("[1, 2]", "JSON object"), ('{"latency": null}', "latency must be a number"), ("{oops", "not readable JSON")):
        bad = tmp_path / "bad.json"
        bad.write_text(text)
        with pytest.raises(ValueError, match=match):
            load_dynamics(bad, "jackal")
    with pytest.raises(ValueError, match="does not exist"):
        load_dynamics(tmp_path / "missing.json", "jackal")
    with pytest.raises(ValueError, match="lo <= hi"):
        Randomization("x", latency=(0.2, 0.1)).validate()
    with pytest.raises(ValueError, match="unknown randomization preset"):
        load_randomization("wild")
    assert Dynamics.from_dict(Dynamics(latency=0.1).to_dict()) == Dynamics(latency=0.1)
