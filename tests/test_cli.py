"""The command line: help, errors, the demo (with the shipped policy and scripted)."""

import json
import subprocess
import sys

import pytest
import torch

from lbgp.cli import default_policy_path, main
from lbgp.viz.recording import ENTITY_PATHS, entity_paths_in


def test_help_lists_the_subcommands(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    for cmd in ("demo", "train", "plot-curves"):
        assert cmd in out


def test_unknown_option_is_a_usage_error(capsys):
    assert main(["demo", "--frobnicate"]) == 2
    err = capsys.readouterr().err
    assert "unrecognized arguments: --frobnicate" in err and len(err.strip().splitlines()) == 1


def test_missing_policy_file_is_a_clear_error(tmp_path, capsys):
    assert main(["demo", "--policy", str(tmp_path / "nope.pt"), "--out", str(tmp_path)]) == 2
    assert "argument --policy" in (err := capsys.readouterr().err) and "nope.pt: no such file" in err


@pytest.mark.parametrize("scripted", [False, True])
def test_demo_writes_a_recording_and_a_summary(tmp_path, scripted):
    args = ["demo", "--out", str(tmp_path)] + (["--scripted"] if scripted else [])
    assert main(args) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert [e["setting"] for e in summary["episodes"]] == ["straight", "circles", "smoothed", "trajectories"]
    if not scripted and default_policy_path().is_file():
        assert summary["policy"].endswith("lbgp_jackal.pt")
    paths = entity_paths_in(tmp_path / "demo.rrd")
    assert set(ENTITY_PATHS) <= paths, set(ENTITY_PATHS) - paths


def test_console_script_entry_point_runs():
    out = subprocess.run([sys.executable, "-m", "lbgp.cli", "--help"], capture_output=True, text=True)
    assert out.returncode == 0 and "demo" in out.stdout


def test_evaluate_writes_the_documented_json(tmp_path):
    out = tmp_path / "m.json"
    rrd = tmp_path / "e.rrd"
    assert main(["evaluate", "--method", "hc", "--scenario", "straight_ahead,turning_inside", "--episodes", "1",
                 "--json", str(out), "--record", str(rrd)]) == 0
    rows = json.loads(out.read_text())
    assert [r["scenario"] for r in rows] == ["straight_ahead", "turning_inside"]
    keys = {"scenario", "method", "distance_mean", "distance_std", "alpha_mean_deg", "alpha_std_deg", "reward",
            "collisions", "terminated_early", "steps"}
    for r in rows:
        assert keys <= set(r) and r["method"] == "hc" and r["steps"] > 0
    assert "world/robot" in entity_paths_in(rrd)


def test_evaluate_goal_deadband_option_reaches_the_lbgp_policy(tmp_path):
    from lbgp.agent.policy import GOAL_DEADBAND_M

    rewards = {}
    for band in ("0", f"{GOAL_DEADBAND_M:g}", "1.0"):
        out = tmp_path / f"m{band}.json"
        assert main(["evaluate", "--method", "lbgp", "--scenario", "turning_ahead", "--episodes", "1", "--goal-deadband", band,
                     "--json", str(out)]) == 0
        rewards[band] = json.loads(out.read_text())[0]["reward"]
    assert len(set(rewards.values())) == 3  # the raw actor, the default band, and a band that swallows every residual
    out = tmp_path / "default.json"
    assert main(["evaluate", "--method", "lbgp", "--scenario", "turning_ahead", "--episodes", "1", "--json", str(out)]) == 0
    assert json.loads(out.read_text())[0]["reward"] == rewards[f"{GOAL_DEADBAND_M:g}"]  # without the option: the default band


def test_evaluate_no_mirror_option_gives_the_actors_own_answer(tmp_path):
    from lbgp.evaluate import evaluate
    from lbgp.policies import make_policy

    out = {}
    for name, extra in (("default", []), ("raw", ["--no-mirror"])):
        out[name] = tmp_path / f"{name}.json"
        assert main(["evaluate", "--method", "e2e", "--scenario", "turning_inside", "--episodes", "1", "--json", str(out[name])] + extra) == 0
    reward = {name: json.loads(path.read_text())[0]["reward"] for name, path in out.items()}
    (raw,) = evaluate(make_policy("e2e", mirror_average=False), "e2e", ["turning_inside"], episodes=1)
    assert reward["raw"] == pytest.approx(raw["reward"], abs=1e-3) and reward["raw"] != reward["default"]


def test_evaluate_rejects_unknown_scenarios(capsys):
    assert main(["evaluate", "--method", "scripted", "--scenario", "moonwalk"]) == 2
    assert "unknown scenario 'moonwalk'" in capsys.readouterr().err


def test_train_prior_weight_option_reaches_the_run_config_and_bad_values_are_refused(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["train", "--prior-weight", "-1", "--out", str(run)]) == 2
    assert "argument --prior-weight: must be a number from 0" in capsys.readouterr().err
    assert not run.exists()  # refused before anything is written
    assert main(["train", "--prior-weight", "0.25", "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    assert json.loads((run / "config.json").read_text())["prior_weight"] == 0.25
    default = tmp_path / "default"
    assert main(["train", "--steps", "40", "--backend", "inline", "--out", str(default)]) == 0
    assert json.loads((default / "config.json").read_text())["prior_weight"] == 1.0
    assert json.loads((default / "config.json").read_text())["mirror_augment"] is False


def test_train_mirror_augment_flag_reaches_the_run_config(tmp_path):
    run = tmp_path / "run"
    assert main(["train", "--mirror-augment", "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    assert json.loads((run / "config.json").read_text())["mirror_augment"] is True


def test_train_previous_goal_flag_reaches_the_run_config_and_the_policy_file(tmp_path):
    from lbgp.agent.policy import load_policy

    run = tmp_path / "run"
    assert main(["train", "--previous-goal", "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    assert json.loads((run / "config.json").read_text())["previous_goal"] is True
    policy = load_policy(run / "policy.pt")
    assert policy.previous_goal and policy.actor.obs_size == 59


def test_a_policy_trained_on_another_planner_is_evaluated_and_shown_on_it(tmp_path, capsys):
    from lbgp.agent.policy import load_policy

    run = tmp_path / "run"
    assert main(["train", "--set", "planner_sqp_iterations=1", "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    assert load_policy(run / "policy.pt").planner_changes == {"sqp_iterations": 1}
    capsys.readouterr()
    assert main(["evaluate", "--method", "lbgp", "--policy", str(run / "policy.pt"), "--scenario", "straight_ahead",
                 "--episodes", "1"]) == 0
    assert "planner: the jackal preset with sqp_iterations=1" in capsys.readouterr().out
    assert main(["evaluate", "--method", "lbgp", "--scenario", "straight_ahead", "--episodes", "1"]) == 0
    assert "planner:" not in capsys.readouterr().out  # the shipped policy drives the preset


def test_train_policy_average_reaches_the_run_config_and_writes_both_policies(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["train", "--policy-average", "1.5", "--steps", "40", "--backend", "inline", "--out", str(run)]) == 2
    assert "--policy-average" in capsys.readouterr().err and not run.exists()
    assert main(["train", "--policy-average", "1e-4", "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    assert json.loads((run / "config.json").read_text())["policy_average"] == 1e-4
    assert (run / "policy.pt").is_file() and (run / "policy_last.pt").is_file()


def test_train_turn_lead_reaches_the_run_config_and_the_policy_file(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["train", "--turn-lead", "0.4", "--paper", "--out", str(run)]) == 2
    assert "turn_lead" in capsys.readouterr().err and not run.exists()  # the paper's actor has no base goal
    assert main(["train", "--turn-lead", "0.4", "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    assert json.loads((run / "config.json").read_text())["turn_lead"] == 0.4
    from lbgp.agent.policy import load_policy

    assert load_policy(run / "policy.pt").actor.turn_lead == 0.4


def test_train_set_changes_only_the_named_fields_over_the_preset(tmp_path):
    run = tmp_path / "run"
    assert main(["train", "--set", "spawn_front_share=0.5", "--set", "noise_correlation=0", "--set", "normalize_obs=off",
                 "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    config = json.loads((run / "config.json").read_text())
    assert config["spawn_front_share"] == 0.5 and config["noise_correlation"] == 0.0 and config["normalize_obs"] is False
    assert config["sigma"] == 0.15 and config["residual_scale"] == 0.375  # the rest: the default preset's
    paper = tmp_path / "paper"
    assert main(["train", "--paper", "--set", "sigma=0.2", "--set", "sigma=0.1", "--set", "batch_size=64",
                 "--steps", "40", "--backend", "inline", "--out", str(paper)]) == 0
    config = json.loads((paper / "config.json").read_text())
    assert config["sigma"] == 0.1 and config["batch_size"] == 64  # the last --set wins
    assert config["residual_scale"] == 0.0 and config["spawn_front_share"] == 0.5  # the rest: the paper's


def test_train_set_takes_layer_sizes_target_updates_and_value_support(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["train", "--set", "hidden=32,16", "--set", "target_tau=0.01", "--set", "target_update_period=7",
                 "--set", "num_atoms=11", "--set", "v_min=-12", "--set", "v_max=28",
                 "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    config = json.loads((run / "config.json").read_text())
    assert config["hidden"] == [32, 16] and config["target_tau"] == 0.01 and config["target_update_period"] == 7
    assert (config["num_atoms"], config["v_min"], config["v_max"]) == (11, -12.0, 28.0)
    from lbgp.agent.checkpoint import load_checked
    from lbgp.agent.train import CHECKPOINT_FORMAT
    from lbgp.agent.policy import load_policy

    layers = [m.out_features for m in load_policy(run / "policy.pt").actor.modules() if isinstance(m, torch.nn.Linear)]
    assert layers[:2] == [32, 16]  # the policy file's actor was built with the layers asked for
    atoms = load_checked(run / "checkpoint.pt", CHECKPOINT_FORMAT)["learner"]["critic"]["atoms"]
    assert torch.allclose(atoms, torch.linspace(-12.0, 28.0, 11))  # the critic's support is the one asked for
    for bad, words in (("hidden=32,none", "layer sizes"), ("hidden=0", "hidden"), ("target_tau=1.5", "target_tau"),
                       ("target_update_period=0", "target_update_period"), ("num_atoms=1", "num_atoms"),
                       ("v_min=nan", "finite"), ("v_max=-40", "v_min < v_max")):
        assert main(["train", "--set", bad, "--steps", "40", "--backend", "inline", "--out", str(tmp_path / "bad")]) == 2
        assert words in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()  # refused before anything is written


def test_train_resume_refuses_options_it_would_ignore(tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["train", "--steps", "40", "--backend", "inline", "--out", str(run)]) == 0
    before = {p.name: p.stat().st_mtime_ns for p in run.iterdir()}
    for extra in (["--set", "sigma=0.3"], ["--paper"], ["--policy-average", "1e-4"], ["--method", "e2e"],
                  ["--robot", "jackal"], ["--seed", "0"], ["--out", str(tmp_path / "other")]):
        assert main(["train", "--resume", str(run), "--steps", "80", *extra]) == 2
        err = capsys.readouterr().err
        assert extra[0] in err and "config.json" in err
    assert {p.name: p.stat().st_mtime_ns for p in run.iterdir()} == before  # nothing touched
