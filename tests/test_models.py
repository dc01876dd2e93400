"""MJCF models: every scene compiles and runs; the drive mapping; bad model files."""

import mujoco
import numpy as np
import pytest

from lbgp.robots import JACKAL, ROBOTS, TURTLEBOT2, DiffDrive, get_robot
from lbgp.sim.tasks import load_physics


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_scene_steps_2s_under_random_wheel_commands_without_warnings(name):
    spec = get_robot(name)
    model = mujoco.MjModel.from_xml_path(str(spec.scene_path))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    steps = int(round(2.0 / model.opt.timestep))
    for k in range(steps):
        if k % 20 == 0:
            data.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_step(model, data)
    assert all(w.number == 0 for w in data.warning), [w.number for w in data.warning]
    assert np.all(np.isfinite(data.qpos))
    # the robot stays on the floor (no tunnelling, no flying off)
    assert 0.0 < data.qpos[2] < 0.2


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_robot_file_compiles_alone_and_has_its_actuators(name):
    spec = get_robot(name)
    model = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    names = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, i) for i in range(model.nu)}
    assert names == set(spec.left_actuators + spec.right_actuators)


def test_diff_drive_round_trip_and_signs():
    drive = DiffDrive(wheel_radius=0.1, track=0.5)
    left, right = drive.wheel_speeds(1.0, 0.0)
    assert left == pytest.approx(10.0) and right == pytest.approx(10.0)
    left, right = drive.wheel_speeds(0.0, 1.0)  # turning left: right wheel forward
    assert right > 0 > left
    for v, w in [(0.3, -1.2), (-0.5, 0.7), (1.9, 0.0)]:
        assert drive.body_velocity(*drive.wheel_speeds(v, w)) == pytest.approx((v, w))


def _steady_velocity(spec, v, w, seconds=2.0):
    physics = load_physics(spec)
    physics.set_person_pose([20.0, 20.0, 0.0])
    physics.set_robot_pose([0.0, 0.0, 0.0])
    physics.drive_wheels(v, w)
    physics.step_physics(int(seconds / physics.model.opt.timestep))
    samples = []
    for _ in range(50):
        physics.step_physics(4)
        samples.append(physics.robot_velocity())
    return np.mean(samples, axis=0)


@pytest.mark.parametrize("spec", [JACKAL, TURTLEBOT2], ids=["jackal", "turtlebot2"])
def test_commanded_body_velocity_is_achieved(spec):
    """The one (v, w) -> wheel mapping drives each robot at roughly the commanded velocity,
    including turning in place (the skid-steer Jackal through its calibrated effective track)."""
    v, w = _steady_velocity(spec, 0.5, 0.0)
    assert v == pytest.approx(0.5, abs=0.05) and abs(w) < 0.05
    v, w = _steady_velocity(spec, 0.0, 1.0)
    assert abs(v) < 0.05 and w == pytest.approx(1.0, rel=0.3)


def test_turtlebot_top_speed_is_about_0_7():
    v, _ = _steady_velocity(TURTLEBOT2, 2.0, 0.0)
    assert 0.6 < v < 0.75


def test_malformed_mjcf_raises_clear_error(tmp_path, monkeypatch):
    import lbgp.robots as robots

    bad_dir = tmp_path / "mjcf" / "jackal"
    bad_dir.mkdir(parents=True)
    (bad_dir / "scene.xml").write_text("<mujoco><worldbody><body name='robot'></worldbod></mujoco>")
    monkeypatch.setattr(robots, "_assets_dir", lambda: tmp_path / "mjcf")
    with pytest.raises(ValueError, match="cannot load MJCF scene .*scene.xml"):
        load_physics(JACKAL)


def test_unknown_robot_name_is_rejected():
    with pytest.raises(ValueError, match="unknown robot 'roomba'.*jackal"):
        get_robot("roomba")
