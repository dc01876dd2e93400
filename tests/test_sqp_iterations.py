"""benchmarks/sqp_iterations.py and the planner configuration it evaluates with."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from sqp_iterations import main  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402


def test_evaluate_drives_with_the_planner_configuration_it_is_given():
    hc = make_policy("hc")
    (preset,) = evaluate(hc, "hc", ["straight_ahead"], episodes=1, seed=0)
    slow = planner_config_for("jackal").with_(max_vel_x=0.3)  # half the person's walking speed
    (capped,) = evaluate(hc, "hc", ["straight_ahead"], episodes=1, seed=0, planner_config=slow)
    assert preset["reward"] > 20.0
    assert capped["reward"] < preset["reward"] - 5.0  # the person catches up with a robot held to 0.3 m/s


def test_caps_are_scored_on_the_sim_tables_episodes_and_compared_with_a_converged_band(tmp_path):
    result = main(["--iterations", "1,30", "--reference-iterations", "30", "--parts", "command,scores", "--episodes", "1",
                   "--json", str(tmp_path / "r.json")])
    # turning_inside is the sim table's scenario 4: its episodes are seeded 4000
    one = planner_config_for("jackal").with_(sqp_iterations=1)
    (hc,) = evaluate(make_policy("hc"), "hc", ["turning_inside"], episodes=1, seed=4000, obs_noise=True, planner_config=one)
    scores = result["scores"]
    assert scores["1"]["hc"]["per_scenario"]["turning_inside"] == pytest.approx(hc["reward"], abs=2e-3)
    assert scores["1"]["hc"]["per_scenario"] != scores["30"]["hc"]["per_scenario"]  # the cap changes the episodes
    row = scores["1"]
    assert row["lbgp_minus_hc"]["turning"] == pytest.approx(row["lbgp"]["turning"] - row["hc"]["turning"], abs=1e-3)
    command = result["command"]
    assert command["30"]["v_max"] == 0.0 and command["30"]["w_max"] == 0.0  # the reference against itself
    assert command["1"]["v_max"] > 0.01  # one Gauss-Newton step stops short of the converged band somewhere
    assert 1.0 < command["reference_sqp_iterations_per_call"] <= 30 * 3  # up to three candidate bands a call
    assert (tmp_path / "r.json").is_file()
