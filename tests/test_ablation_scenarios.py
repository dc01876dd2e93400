"""benchmarks/ablation_scenarios.py: the ablation's policies scored on the paper's scenarios."""

import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from ablation_scenarios import acting_run_name, main, scenario_seed, summarise, variant_of  # noqa: E402

from lbgp.agent.policy import GOAL_DEADBAND_M  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import default_policy_path, make_policy  # noqa: E402


def test_variants_are_summarised_over_their_seeds():
    assert variant_of("LBGP-no-curriculum_s2") == "LBGP-no-curriculum"
    out = summarise({"LBGP_s0": {"sum": 10.0}, "LBGP_s1": {"sum": 12.0}, "E2E_s0": {"sum": 5.0}})
    assert out["LBGP"]["runs"] == ["LBGP_s0", "LBGP_s1"] and out["LBGP"]["mean_sum"] == 11.0
    assert out["LBGP"]["ci95_half_width"] == pytest.approx(12.706, abs=1e-3)  # t(0.975, 1) * std / sqrt(2), std = sqrt(2)
    assert out["E2E"]["mean_sum"] == 5.0 and out["E2E"]["ci95_half_width"] is None
    assert out["E2E"]["minus_LBGP"] == {"difference": -6.0, "ci95_half_width": None, "separated": False}
    assert "minus_LBGP" not in out["LBGP"]


def test_a_runs_other_acting_settings_are_variants_of_their_own():
    assert acting_run_name("LBGP_s1", GOAL_DEADBAND_M, mirror=True) == acting_run_name("LBGP_s1") == "LBGP_s1"  # the defaults
    assert acting_run_name("LBGP_s1", GOAL_DEADBAND_M + 0.025) == f"LBGP@deadband{GOAL_DEADBAND_M + 0.025:g}_s1"
    assert acting_run_name("LBGP-no-curriculum_s2", 0.0) == "LBGP-no-curriculum@deadband0_s2"
    assert variant_of(acting_run_name("LBGP_s1", 0.2)) == "LBGP@deadband0.2"
    assert acting_run_name("E2E_s0", None, mirror=False) == "E2E@nomirror_s0"
    assert acting_run_name("LBGP_s0", 0.0, mirror=False) == "LBGP@deadband0@nomirror_s0"


def test_a_dead_band_variant_is_compared_with_its_own_policies_seed_by_seed():
    out = summarise({"LBGP_s0": {"sum": 10.0}, "LBGP_s1": {"sum": 20.0}, "LBGP_s2": {"sum": 15.0},
                     "LBGP@deadband0_s0": {"sum": 9.0}, "LBGP@deadband0_s1": {"sum": 18.0}, "LBGP@deadband0_s2": {"sum": 14.0}})
    paired = out["LBGP@deadband0"]["minus_LBGP_paired"]
    # differences -1, -2, -1: mean -4/3, std 1/sqrt(3), t(0.975, 2) = 4.303 -> half-width 4.303 / 3 = 1.434
    assert paired["per_seed"] == [-1.0, -2.0, -1.0] and paired["difference"] == pytest.approx(-1.333, abs=1e-3)
    assert paired["ci95_half_width"] == pytest.approx(1.434, abs=1e-3) and not paired["separated"]
    # Welch's interval for the same numbers is far wider: the seeds' spread dominates it
    assert out["LBGP@deadband0"]["minus_LBGP"]["ci95_half_width"] > 10.0
    assert "minus_LBGP_paired" not in out["LBGP"]


def test_welch_difference_separates_only_what_its_interval_excludes():
    from ablation_scenarios import welch_difference

    diff, half = welch_difference([10.0, 11.0, 12.0], [5.0, 7.0, 9.0])
    # variances 1/3 and 4/3 per mean: se = sqrt(5/3); Welch dof = (5/3)^2 / ((1/3)^2/2 + (4/3)^2/2) = 2.94
    assert diff == 4.0 and half == pytest.approx(4.1554, abs=1e-3)
    assert welch_difference([1.0, 1.0], [1.0, 1.0]) == (0.0, 0.0)


