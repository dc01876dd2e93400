"""The planner's drive model (lbgp.drive_model): the prediction of the state when a command acts,
checked against exact kinematics and against MuJoCo; the limits; wiring into sim, deploy and CLI."""

import math

import numpy as np
import pytest

from lbgp.cli import main
from lbgp.drive_model import DrivePrediction, load_drive_model, within_drive_limits
from lbgp.dynamics import HARDWARE_LIKE, Dynamics
from lbgp.planner import planner_config_for
from lbgp.policies import make_policy
from lbgp.sim.env import make_env
from lbgp.stack import make_controller, planner_limits
from lbgp.world import WorldState


def state(t=0.0, robot=(0.0, 0.0, 0.0), person=(-1.5, 0.0, 0.0), person_velocity=(0.0, 0.0), turn=0.0):
    return WorldState(t, np.array(robot, float), np.zeros(2), np.array(person, float), np.array(person_velocity, float), turn)


def test_commands_in_flight_move_the_predicted_robot_by_what_they_will_do():
    pred = DrivePrediction(Dynamics(latency=0.2))
    assert pred.predict(state(0.0)).robot_pose == pytest.approx([0.0, 0.0, 0.0])  # nothing sent: it stays
    pred.sent(0.0, 0.4, 0.0)  # acts at t = 0.2
    seen = pred.predict(state(0.1))  # over [0.1, 0.3] it drives at 0.4 m/s for 0.1 s
    assert seen.t == pytest.approx(0.3)
    # (the drive train, like the simulator's, applies a command from the 5 ms step that ends at its arrival)
    assert seen.robot_pose == pytest.approx([0.04, 0.0, 0.0], abs=2.5e-3)
    pred.sent(0.1, 0.4, 1.0)  # a turn that acts at 0.3: over [0.2, 0.4] 0.1 s straight, then 0.1 s on an arc
    seen = pred.predict(state(0.2))
    arc = 0.4 / 1.0 * np.array([math.sin(0.1), 1.0 - math.cos(0.1)])
    assert seen.robot_pose == pytest.approx([0.04 + arc[0], arc[1], 0.1], abs=6e-3)
    pred.reset()
    assert pred.predict(state(0.3)).robot_pose == pytest.approx([0.0, 0.0, 0.0])  # forgotten


def test_the_limiter_and_the_lag_slow_the_predicted_motion():
    fast, slow = DrivePrediction(Dynamics(latency=0.1)), DrivePrediction(Dynamics(latency=0.1, max_linear_accel=0.5, time_constant=0.12))
    for pred in (fast, slow):
        for k in range(3):
            pred.sent(0.1 * k, 0.6, 0.0)
    x_fast, x_slow = fast.predict(state(0.3)).robot_pose[0], slow.predict(state(0.3)).robot_pose[0]
    assert x_fast == pytest.approx(0.06, abs=1e-3)  # at 0.6 m/s over the whole latency
    assert 0.0 < x_slow < 0.5 * x_fast  # 0.5 m/s^2 from rest: below 0.15 m/s by t = 0.4, less after the lag


def test_the_person_moves_along_the_arc():
    pred = DrivePrediction(Dynamics(latency=0.25))
    seen = pred.predict(state(0.0, person=(1.0, 2.0, 0.3), person_velocity=(1.0 * math.cos(0.3), 1.0 * math.sin(0.3)), turn=0.8))
    # exact constant-turn arc: speed 1, turn 0.8 rad/s, 0.25 s
    yaw0, yaw1 = 0.3, 0.3 + 0.8 * 0.25
    exact = np.array([1.0 + (math.sin(yaw1) - math.sin(yaw0)) / 0.8, 2.0 - (math.cos(yaw1) - math.cos(yaw0)) / 0.8])
    assert seen.person_pose[:2] == pytest.approx(exact, abs=1e-3)
    assert seen.person_pose[2] == pytest.approx(yaw1)
    assert seen.person_velocity == pytest.approx([math.cos(yaw1), math.sin(yaw1)])
    assert seen.robot_velocity == pytest.approx([0.0, 0.0])  # the planner still chains from the last command


def test_the_prediction_matches_mujoco_on_the_hardware_like_robot():
    """On the hardware-like TurtleBot 2 in MuJoCo (latency, lag, 0.5 m/s^2 limiter), the pose predicted
    one latency ahead is much closer to where the robot really is then than the stale measured pose."""
    env = make_env("straight_ahead", robot="turtlebot2", seed=0, dynamics=HARDWARE_LIKE["turtlebot2"].replace(latency_jitter=0.0),
                   drive_model=HARDWARE_LIKE["turtlebot2"].replace(latency_jitter=0.0))
    task = env.task
    prediction = task.controller.prediction
    assert prediction is not None and prediction.horizon == pytest.approx(0.1)
    predicted, stale = {}, {}
    plan = task.controller.command
    def spy(state):  # noqa: E306 - record what the controller predicted for the tick one latency ahead
        key = round(state.t + prediction.horizon, 3)
        predicted[key], stale[key] = prediction.predict(state).robot_pose[:2], state.robot_pose[:2].copy()
        return plan(state)
    task.controller.command = spy
    env.reset()
    errors_pred, errors_stale = [], []
    for _ in range(15):
        env.step(np.array([0.0, 0.0]))
        now = round(float(env.physics.data.time), 3)
        if now in predicted:
            actual = env.physics.robot_pose()[:2]
            errors_pred.append(np.linalg.norm(predicted[now] - actual))
            errors_stale.append(np.linalg.norm(stale[now] - actual))
    assert len(errors_pred) >= 10 and max(errors_stale) > 0.04  # the robot really moves
    assert np.mean(errors_pred) < 0.35 * np.mean(errors_stale)


