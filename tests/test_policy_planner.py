"""A policy file names the planner it was trained on, and every place that drives a policy uses it."""

import numpy as np
import pytest
import torch

from lbgp.agent import load_policy
from lbgp.agent.config import D4PGConfig
from lbgp.agent.networks import Actor
from lbgp.agent.policy import save_policy
from lbgp.agent.train import Trainer
from lbgp.evaluate import evaluate
from lbgp.planner import checked_changes, planner_config_for
from lbgp.real.loop import DeployConfig, DeployLoop
from lbgp.rollout import ConstantGoalPolicy
from lbgp.stack import policy_planner, policy_planner_note


def _actor(seed: int = 0) -> Actor:
    torch.manual_seed(seed)
    return Actor(57, 2, (16, 16), residual_scale=0.75)


def test_checked_changes_accepts_planner_fields_and_refuses_anything_else():
    assert checked_changes({"sqp_iterations": 1.0, "wait_candidate": False, "osqp_refine_eps": None}) == {
        "sqp_iterations": 1, "wait_candidate": False, "osqp_refine_eps": None}
    assert type(checked_changes({"sqp_iterations": 1.0})["sqp_iterations"]) is int
    assert checked_changes({"sqp_iterations": np.int64(2), "max_vel_x": np.float32(1.25)}) == {"sqp_iterations": 2, "max_vel_x": 1.25}
    assert planner_config_for("jackal", {"sqp_iterations": 1}) == planner_config_for("jackal").with_(sqp_iterations=1)
    for bad, words in [({"warp_speed": 1}, "'warp_speed' is not a planner setting"),
                       ({"sqp_iterations": 1.5}, "sqp_iterations takes a value of type int"),
                       ({"sqp_iterations": None}, "sqp_iterations takes a value of type int"),
                       ({"max_vel_x": float("nan")}, "max_vel_x"),
                       ({"max_vel_x": "fast"}, "max_vel_x"),
                       ({"wait_candidate": 1}, "wait_candidate takes a value of type bool"),
                       ([("sqp_iterations", 1)], "must be a mapping")]:
        with pytest.raises(ValueError, match=words):
            checked_changes(bad)


