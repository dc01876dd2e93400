"""benchmarks/goal_smoothing.py: acting with an exponential average of a policy's goals."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from ablation_scenarios import scenario_seed  # noqa: E402
from goal_smoothing import HeldGoals, SmoothedGoals, main  # noqa: E402

from lbgp.actions import goal_from_action  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import default_policy_path, make_policy  # noqa: E402

SHIPPED = default_policy_path("lbgp")


def test_each_goal_is_the_smoothed_mix_of_the_last_one_and_the_policy_s(noisy_observations):
    smoothed, raw = SmoothedGoals(make_policy("lbgp", SHIPPED, robot="jackal"), 0.5), make_policy("lbgp", SHIPPED, robot="jackal")
    observations = noisy_observations("turning_inside", 0, 8)
    last, moved = None, 0.0
    for obs in observations:
        answer, action = raw.act(obs), smoothed.act(obs)
        expected = answer if last is None else 0.5 * last + 0.5 * answer
        np.testing.assert_allclose(action, expected, atol=1e-6)
        if last is not None:
            moved = max(moved, float(np.abs(answer - last).max()))
        last = action
    assert moved > 1e-3  # the policy's goals changed, so the mix differs from its answers
    smoothed.reset()  # a new episode starts from the policy's own goal
    np.testing.assert_allclose(smoothed.act(observations[3]), raw.act(observations[3]), atol=1e-6)


def test_a_held_goal_stays_until_the_policy_s_goal_moves_farther_than_the_hold(noisy_observations):
    held, raw = HeldGoals(make_policy("lbgp", SHIPPED, robot="jackal"), 0.05), make_policy("lbgp", SHIPPED, robot="jackal")
    last, kept, jumped = None, 0, 0
    for obs in noisy_observations("turning_inside", 0, 12):
        answer, action = raw.act(obs), held.act(obs)
        if last is not None and np.hypot(*(goal_from_action(answer) - goal_from_action(last))) <= 0.05:
            np.testing.assert_array_equal(action, last)
            kept += 1
        else:
            np.testing.assert_allclose(action, answer, atol=1e-6)
            jumped += 1
        last = action
    assert kept > 0 and jumped > 1  # both branches ran
    with pytest.raises(ValueError, match="hold"):
        HeldGoals(raw, -0.1)


def test_smoothing_is_refused_outside_0_to_1_and_for_a_velocity_policy():
    goal_policy = make_policy("lbgp", SHIPPED, robot="jackal")
    for bad in (1.0, -0.1, float("nan")):
        with pytest.raises(ValueError, match="smoothing"):
            SmoothedGoals(goal_policy, bad)
    with pytest.raises(ValueError, match="needs a goal policy"):
        SmoothedGoals(make_policy("e2e", robot="jackal"), 0.5)


def test_the_benchmark_scores_unsmoothed_as_the_sim_table_does_and_pairs_by_run(tmp_path, capsys):
    runs = tmp_path / "runs" / "LBGP_s0"
    runs.mkdir(parents=True)
    (runs / "policy.pt").write_bytes(Path(SHIPPED).read_bytes())
    out = tmp_path / "smoothing.json"
    result = main(["--runs", str(tmp_path / "runs"), "--smoothings", "0.5", "--scenarios", "turning_inside",
                   "--holds", "0.1", "--episodes", "2", "--json", str(out)])
    assert json.loads(out.read_text()) == result
    row = evaluate(make_policy("lbgp", SHIPPED, robot="jackal"), "lbgp", ["turning_inside"], robot="jackal", episodes=2,
                   seed=scenario_seed(0, "turning_inside"), obs_noise=True)[0]
    assert result["runs"]["LBGP_s0"]["0"]["turning_inside"] == pytest.approx(row["reward"], abs=1e-3)
    smoothed = result["runs"]["LBGP_s0"]["0.5"]["turning_inside"]
    assert smoothed != result["runs"]["LBGP_s0"]["0"]["turning_inside"]
    summary = result["smoothings"]["0.5"]
    assert summary["minus_unsmoothed_paired"]["per_run"]["LBGP_s0"] == pytest.approx(smoothed - row["reward"], abs=2e-3)
    assert summary["minus_unsmoothed_paired"]["ci95_half_width"] is None  # one run: no interval
    assert set(result["smoothings"]) == {"0.5", "hold0.1"}
    for bad in (["--smoothings", "1"], ["--smoothings", "x"], ["--smoothings", "", "--holds", ""], ["--holds", "-0.1"],
                ["--scenarios", "nowhere"]):
        with pytest.raises(SystemExit):
            main(["--runs", str(tmp_path / "runs"), "--json", str(out), *bad])
    assert "unknown scenario" in capsys.readouterr().err
