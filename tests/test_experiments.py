"""The experiment commands end to end on tiny budgets: tables with the paper's numbers, winners,
pictures, the ablation figure."""

import csv
import dataclasses
import json
import shutil

import numpy as np
import pytest

from lbgp.cli import main
from lbgp.experiments import paper
from lbgp.experiments.ablation import run_ablation
from lbgp.experiments.real_protocol import PATHS, SETTINGS, run_real_protocol, run_setting
from lbgp.experiments.sim_table import run_sim_table
from lbgp.geometry import distance_and_alpha
from lbgp.policies import make_policy
from lbgp.real.sim_world import SimWorld


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_sim_table_on_a_tiny_budget(tmp_path):
    rows = run_sim_table(tmp_path, episodes=3, scenarios=["straight_ahead", "turning_inside"], horizon=6)
    assert {(r["scenario"], r["method"]) for r in rows} == {(s, m) for s in ("straight_ahead", "turning_inside") for m in ("lbgp", "hc", "e2e")}
    table = read_csv(tmp_path / "sim_table.csv")
    assert len(table) == 6
    for scenario in ("straight_ahead", "turning_inside"):
        mine = [r for r in table if r["scenario"] == scenario]
        assert all(r["episodes"] == "3" and float(r["reward_ci95"]) >= 0 for r in mine)  # noise on: seeded episodes
        best = max(mine, key=lambda r: float(r["reward"]))
        others = [r for r in mine if r is not best]
        separate = all(float(best["reward"]) - float(best["reward_ci95"]) > float(r["reward"]) + float(r["reward_ci95"]) for r in others)
        assert all(r["winner_ours"] == (best["method"] if separate else "tie") for r in mine)
        assert 0 < float(mine[0]["ceiling"]) <= 6 * 0.75 + 1e-9  # 6 steps of at most 0.75
        assert all(float(r["reward"]) <= float(r["ceiling"]) + 1e-9 for r in mine)
        assert all(r["winner_paper"] == max(paper.SIM[scenario], key=lambda m: paper.SIM[scenario][m][4]) for r in mine)
        lbgp = next(r for r in mine if r["method"] == "lbgp")
        assert float(lbgp["paper_reward"]) == paper.SIM[scenario]["lbgp"][4]
    md = (tmp_path / "sim_table.md").read_text()
    assert "Winner per row" in md and "28.31" in md
    assert (tmp_path / "figures" / "sim_straight_ahead.png").stat().st_size > 5_000


def test_real_protocol_settings_start_where_the_paper_says():
    for path, settings in SETTINGS.items():
        for name, (distance, alpha_deg) in settings.items():
            world = SimWorld(robot="turtlebot2", person_path=PATHS[path](), spawn=(distance, alpha_deg))
            d, a = distance_and_alpha(*world.poses())
            assert d == pytest.approx(distance, abs=1e-3) and np.degrees(a) == pytest.approx(alpha_deg, abs=0.5), (path, name)
    assert np.linalg.norm(PATHS["straight"]()[-1] - PATHS["straight"]()[0]) == pytest.approx(7.0)
    u = PATHS["u_turn"]()
    assert u[-1][0] < 0.1 and u[-1][1] == pytest.approx(-2.0)  # back where it came from, 2 m to the right


def test_real_protocol_in_parallel_processes_gives_the_same_rows(tmp_path):
    kwargs = dict(steps=3, paths=["straight"], methods=("hc", "lbgp"), dynamics_sets=("nominal",), repeats=2)
    serial = run_real_protocol(tmp_path / "serial", **kwargs)
    parallel = run_real_protocol(tmp_path / "parallel", jobs=2, **kwargs)
    assert len(serial) == 8 and serial == parallel
    assert (tmp_path / "parallel" / "real_protocol_table.md").read_text() == (tmp_path / "serial" / "real_protocol_table.md").read_text()