def test_the_policy_file_keeps_its_planner_and_a_file_without_one_uses_the_preset(tmp_path):
    save_policy(tmp_path / "cap1.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75,
                planner_changes={"sqp_iterations": 1})
    save_policy(tmp_path / "preset.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75)
    cap1, preset = load_policy(tmp_path / "cap1.pt"), load_policy(tmp_path / "preset.pt")
    assert cap1.planner_changes == {"sqp_iterations": 1} and preset.planner_changes == {}
    assert policy_planner(cap1, "jackal") == planner_config_for("jackal").with_(sqp_iterations=1)
    assert policy_planner(cap1, "turtlebot2").max_vel_x == planner_config_for("turtlebot2").max_vel_x
    assert policy_planner(preset, "jackal") is None
    named = planner_config_for("jackal").with_(n_poses=15)
    assert policy_planner(cap1, "jackal", named) is named  # the caller's planner wins
    assert "sqp_iterations=1" in policy_planner_note(cap1, "jackal") and policy_planner_note(preset, "jackal") == ""
    # a file written before the planner was recorded (no "planner" entry) loads with the preset
    data = torch.load(tmp_path / "preset.pt", weights_only=False)
    data.pop("planner")
    data["version"] = 5
    torch.save(data, tmp_path / "v5.pt")
    assert load_policy(tmp_path / "v5.pt").planner_changes == {}


def test_a_malformed_planner_entry_is_refused_with_its_reason(tmp_path):
    save_policy(tmp_path / "p.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75)
    data = torch.load(tmp_path / "p.pt", weights_only=False)
    data["planner"] = {"sqp_iterations": "many"}
    torch.save(data, tmp_path / "bad.pt")
    with pytest.raises(ValueError, match=r"bad\.pt: malformed policy file.*sqp_iterations"):
        load_policy(tmp_path / "bad.pt")
    with pytest.raises(ValueError, match="not a planner setting"):
        save_policy(tmp_path / "q.pt", _actor(), "lbgp", "jackal", (16, 16), planner_changes={"horizon_s": 2.0})
    assert not (tmp_path / "q.pt").exists()


def test_evaluate_drives_the_policys_planner(tmp_path):
    """The same actor saved with and without the SQP cap of 1: evaluated as it comes, the cap-1 file
    scores exactly what the plain file scores on the cap-1 planner, and not what it scores on the preset."""
    save_policy(tmp_path / "cap1.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75,
                planner_changes={"sqp_iterations": 1})
    save_policy(tmp_path / "preset.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75)
    kwargs = dict(robot="jackal", episodes=1, seed=3, obs_noise=True)
    own = evaluate(load_policy(tmp_path / "cap1.pt"), "lbgp", ["turning_ahead"], **kwargs)[0]
    cap1 = evaluate(load_policy(tmp_path / "preset.pt"), "lbgp", ["turning_ahead"],
                    planner_config=planner_config_for("jackal", {"sqp_iterations": 1}), **kwargs)[0]
    preset = evaluate(load_policy(tmp_path / "preset.pt"), "lbgp", ["turning_ahead"], **kwargs)[0]
    assert own["reward"] == cap1["reward"] and own["distance_mean"] == cap1["distance_mean"]
    assert own["reward"] != preset["reward"]


def test_training_records_its_planner_and_deploy_drives_it(tmp_path):
    trainer = Trainer(D4PGConfig(total_steps=100, min_replay=50, num_actors=1, hidden=(16, 16), batch_size=16,
                                 planner_sqp_iterations=1), tmp_path / "run", progress=False)
    try:
        path = trainer.snapshot()
    finally:
        trainer.close()
    policy = load_policy(path)
    assert policy.planner_changes == {"sqp_iterations": 1}

    class Sink:
        def send(self, t, v, w, status="ok"):
            pass

    class Source:
        def read(self):
            return []

    loop = DeployLoop(Source(), Sink(), policy, DeployConfig(robot="turtlebot2"), clock=lambda: 0.0)
    assert loop.limits.sqp_iterations == 1 and loop.controller.planner.cfg.sqp_iterations == 1
    assert loop.limits.max_vel_x == planner_config_for("turtlebot2").max_vel_x
    plain = DeployLoop(Source(), Sink(), ConstantGoalPolicy(), DeployConfig(robot="turtlebot2"), clock=lambda: 0.0)
    assert plain.limits.sqp_iterations == planner_config_for("turtlebot2").sqp_iterations
    assert np.isfinite(plain.limits.control_period)


def test_the_sim_table_says_when_a_method_drives_another_planner(tmp_path):
    from lbgp.experiments.sim_table import run_sim_table

    save_policy(tmp_path / "cap1.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75,
                planner_changes={"sqp_iterations": 1})
    save_policy(tmp_path / "preset.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75)
    for name in ("cap1", "preset"):
        out = tmp_path / name
        run_sim_table(out, episodes=1, scenarios=["straight_ahead"], methods=("lbgp", "hc"),
                      policies={"lbgp": tmp_path / f"{name}.pt"}, horizon=4)
        table = (out / "sim_table.md").read_text()
        assert ("LBGP's planner: the jackal preset with sqp_iterations=1" in table) == (name == "cap1")
        assert ("planner:" in table) == (name == "cap1")


def test_the_real_protocol_tables_say_when_a_method_drives_another_planner(tmp_path):
    from lbgp.experiments.real_protocol import run_real_protocol

    save_policy(tmp_path / "cap1.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75,
                planner_changes={"sqp_iterations": 1})
    run_real_protocol(tmp_path / "out", steps=3, methods=("lbgp", "hc"), paths=["straight"],
                      policies={"lbgp": tmp_path / "cap1.pt"}, dynamics_sets=("nominal",))
    table = (tmp_path / "out" / "real_protocol_table.md").read_text()
    assert "LBGP's planner: the turtlebot2 preset with sqp_iterations=1" in table


def test_a_deploy_log_names_the_planner_it_drove(tmp_path):
    from lbgp.real.deploy import deploy
    from lbgp.real.mcap_log import read_log

    save_policy(tmp_path / "cap1.pt", _actor(), "lbgp", "jackal", (16, 16), residual_scale=0.75,
                planner_changes={"sqp_iterations": 1})
    loop = deploy(load_policy(tmp_path / "cap1.pt"), source="sim://straight_ahead", robot="turtlebot2", steps=3,
                  log=tmp_path / "run.mcap")
    assert loop.error is None and loop.limits.sqp_iterations == 1
    assert read_log(tmp_path / "run.mcap")["metadata"]["planner_changes"] == str({"sqp_iterations": 1})
    deploy(ConstantGoalPolicy(), source="sim://straight_ahead", robot="turtlebot2", steps=3, log=tmp_path / "hc.mcap")
    assert "planner_changes" not in read_log(tmp_path / "hc.mcap")["metadata"]