def test_each_runs_policy_faces_the_noisy_episodes_of_the_sim_table(tmp_path):
    runs = tmp_path / "ablation_runs"
    for run, method in (("LBGP_s0", "lbgp"), ("LBGP_s1", "lbgp"), ("E2E_s0", "e2e")):
        (runs / run).mkdir(parents=True)
        shutil.copy(default_policy_path(method), runs / run / "policy.pt")
    result = main(["--runs", str(runs), "--scenarios", "turning_ahead", "--episodes", "2", "--json", str(tmp_path / "out.json")])
    # the episodes of lbgp experiment sim's turning_ahead row (scenario 2: seed 2000)
    (direct,) = evaluate(make_policy("lbgp"), "lbgp", ["turning_ahead"], episodes=2, seed=2000, obs_noise=True)
    assert result["runs"]["LBGP_s0"]["sum"] == pytest.approx(direct["reward"], abs=1e-3)
    assert result["variants"]["LBGP"]["sums"] == [result["runs"]["LBGP_s0"]["sum"]] * 2  # the same policy twice
    assert result["variants"]["LBGP"]["ci95_half_width"] == 0.0
    assert result["runs"]["E2E_s0"]["method"] == "e2e" and result["hc"]["method"] == "hc"
    assert result["runs"]["E2E_s0"]["sum"] != result["runs"]["LBGP_s0"]["sum"] != result["hc"]["sum"]
    assert (tmp_path / "out.json").is_file()


def test_runs_from_several_folders_and_chosen_variants(tmp_path):
    from ablation_scenarios import run_policies

    a, b = tmp_path / "ablation_runs", tmp_path / "other_runs"
    for folder, run in ((a, "LBGP_s0"), (a, "E2E_s0"), (b, "LBGP-mirror-augment_s0"), (b, "LBGP-mirror-augment_s1")):
        (folder / run).mkdir(parents=True)
        (folder / run / "policy.pt").write_bytes(b"")
    (a / "LBGP_s1").mkdir()  # a run without a policy file is not a run to score
    assert sorted(run_policies([a, b])) == ["E2E_s0", "LBGP-mirror-augment_s0", "LBGP-mirror-augment_s1", "LBGP_s0"]
    chosen = run_policies([a, b], ["LBGP", "LBGP-mirror-augment"])
    assert sorted(chosen) == ["LBGP-mirror-augment_s0", "LBGP-mirror-augment_s1", "LBGP_s0"]
    assert chosen["LBGP-mirror-augment_s1"] == b / "LBGP-mirror-augment_s1" / "policy.pt"
    assert sorted(run_policies(a)) == ["E2E_s0", "LBGP_s0"]  # one folder, as before
    (b / "LBGP_s0").mkdir()
    (b / "LBGP_s0" / "policy.pt").write_bytes(b"")
    with pytest.raises(ValueError, match="LBGP_s0 is in two folders"):
        run_policies([a, b])


def test_last_actor_scores_a_policy_average_runs_last_actor_as_its_paired_control(tmp_path):
    runs, kept = tmp_path / "runs", Path(__file__).resolve().parents[1] / "results" / "policy_average_runs"
    (runs / "LBGP-policy-average_s0").mkdir(parents=True)
    for name in ("policy.pt", "policy_last.pt"):
        shutil.copy(kept / "LBGP-policy-average_s0" / name, runs / "LBGP-policy-average_s0" / name)
    (runs / "LBGP_s0").mkdir()  # a run without policy_last.pt: no @last variant
    shutil.copy(default_policy_path("lbgp"), runs / "LBGP_s0" / "policy.pt")
    assert acting_run_name("LBGP-policy-average_s0", last=True) == "LBGP-policy-average@last_s0"
    assert acting_run_name("LBGP_s1", 0.0, mirror=False, last=True) == "LBGP@last@deadband0@nomirror_s1"
    result = main(["--runs", str(runs), "--scenarios", "turning_ahead", "--episodes", "1", "--last-actor",
                   "--json", str(tmp_path / "out.json")])
    assert sorted(result["runs"]) == ["LBGP-policy-average@last_s0", "LBGP-policy-average_s0", "LBGP_s0"]
    last, average = result["runs"]["LBGP-policy-average@last_s0"], result["runs"]["LBGP-policy-average_s0"]
    assert last["policy"].endswith("policy_last.pt") and average["policy"].endswith("policy.pt")
    assert last["sum"] != average["sum"]  # two different actors on the same episode
    paired = result["variants"]["LBGP-policy-average@last"]["minus_LBGP-policy-average_paired"]
    assert paired["per_seed"] == [pytest.approx(last["sum"] - average["sum"], abs=2e-3)]