def test_real_protocol_runs_through_the_deploy_loop_and_ends_far_runs(tmp_path):
    # a robot that drives away: the paper's rule ends the run once D > 3 m
    class Away:
        control = "velocity"

        def act(self, observation):
            return np.array([-1.0, 1.0], np.float32)

    metrics = run_setting(Away(), "straight", "behind", steps=100)
    assert metrics.terminated_early and metrics.steps < 100 and not metrics.contact
    # the far-left U-turn start (3.6 m) is allowed: the rule applies once the robot came within 3 m
    far = run_setting(make_policy("scripted"), "u_turn", "ahead_far_left", steps=8)
    assert far.steps == 8 and far.distances[0] > 3.0

    rows = run_real_protocol(tmp_path, steps=4, paths=["s_shape"])
    assert len(rows) == 24 and {r["setting"] for r in rows} == set(SETTINGS["s_shape"])
    assert {r["dynamics"] for r in rows} == {"nominal", "hardware_like"}  # the held-out robot beside the nominal one
    assert (tmp_path / "real_protocol_hardware_table.md").is_file()
    gap = (tmp_path / "real_protocol_gap.md").read_text()
    assert all(f"| {m} |" in gap for m in ("LBGP", "HC", "E2E"))
    table = read_csv(tmp_path / "real_protocol_table.csv")
    failed = [r for r in table if r["paper_reward"] == "failed"]
    assert {r["setting"] for r in failed} == {s for s in SETTINGS["s_shape"] if paper.REAL[("s_shape", s)]["e2e"] is None}
    assert (tmp_path / "figures" / "real_protocol_s_shape_behind.png").is_file()


def test_ablation_on_a_tiny_budget(tmp_path):
    report = run_ablation(tmp_path, minutes=1.0, seeds=[0], steps=150, backend="inline", runs_dir=tmp_path / "runs")
    assert set(report["runs"]) == {"LBGP_s0", "LBGP-no-curriculum_s0", "E2E_s0"}
    assert report["complete"] and report["missing_runs"] == []
    assert (tmp_path / "runs" / "E2E_s0" / "checkpoint.pt").is_file()
    assert set(report["final_returns"]) <= {"LBGP", "LBGP-no-curriculum", "E2E"}
    assert report["runs"]["LBGP-no-curriculum_s0"]["final_level"] == "trajectories"
    assert report["runs"]["E2E_s0"]["method"] == "e2e"
    assert (tmp_path / "ablation_curves.png").stat().st_size > 5_000
    kept = tmp_path / "ablation_runs" / "E2E_s0"
    assert sorted(p.name for p in kept.iterdir()) == ["config.json", "curve.csv", "policy.pt", "summary.json"]
    assert (kept / "policy.pt").read_bytes() == (tmp_path / "runs" / "E2E_s0" / "policy.pt").read_bytes()


def test_ablation_gives_every_variant_the_same_wall_time_and_e2e_steps_it_cannot_use_up():
    from lbgp.experiments.ablation import variant_config

    lbgp, e2e = variant_config("LBGP", 1, 30.0), variant_config("E2E", 1, 30.0)
    assert lbgp.time_limit_s == e2e.time_limit_s == 1800.0 and lbgp.seed == e2e.seed == 1
    assert lbgp.total_steps == 300_000 and e2e.total_steps == 1_000_000 and e2e.method == "e2e"
    assert variant_config("LBGP-no-curriculum", 0, 30.0).curriculum is False
    assert variant_config("E2E", 0, 1.0, steps=150).total_steps == 150


