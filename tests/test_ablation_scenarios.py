"""benchmarks/ablation_scenarios.py: the ablation's policies scored on the paper's scenarios."""

import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from ablation_scenarios import main, summarise, variant_of  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import default_policy_path, make_policy  # noqa: E402


def test_variants_are_summarised_over_their_seeds():
    assert variant_of("LBGP-no-curriculum_s2") == "LBGP-no-curriculum"
    out = summarise({"LBGP_s0": {"sum": 10.0}, "LBGP_s1": {"sum": 12.0}, "E2E_s0": {"sum": 5.0}})
    assert out["LBGP"]["runs"] == ["LBGP_s0", "LBGP_s1"] and out["LBGP"]["mean_sum"] == 11.0
    assert out["LBGP"]["ci95_half_width"] == pytest.approx(12.706, abs=1e-3)  # t(0.975, 1) * std / sqrt(2), std = sqrt(2)
    assert out["E2E"]["mean_sum"] == 5.0 and out["E2E"]["ci95_half_width"] is None


def test_each_runs_policy_faces_the_same_noisy_episodes_as_lbgp_evaluate(tmp_path):
    runs = tmp_path / "ablation_runs"
    for run, method in (("LBGP_s0", "lbgp"), ("LBGP_s1", "lbgp"), ("E2E_s0", "e2e")):
        (runs / run).mkdir(parents=True)
        shutil.copy(default_policy_path(method), runs / run / "policy.pt")
    result = main(["--runs", str(runs), "--scenarios", "turning_ahead", "--episodes", "2", "--json", str(tmp_path / "out.json")])
    (direct,) = evaluate(make_policy("lbgp"), "lbgp", ["turning_ahead"], episodes=2, seed=0, obs_noise=True)
    assert result["runs"]["LBGP_s0"]["sum"] == pytest.approx(direct["reward"], abs=1e-3)
    assert result["variants"]["LBGP"]["sums"] == [result["runs"]["LBGP_s0"]["sum"]] * 2  # the same policy twice
    assert result["variants"]["LBGP"]["ci95_half_width"] == 0.0
    assert result["runs"]["E2E_s0"]["method"] == "e2e" and result["hc"]["method"] == "hc"
    assert result["runs"]["E2E_s0"]["sum"] != result["runs"]["LBGP_s0"]["sum"] != result["hc"]["sum"]
    assert (tmp_path / "out.json").is_file()