@pytest.mark.parametrize("flags, changes, scenario", [
    (["--planner-sqp-iterations", "1"], {"sqp_iterations": 1}, "turning_inside"),
    (["--planner-changes", "max_vel_x=2.0"], {"max_vel_x": 2.0}, "straight_behind"),  # from behind, faster gets in front sooner
])
def test_a_planner_change_scores_hc_and_the_policies_on_that_planner(tmp_path, flags, changes, scenario):
    """--planner-sqp-iterations K or --planner-changes NAME=VALUE: every planner-driven method faces
    the same episodes on the preset with that change (as evaluate with the preset changed), and the
    file says so."""
    from lbgp.planner import planner_config_for

    runs = tmp_path / "runs"
    (runs / "LBGP_s0").mkdir(parents=True)
    shutil.copy(default_policy_path("lbgp"), runs / "LBGP_s0" / "policy.pt")
    args = ["--runs", str(runs), "--scenarios", scenario, "--episodes", "1"]
    changed = main(args + flags + ["--json", str(tmp_path / "changed.json")])
    preset = main(args + ["--json", str(tmp_path / "preset.json")])
    (hc,) = evaluate(make_policy("hc"), "hc", [scenario], episodes=1, seed=scenario_seed(0, scenario), obs_noise=True,
                     planner_config=planner_config_for("jackal").with_(**changes))
    assert changed["planner_changes"] == changes and preset["planner_changes"] == {}
    assert changed["hc"]["sum"] == pytest.approx(hc["reward"], abs=1e-3)
    assert changed["hc"]["sum"] != preset["hc"]["sum"]
    assert changed["runs"]["LBGP_s0"]["sum"] != preset["runs"]["LBGP_s0"]["sum"]


@pytest.mark.parametrize("flags, named", [
    (["--planner-sqp-iterations", "-1"], "planner_sqp_iterations"),
    (["--planner-changes", "max_speed=2"], "max_speed"),
    (["--planner-changes", "sqp_iterations=2", "--planner-sqp-iterations", "1"], "sqp_iterations"),
])
def test_a_bad_planner_change_is_refused_by_name_with_nothing_written(tmp_path, capsys, flags, named):
    runs = tmp_path / "runs"
    (runs / "LBGP_s0").mkdir(parents=True)
    shutil.copy(default_policy_path("lbgp"), runs / "LBGP_s0" / "policy.pt")
    with pytest.raises(SystemExit) as exit_info:
        main(["--runs", str(runs), "--episodes", "1"] + flags + ["--json", str(tmp_path / "bad.json")])
    assert exit_info.value.code == 2 and named in capsys.readouterr().err
    assert not (tmp_path / "bad.json").exists()