def test_ablation_spans_sittings_by_keeping_finished_runs_beside_the_results(tmp_path):
    """A fresh machine has no runs/: finished runs are reused from OUT/ablation_runs, new ones are
    bounded per call (seed by seed), and a run kept with other settings is trained again."""
    common = dict(minutes=1.0, steps=120, backend="inline")
    first = run_ablation(tmp_path, seeds=[0, 1], runs_dir=tmp_path / "runs_a", max_new_runs=2, **common)
    assert list(first["runs"]) == ["LBGP_s0", "LBGP-no-curriculum_s0"]  # every variant's seed 0 comes first
    assert not first["complete"]
    assert first["missing_runs"] == ["E2E_s0", "LBGP_s1", "LBGP-no-curriculum_s1", "E2E_s1"]
    assert json.loads((tmp_path / "ablation.json").read_text())["missing_runs"] == first["missing_runs"]

    shutil.rmtree(tmp_path / "runs_a")  # the next sitting starts without the training runs
    second = run_ablation(tmp_path, seeds=[0, 1], runs_dir=tmp_path / "runs_b", max_new_runs=1, **common)
    assert second["runs"]["LBGP_s0"] == first["runs"]["LBGP_s0"]  # reused, not retrained
    assert not (tmp_path / "runs_b" / "LBGP_s0").exists() and (tmp_path / "runs_b" / "E2E_s0").is_dir()
    assert second["missing_runs"] == ["LBGP_s1", "LBGP-no-curriculum_s1", "E2E_s1"]

    other = run_ablation(tmp_path, seeds=[0], runs_dir=tmp_path / "runs_c", max_new_runs=1, minutes=1.0, steps=100, backend="inline")
    assert (tmp_path / "runs_c" / "LBGP_s0").is_dir()  # another budget: the kept run does not count
    assert json.loads((tmp_path / "ablation_runs" / "LBGP_s0" / "config.json").read_text())["total_steps"] == 100
    assert other["missing_runs"] == ["LBGP-no-curriculum_s0", "E2E_s0"]


def test_experiment_cli_checks_its_arguments(tmp_path):
    assert main(["experiment", "real-protocol", "--robot", "jackal", "--out", str(tmp_path)]) == 2
    assert main(["experiment", "nonsense"]) == 2
    assert main(["experiment", "sim", "--episodes", "many"]) == 2


@pytest.mark.parametrize("method", ["lbgp", "hc", "e2e"])
def test_each_method_runs_every_scenario_for_a_short_seeded_episode(method):
    from lbgp.evaluate import evaluate
    from lbgp.sim.tasks import SCENARIOS

    policy = make_policy(method)
    rows = evaluate(policy, method, list(SCENARIOS), episodes=1, seed=3, horizon=4)
    assert [r["scenario"] for r in rows] == list(SCENARIOS)
    for r in rows:
        assert r["method"] == method and 1 <= r["steps"] <= 4
        assert np.isfinite(r["distance_mean"]) and np.isfinite(r["reward"])


# ---------------------------------------------------------------- honest evaluation
def test_winner_only_where_the_confidence_intervals_separate():
    from lbgp.experiments.tables import TIE, winner

    assert winner({"lbgp": 10.0, "hc": 8.0}, {"lbgp": 0.5, "hc": 0.5}) == "lbgp"
    assert winner({"lbgp": 10.0, "hc": 9.2}, {"lbgp": 0.5, "hc": 0.5}) == TIE
    assert winner({"lbgp": 10.0, "hc": 8.0}, {"lbgp": float("nan"), "hc": 0.5}) == TIE  # one episode: no ranking
    assert winner({"lbgp": 10.0, "hc": 8.0}) == "lbgp"  # without intervals: the best mean


def test_head_to_head_counts_separated_and_overlapping_rows(tmp_path):
    from lbgp.experiments.tables import head_to_head, head_to_head_csv, write_tables

    def row(scenario, method, reward, ci):
        return {"scenario": scenario, "method": method, "reward": reward, "reward_ci95": ci, "distance_mean": 1.5,
                "distance_std": 0.1, "alpha_mean_deg": 0.0, "alpha_std_deg": 1.0, "collisions": 0, "terminated_early": 0}

    rows = [row("a", "lbgp", 10.0, 0.5), row("a", "hc", 8.0, 0.5),  # higher, separated
            row("b", "lbgp", 9.0, 0.5), row("b", "hc", 9.5, 0.5),  # overlap, lower mean
            row("c", "lbgp", 5.0, 0.1), row("c", "hc", 7.0, 0.1),  # lower, separated
            row("d", "lbgp", 4.0, 0.1), row("d", "e2e", 1.0, 0.1)]  # no HC: not counted
    want = {"rows": 3, "higher": 1, "lower": 1, "overlap": 1, "mean_at_least": 1}
    assert head_to_head(rows, ["scenario"]) == want
    write_tables(rows, ["scenario"], {}, tmp_path / "t.md", tmp_path / "t.csv", "title", "preamble")
    assert head_to_head_csv(tmp_path / "t.csv") == want
    assert "higher in 1 and lower in 1 of 3 rows" in (tmp_path / "t.md").read_text()
    assert head_to_head([row("a", "lbgp", 1.0, 0.1)], ["scenario"]) is None


