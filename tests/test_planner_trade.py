"""benchmarks/planner_trade.py: a planner variant scored for HC and LBGP on the sim table's episodes
and on the planner issue's own protocol."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from planner_trade import main, parse_variant  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402


def test_variants_are_parsed_and_checked_against_the_planner_config():
    assert parse_variant("preset") == {} and parse_variant(" ") == {}
    assert parse_variant("weight_turn=0.05,sqp_iterations=2,lateral_acc_limit_clear=none") == {
        "weight_turn": 0.05, "sqp_iterations": 2, "lateral_acc_limit_clear": None}
    assert isinstance(parse_variant("sqp_iterations=2")["sqp_iterations"], int)
    with pytest.raises(ValueError, match="not NAME=VALUE"):
        parse_variant("weight_turn")
    with pytest.raises(ValueError, match="not a planner setting"):
        parse_variant("weigth_turn=0.05")
    with pytest.raises(ValueError, match="sqp_iterations"):
        parse_variant("sqp_iterations=2.5")
    with pytest.raises(ValueError, match="'many' is not a number"):
        parse_variant("weight_turn=many")


def test_bad_variants_end_with_a_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--variants", "preset;bogus=1", "--json", str(tmp_path / "r.json")])
    assert exit_info.value.code == 2
    assert "bogus" in capsys.readouterr().err
    assert not (tmp_path / "r.json").exists()


def test_a_variant_is_scored_as_the_sim_table_and_the_planner_issue_score_it(tmp_path):
    # the Jackal's turn-rate weight before 2026-12-06 against the preset, one episode per scenario
    result = main(["--variants", "preset;weight_turn=0.05", "--seeds", "0", "--episodes", "1",
                   "--json", str(tmp_path / "r.json")])
    preset, before = result["variants"]["preset"], result["variants"]["weight_turn=0.05"]
    assert before["changes"] == {"weight_turn": 0.05} and preset["changes"] == {}
    # trajectory_three is the sim table's scenario 8: its episodes are seeded 8000, noise on
    old = planner_config_for("jackal", {"weight_turn": 0.05})
    (hc,) = evaluate(make_policy("hc"), "hc", ["trajectory_three"], episodes=1, seed=8000, obs_noise=True, planner_config=old)
    scores = before["scores"]["0"]
    assert scores["hc"]["per_scenario"]["trajectory_three"] == pytest.approx(hc["reward"], abs=2e-3)
    assert scores["hc"]["per_scenario"] != preset["scores"]["0"]["hc"]["per_scenario"]  # the weight changes the episodes
    assert scores["lbgp_minus_hc"]["trajectories"] == pytest.approx(
        scores["lbgp"]["trajectories"] - scores["hc"]["trajectories"], abs=1e-3)
    # the planner issue's protocol: `lbgp evaluate --method hc --scenario all --episodes 5`, noise-free
    original = preset["hc_original_protocol"]["per_scenario"]
    assert len(original) == 9
    (first,) = evaluate(make_policy("hc"), "hc", ["straight_ahead"], episodes=5, seed=0)
    assert original["straight_ahead"] == pytest.approx(first["reward"], abs=2e-3)
    assert (tmp_path / "r.json").is_file()