def test_two_runs_are_compared_on_the_same_episodes_with_a_paired_interval():
    from ablation_scenarios import paired_comparisons, paired_sum_difference

    a = {"per_scenario": {"turning_ahead": 0, "trajectory_one": 0},
         "episode_rewards": {"turning_ahead": [10.0, 12.0, 14.0], "trajectory_one": [5.0, 5.0, 8.0]}}
    b = {"per_scenario": {"turning_ahead": 0, "trajectory_one": 0},
         "episode_rewards": {"turning_ahead": [9.0, 11.0, 12.0], "trajectory_one": [4.0, 5.0, 7.0]}}
    # episode by episode, summed over both rows: 2, 1, 3 -> mean 2, std 1, t(0.975, 2) = 4.303 -> 4.303 / sqrt(3)
    both = paired_sum_difference(a, b, ["turning_ahead", "trajectory_one"])
    assert both["difference"] == 2.0 and both["ci95_half_width"] == pytest.approx(2.484, abs=1e-3)
    assert not both["separated"] and both["episodes"] == 3
    # turning_ahead alone: 1, 1, 2 -> mean 4/3, std 1/sqrt(3): half-width 4.303 / 3 = 1.434, not separated
    one = paired_sum_difference(a, b, ["turning_ahead", "turning_behind"])  # a row neither scored is left out
    assert one["rows"] == ["turning_ahead"] and one["difference"] == pytest.approx(1.333, abs=1e-3)
    assert one["ci95_half_width"] == pytest.approx(1.434, abs=1e-3) and not one["separated"]
    b_low = {**b, "episode_rewards": {k: [x - 10.0 for x in v] for k, v in b["episode_rewards"].items()}}
    assert paired_sum_difference(a, b_low, ["turning_ahead"])["separated"]  # 11.33 +- 1.43
    assert paired_sum_difference(a, {"per_scenario": {}}, ["turning_ahead"]) is None  # a file from before episodes were kept
    with pytest.raises(ValueError, match="pairing needs the same episodes"):
        paired_sum_difference(a, {"episode_rewards": {"turning_ahead": [1.0, 2.0]}}, ["turning_ahead"])

    runs = {"X_s0": a, "Y_s0": b}
    paired_comparisons(runs, b_low, paired_with="Y_s0")
    assert runs["X_s0"]["minus_Y_s0"] == both and "minus_Y_s0" not in runs["Y_s0"]
    assert runs["X_s0"]["over_hc"]["turning"]["rows"] == ["turning_ahead"]
    # trajectory_one: mean 6 against b_low's (-6 - 5 - 3) / 3
    assert runs["X_s0"]["over_hc"]["trajectory"]["difference"] == pytest.approx(6.0 + 14.0 / 3, abs=1e-3)
    assert runs["Y_s0"]["over_hc"]["all"]["difference"] == pytest.approx(20.0)  # 10 higher in each row and episode
    with pytest.raises(ValueError, match="no such run"):
        paired_comparisons(runs, b_low, paired_with="Z_s0")


def test_paired_with_sets_each_run_against_a_named_one(tmp_path):
    runs = tmp_path / "runs"
    for run in ("LBGP_s0", "LBGP_s1"):
        (runs / run).mkdir(parents=True)
        shutil.copy(default_policy_path("lbgp"), runs / run / "policy.pt")
    args = ["--runs", str(runs), "--scenarios", "turning_ahead,trajectory_one", "--episodes", "2"]
    result = main(args + ["--paired-with", "LBGP_s0", "--json", str(tmp_path / "out.json")])
    same = result["runs"]["LBGP_s1"]["minus_LBGP_s0"]  # the same policy: every episode alike
    assert same["difference"] == 0.0 and same["ci95_half_width"] == 0.0 and not same["separated"]
    assert same["episodes"] == 2 and same["rows"] == ["turning_ahead", "trajectory_one"]
    run, hc = result["runs"]["LBGP_s0"], result["hc"]
    assert len(run["episode_rewards"]["turning_ahead"]) == 2
    lead = run["over_hc"]["turning"]["difference"]
    assert lead == pytest.approx(run["per_scenario"]["turning_ahead"] - hc["per_scenario"]["turning_ahead"], abs=2e-3)
    assert run["over_hc"]["all"]["difference"] == pytest.approx(run["sum"] - hc["sum"], abs=3e-3)
    with pytest.raises(SystemExit):
        main(args + ["--paired-with", "LBGP_s7", "--json", str(tmp_path / "bad.json")])
    assert not (tmp_path / "bad.json").exists()
    # an acting variant of a run is a run to pair with too
    acting = main(["--runs", str(runs), "--scenarios", "turning_ahead", "--episodes", "1", "--deadbands", f"{GOAL_DEADBAND_M},0",
                   "--paired-with", "LBGP@deadband0_s0", "--json", str(tmp_path / "acting.json")])
    raw, kept = acting["runs"]["LBGP@deadband0_s0"], acting["runs"]["LBGP_s0"]
    assert kept["minus_LBGP@deadband0_s0"]["difference"] == pytest.approx(kept["sum"] - raw["sum"], abs=2e-3)