def test_lead_over_hc_is_summed_over_rows_and_paired_by_episode(tmp_path):
    from lbgp.experiments.tables import paired_lead, write_tables
    from lbgp.metrics import reward_ci95

    def row(scenario, method, rewards):
        return {"scenario": scenario, "method": method, "reward": float(np.mean(rewards)), "reward_ci95": reward_ci95(rewards),
                "episode_rewards": list(rewards), "distance_mean": 1.5, "distance_std": 0.1, "alpha_mean_deg": 0.0,
                "alpha_std_deg": 1.0, "collisions": 0, "terminated_early": 0}

    # HC's episodes vary a lot, LBGP is HC plus a steady lead: pairing sees the steady lead
    hc_a, hc_b = [10.0, 2.0, 7.0, 4.0], [1.0, 9.0, 3.0, 6.0]
    rows = [row("a", "hc", hc_a), row("a", "lbgp", [r + 1.0 for r in hc_a]),
            row("b", "hc", hc_b), row("b", "lbgp", [r + 2.0 + 0.1 * i for i, r in enumerate(hc_b)]),
            row("c", "hc", [0.0, 0.0, 0.0, 0.0])]
    lead = paired_lead(rows, ["a", "b"])
    per_episode = [3.0, 3.1, 3.2, 3.3]
    assert lead["lead"] == pytest.approx(3.15) and lead["episodes"] == 4
    assert lead["ci95"] == pytest.approx(reward_ci95(per_episode))
    assert lead["ci95"] < 0.25 < reward_ci95(hc_a)  # unpaired intervals would be far wider
    assert paired_lead(rows, ["a"])["ci95"] == 0.0  # a constant lead is certain
    with pytest.raises(ValueError, match="lbgp on c"):
        paired_lead(rows, ["a", "c"])
    rows.append(row("c", "lbgp", [1.0, 1.0]))
    with pytest.raises(ValueError, match="same episodes"):
        paired_lead(rows, ["a", "c"])
    write_tables(rows[:4], ["scenario"], {}, tmp_path / "t.md", tmp_path / "t.csv", "title", "preamble",
                 leads={"both": ("a", "b"), "missing": ("a", "z")})
    md = (tmp_path / "t.md").read_text()
    assert "LBGP - HC summed over the both rows (a, b): +3.15 ± " in md and "over 4 seeds" in md
    assert "missing" not in md  # rows that did not run are not summed


def test_reward_confidence_interval_is_students_t():
    from lbgp.metrics import reward_ci95

    assert np.isnan(reward_ci95([3.0]))
    assert reward_ci95([2.0, 2.0, 2.0]) == 0.0
    # n = 4, sample std 1.2910, t(0.975, 3) = 3.1824
    assert reward_ci95([1.0, 2.0, 3.0, 4.0]) == pytest.approx(3.1824 * 1.29099 / 2.0, rel=1e-4)


def test_every_method_faces_the_same_seeded_episodes():
    """Episode i is seeded on its own: what an earlier episode consumed does not change it."""
    from lbgp.evaluate import evaluate
    from lbgp.rollout import ConstantGoalPolicy

    noisy = dict(robot="jackal", episodes=3, seed=7, horizon=4, obs_noise=True)
    full = evaluate(ConstantGoalPolicy(), "scripted", ["straight"], **noisy)[0]
    again = evaluate(ConstantGoalPolicy(), "scripted", ["straight"], **noisy)[0]
    assert full["reward"] == again["reward"] and full["reward_std"] > 0  # random spawns differ per episode
    hc = evaluate(make_policy("hc"), "hc", ["straight"], **noisy)[0]
    assert hc["episodes"] == 3 and not np.isnan(hc["reward_ci95"])


