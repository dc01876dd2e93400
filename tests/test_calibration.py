"""Command calibration: identified gains -> command scales; applied where commands leave lbgp
(simulated wheels, the deploy loop's sink), never in the planner's own command chain."""

import json

import numpy as np
import pytest

from lbgp.calibration import SIM_REFERENCE_GAINS, CommandCalibration, load_calibration
from lbgp.real.loop import DeployConfig, DeployLoop
from lbgp.real.sim_world import SimCommandSink, SimPoseSource, SimWorld
from lbgp.rollout import ConstantGoalPolicy
from lbgp.sim import make_env


def test_gains_are_taken_relative_to_the_simulated_robot():
    ref_v, ref_w = SIM_REFERENCE_GAINS["jackal"]
    cal = CommandCalibration.from_gains("jackal", ref_v, ref_w / 2)  # turns half as much as the simulated Jackal
    assert cal.scale_v == pytest.approx(1.0) and cal.scale_w == pytest.approx(2.0)
    assert cal.apply(0.5, -0.4) == pytest.approx((0.5, -0.8))
    assert CommandCalibration().is_identity and not cal.is_identity


def test_files_load_and_bad_ones_name_the_problem(tmp_path):
    sysid = tmp_path / "sysid.json"
    sysid.write_text(json.dumps({"dynamics": {}, "fit": {"gain_v": 0.99, "gain_w": 0.43}, "robot": "jackal"}))
    cal = load_calibration(sysid, "jackal")
    assert cal.scale_w == pytest.approx(SIM_REFERENCE_GAINS["jackal"][1] / 0.43) and str(sysid) in cal.source
    scales = tmp_path / "scales.json"
    scales.write_text('{"scale_w": 1.4}')
    assert load_calibration(scales, "turtlebot2") == CommandCalibration(1.0, 1.4, str(scales))
    assert load_calibration("none", "jackal").is_identity and load_calibration(None, "jackal").is_identity
    cases = [
        ("missing.json", None, "does not exist"),
        ("junk.json", "{not json", "not readable JSON"),
        ("list.json", "[1, 2]", "expected a JSON object"),
        ("other.json", '{"fit": {"gain_v": 1, "gain_w": 1}, "robot": "turtlebot2"}', "identified on turtlebot2, not jackal"),
        ("zero.json", '{"fit": {"gain_v": 1, "gain_w": 0}}', "gain_w must be a positive number"),
        ("nan.json", '{"scale_v": NaN}', "scale_v must be within"),
        ("wild.json", '{"scale_w": 10}', "scale_w must be within"),
        ("empty.json", "{}", "expected lbgp sysid's output"),
    ]
    for name, text, needle in cases:
        path = tmp_path / name
        if text is not None:
            path.write_text(text)
        with pytest.raises(ValueError, match=needle):
            load_calibration(path, "jackal")


def yaw_turned(calibration) -> tuple[float, list[float], np.ndarray]:
    """Turn with E2E-style velocity commands for 1 s; (yaw turned, commands the task kept, the
    wheel actuators' last setpoints)."""
    env = make_env("straight_ahead", robot="turtlebot2", seed=0, control="velocity", calibration=calibration)
    env.reset()
    yaw0 = env.physics.robot_pose()[2]
    kept = []
    action = np.array([-1.0, 0.3])  # slowest v, a gentle left turn
    for _ in range(5):
        assert not env.step(action).last()
        kept.append(env.task.last_command.w)
    return float(env.physics.robot_pose()[2] - yaw0), kept, np.array(env.physics.data.ctrl)


def test_simulated_wheels_get_the_calibrated_command_and_the_task_keeps_its_own():
    plain, kept_plain, wheels_plain = yaw_turned(None)
    scaled, kept_scaled, wheels_scaled = yaw_turned(CommandCalibration(1.0, 1.5))
    assert kept_plain == kept_scaled  # the controller's command chain is untouched
    assert np.ptp(wheels_plain) > 0.5
    # wheel speeds: their sum follows v (scale 1), their difference w (scale 1.5)
    assert wheels_scaled.sum() == pytest.approx(wheels_plain.sum())
    assert np.diff(wheels_scaled)[0] == pytest.approx(1.5 * np.diff(wheels_plain)[0])
    assert abs(plain) > 0.3 and scaled / plain > 1.3  # and the base turns further


def test_deploy_loop_sends_and_logs_the_calibrated_command():
    world = SimWorld(robot="turtlebot2", seed=0)
    source = SimPoseSource(world, seed=0)
    cal = CommandCalibration(0.9, 1.6)
    loop = DeployLoop(source, SimCommandSink(world), ConstantGoalPolicy(), DeployConfig(robot="turtlebot2", max_steps=10, calibration=cal))
    planned = []
    tick = loop.tick

    def tick_and_remember():
        record = tick()
        planned.append(loop.command)  # the planner-side command the next tick chains from
        return record

    loop.tick = tick_and_remember
    loop.run()
    moving = [(r, p) for r, p in zip(loop.records, planned) if abs(p[0]) > 1e-3 or abs(p[1]) > 1e-3]
    assert len(moving) > 5
    for record, (v, w) in moving:
        assert (record.v, record.w) == pytest.approx((0.9 * v, 1.6 * w))
