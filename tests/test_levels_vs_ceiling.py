"""benchmarks/levels_vs_ceiling.py: each method's return on the training levels as a share of the ceiling."""

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from levels_vs_ceiling import main  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import level_names  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OTHER = ROOT / "results" / "motion_features_runs" / "LBGP_s0" / "policy.pt"
CEILING = str(ROOT / "results" / "reward_ceiling.json")


def test_a_candidate_lbgp_policy_is_scored_on_the_same_seeded_level_episodes(tmp_path):
    out = tmp_path / "levels.json"
    args = ["--json", str(out), "--methods", "lbgp", "--episodes", "2", "--ceiling", CEILING]
    shipped = main(args)["methods"]["lbgp"]
    candidate = main(args + ["--lbgp-policy", str(OTHER)])
    assert json.loads(out.read_text()) == candidate
    assert str(OTHER) in candidate["command"]
    rows = candidate["methods"]["lbgp"]
    expected = evaluate(make_policy("lbgp", policy_file=OTHER, robot="jackal"), "lbgp", level_names(), robot="jackal",
                        episodes=2, seed=0)
    for row in expected:
        assert rows[row["scenario"]]["mean_return"] == pytest.approx(row["reward"], abs=1e-3)
        ceiling = candidate["ceilings"][row["scenario"]]
        assert rows[row["scenario"]]["share_of_ceiling"] == pytest.approx(row["reward"] / ceiling, abs=1e-3)
    # the flag really swapped the policy: another policy plays the same episodes differently
    assert any(abs(rows[k]["mean_return"] - shipped[k]["mean_return"]) > 1e-3 for k in rows)
