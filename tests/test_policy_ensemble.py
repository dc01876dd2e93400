"""benchmarks/policy_ensemble.py: acting with the mean goal of several trained policies."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from policy_ensemble import EnsemblePolicy, main  # noqa: E402

from lbgp.actions import goal_from_action  # noqa: E402
from lbgp.policies import default_policy_path, make_policy  # noqa: E402

SHIPPED = str(default_policy_path("lbgp"))
OTHER = str(Path(__file__).resolve().parents[1] / "results" / "motion_features_runs" / "LBGP_s0" / "policy.pt")


def test_an_ensemble_of_one_policy_twice_acts_as_that_policy(noisy_observations):
    alone, twice = make_policy("lbgp", SHIPPED, robot="jackal"), EnsemblePolicy([SHIPPED, SHIPPED])
    for obs in noisy_observations("turning_inside", 0, 6):
        np.testing.assert_allclose(twice.act(obs), alone.act(obs), atol=1e-5)


def test_an_ensemble_acts_with_the_mean_of_its_members_goals(noisy_observations):
    ensemble = EnsemblePolicy([SHIPPED, OTHER], goal_deadband=0.0)
    members = [make_policy("lbgp", f, robot="jackal", goal_deadband=0.0) for f in (SHIPPED, OTHER)]
    apart = 0.0
    for obs in noisy_observations("turning_inside", 0, 6):
        goals = [goal_from_action(m.act(obs)) for m in members]
        apart = max(apart, float(np.hypot(*(goals[0] - goals[1]))))
        np.testing.assert_allclose(goal_from_action(ensemble.act(obs)), (goals[0] + goals[1]) / 2, atol=1e-5)
    assert apart > 0.01  # the two members disagree, so the mean is not either one's goal


def test_the_benchmark_scores_members_and_ensemble_on_the_same_episodes(tmp_path, capsys):
    out = tmp_path / "ensemble.json"
    result = main(["--json", str(out), "--ensemble", f"{SHIPPED},{OTHER}", "--scenarios", "straight_ahead", "--episodes", "1"])
    assert json.loads(out.read_text()) == result
    (row,) = result["ensembles"]
    assert set(row["members"]) == {SHIPPED, OTHER}
    assert row["members_mean_sum"] == pytest.approx(np.mean(list(row["members"].values())), abs=1e-3)
    assert row["minus_members_mean"] == pytest.approx(row["sum"] - row["members_mean_sum"], abs=1e-3)
    with pytest.raises(SystemExit):
        main(["--json", str(out), "--ensemble", SHIPPED])
    assert "two or more" in capsys.readouterr().err