def test_planner_keeps_within_the_drive_limits():
    limits = planner_limits("turtlebot2")
    hw = HARDWARE_LIKE["turtlebot2"]
    assert within_drive_limits(limits, None) is limits
    lowered = within_drive_limits(limits, hw)
    assert lowered.acc_lim_x == 0.5 and lowered.acc_lim_theta == min(limits.acc_lim_theta, 3.5)
    controller = make_controller("goal", limits, hw)
    assert controller.planner.cfg.acc_lim_x == 0.5
    assert make_controller("velocity", limits, hw).limits is limits  # E2E's commands are its own
    # from rest towards a goal far ahead: each command's v rises by at most 0.5 m/s^2 * 0.1 s
    vs, s = [0.0], state(0.0, robot=(0.0, 0.0, 0.0), person=(-1.5, 0.0, 0.0), person_velocity=(1.0, 0.0))
    controller.set_goal([3.0, 0.0])
    for k in range(8):
        s.t, s.robot_velocity = 0.1 * k, np.array([vs[-1], 0.0])
        vs.append(controller.command(s).v)
    assert max(np.diff(vs)) <= 0.05 + 1e-6 and vs[-1] > 0.3


def test_an_ideal_drive_model_changes_nothing():
    """The nominal drive (no latency, no limiter) predicts no motion and keeps the limits: same episode."""
    runs = []
    for model in (None, "nominal"):
        env = make_env("turning_ahead", robot="turtlebot2", seed=3, horizon=6, drive_model=model)
        env.reset()
        runs.append([env.step(np.array([0.1, -0.2])).reward for _ in range(6)])
    assert runs[0] == runs[1]
    assert load_drive_model("none", "jackal") is None and load_drive_model(None, "jackal") is None
    assert planner_config_for("turtlebot2").acc_lim_x == 1.0  # the preset itself is untouched


def test_deploy_and_protocol_plan_with_the_drive_model(tmp_path):
    from lbgp.experiments.real_protocol import run_setting
    from lbgp.real.deploy import deploy

    policy = make_policy("hc")
    log = tmp_path / "run.mcap"
    loop = deploy(policy, source="sim://straight_ahead", steps=3, robot="turtlebot2", log=log, drive_model="hardware_like")
    assert loop.error is None and loop.controller.prediction is not None and loop.controller.planner.cfg.acc_lim_x == 0.5
    from lbgp.real.mcap_log import read_log

    assert "max_linear_accel" in read_log(log)["metadata"]["drive_model"]
    with_model = run_setting(policy, "straight", "ahead", steps=12, dynamics="hardware_like", drive_model="hardware_like")
    without = run_setting(policy, "straight", "ahead", steps=12, dynamics="hardware_like")
    assert with_model.total_reward != without.total_reward


def test_cli_takes_a_sysid_file_as_drive_model_and_refuses_a_bad_one(tmp_path, capsys):
    good = tmp_path / "dyn.json"
    good.write_text('{"dynamics": {"latency": 0.1, "max_linear_accel": 0.5}, "rms_v": 0.01}')
    out = tmp_path / "eval.json"
    assert main(["evaluate", "--method", "hc", "--robot", "turtlebot2", "--scenario", "straight_ahead", "--episodes", "1",
                 "--drive-model", str(good), "--json", str(out)]) == 0
    bad = tmp_path / "bad.json"
    bad.write_text('{"dynamics": {"latency": "soon"}}')
    assert main(["evaluate", "--method", "hc", "--scenario", "straight_ahead", "--episodes", "1", "--drive-model", str(bad)]) == 2
    assert "latency" in capsys.readouterr().err
    assert main(["evaluate", "--drive-model", str(tmp_path / "missing.json")]) == 2
    assert "missing.json: no such file" in capsys.readouterr().err


def test_the_deploy_loops_safety_stop_is_a_command_in_flight_for_the_drive_model():
    """After a too_close stop the base is braking: the prediction must integrate the stop ramp the
    loop sent, not the last planned command (which would predict the robot still driving)."""
    from lbgp.real.frames import PoseFrame
    from lbgp.real.loop import DeployConfig, DeployLoop
    from lbgp.real.replay import ReplayClock
    from lbgp.real.safety import TOO_CLOSE
    from lbgp.rollout import ConstantGoalPolicy

    class Scripted:
        clock = ReplayClock()
        person = np.array([-1.5, 0.0, 0.0])

        def poll(self, now, timeout=0.0):
            return [PoseFrame(now + 100.0, np.zeros(3), self.person.copy(), now)]  # its own clock, 100 s ahead

    class Sink:
        def send(self, t, v, w, status="ok"):
            pass

    source = Scripted()
    config = DeployConfig(robot="turtlebot2", drive_model=Dynamics(latency=0.2))
    loop = DeployLoop(source, Sink(), ConstantGoalPolicy((3.0, 0.0)), config, clock=source.clock)
    for k in range(10):
        source.clock.sleep_until(0.1 * k)
        assert loop.tick().status == "ok"
    assert loop.command[0] > 0.2  # driving towards the goal 1.5 m ahead
    driving = state(100.9)
    ahead = loop.controller.prediction.predict(driving).robot_pose[0]
    assert ahead > 0.03  # in flight: 0.2 s of driving

    source.person = np.array([-0.3, 0.0, 0.0])  # the person steps up to the robot
    for k in range(10, 15):
        source.clock.sleep_until(0.1 * k)
        assert loop.tick().status == TOO_CLOSE
    assert loop.command == (0.0, 0.0)
    stopped = loop.controller.prediction.predict(state(101.4)).robot_pose[0]
    assert stopped == pytest.approx(0.0, abs=1e-6)  # the stop ramp has arrived: the robot is predicted still