def test_scenario_ceiling_is_an_upper_bound():
    from lbgp.experiments.ceiling import scenario_ceiling
    from lbgp.sim import make_env
    from lbgp.rollout import run_episode

    assert scenario_ceiling("straight_ahead", 1.5) == pytest.approx(35 * 0.75)  # starts at the optimum, can stay there
    bound = scenario_ceiling("turning_inside", 1.5, steps=10)
    got = run_episode(make_env("turning_inside", robot="jackal", seed=0, horizon=10), make_policy("hc")).total_reward
    assert got <= bound + 1e-9 and bound < 10 * 0.75


def test_hardware_like_robot_changes_the_protocol_outcome_and_the_gap_sums_per_method():
    from lbgp.experiments.real_protocol import gap_summary

    policy = make_policy("hc", robot="turtlebot2")
    nominal = run_setting(policy, "straight", "ahead", steps=15, dynamics="nominal")
    hardware = run_setting(policy, "straight", "ahead", steps=15, dynamics="hardware_like")
    assert nominal.total_reward != hardware.total_reward
    rows = lambda rewards: [{"method": m, "path": "p", "setting": s, "reward": r} for (m, s), r in rewards.items()]  # noqa: E731
    g = gap_summary(rows({("hc", "a"): 10.0, ("hc", "b"): 6.0, ("e2e", "a"): 12.0, ("e2e", "b"): 2.0}),
                    rows({("hc", "a"): 8.0, ("hc", "b"): 4.0, ("e2e", "a"): 3.0, ("e2e", "b"): 5.0}))
    assert g["hc"]["kept"] == pytest.approx(12 / 16) and g["e2e"]["kept"] == pytest.approx(8 / 14)
    assert g["hc"]["best_settings_hardware"] == 1 and g["e2e"]["best_settings_hardware"] == 1


def test_ablation_final_returns_summarise_each_variant_over_its_seeds():
    from lbgp.experiments.ablation import final_returns

    summaries = {"A_s0": {"final_exploit_return_mean_last20": 1.0}, "A_s1": {"final_exploit_return_mean_last20": 3.0},
                 "B_s0": {"final_exploit_return_mean_last20": 5.0}, "B_s1": {"final_exploit_return_mean_last20": None}}
    out = final_returns(summaries, {"A_s0": "A", "A_s1": "A", "B_s0": "B", "B_s1": "B"})
    assert out["A"]["mean"] == 2.0 and out["A"]["per_seed"] == [1.0, 3.0]
    assert abs(out["A"]["ci95_half_width"] - 12.706) < 1e-3  # t(0.975, 1) * sqrt(2) / sqrt(2)
    assert out["B"] == {"per_seed": [5.0], "mean": 5.0, "ci95_half_width": None}


def test_a_kept_run_made_before_a_setting_existed_is_reused_at_that_settings_default(tmp_path):
    """The archived configs predate later settings (mirror_augment, turn_lead): a key missing from
    a kept config reads as its default, the behaviour from before it existed; a kept value that
    differs from the asked one is still another run."""
    from lbgp.experiments.ablation import ARCHIVED_FILES, archived_run, variant_config

    cfg = variant_config("LBGP", 0, 30.0)
    old = json.loads(cfg.to_json())
    del old["mirror_augment"], old["turn_lead"]
    for name in ARCHIVED_FILES:
        (tmp_path / name).write_text("{}")
    (tmp_path / "config.json").write_text(json.dumps(old))
    (tmp_path / "summary.json").write_text(json.dumps({"env_steps": 7}))
    assert archived_run(tmp_path, cfg) == {"env_steps": 7}
    assert archived_run(tmp_path, dataclasses.replace(cfg, turn_lead=0.4)) is None
    (tmp_path / "config.json").write_text(json.dumps({**old, "not_a_setting": 1}))
    assert archived_run(tmp_path, cfg) is None
