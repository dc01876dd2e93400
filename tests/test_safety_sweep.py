"""benchmarks/safety_sweep.py: contacts and loops over seeded evaluation episodes."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from safety_sweep import main  # noqa: E402

from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import level_names, scenario_names  # noqa: E402


def test_the_sweep_counts_each_scenarios_episodes_on_the_planner_it_is_given(tmp_path, capsys):
    """One episode per scenario: the counts and rewards are evaluate's on the same seeded noisy
    episodes, on the preset with --planner-changes applied; an unknown setting is refused by name."""
    out = tmp_path / "sweep.json"
    result = main(["--json", str(out), "--method", "hc", "--episodes", "9", "--planner-changes", "max_vel_x=2.0"])
    faster = planner_config_for("jackal").with_(max_vel_x=2.0)
    rows = evaluate(make_policy("hc", robot="jackal"), "hc", scenario_names(), robot="jackal", episodes=1, seed=0,
                    obs_noise=True, planner_config=faster)
    assert result["planner_changes"] == {"max_vel_x": 2.0} and result["episodes"] == 9 and out.is_file()
    for row in rows:
        got = result["per_scenario"][row["scenario"]]
        assert got["reward"] == pytest.approx(row["reward"], abs=1e-3)
        assert (got["contacts"], got["loops"]) == (int(row["collisions"]), int(row.get("loops", 0)))
    assert result["contacts"] == sum(v["contacts"] for v in result["per_scenario"].values())
    preset = main(["--json", str(tmp_path / "preset.json"), "--method", "hc", "--episodes", "9"])
    assert preset["planner_changes"] == {}
    assert any(preset["per_scenario"][k]["reward"] != result["per_scenario"][k]["reward"] for k in scenario_names())
    with pytest.raises(SystemExit) as exit_info:
        main(["--json", str(tmp_path / "bad.json"), "--planner-changes", "top_speed=2"])
    assert exit_info.value.code == 2 and "top_speed" in capsys.readouterr().err
    assert not (tmp_path / "bad.json").exists()


def test_levels_sweeps_the_training_levels_episodes_as_evaluate_plays_them(tmp_path):
    """--levels: one seeded, noisy random-spawn episode per training level, the same as evaluate's."""
    result = main(["--levels", "--json", str(tmp_path / "levels.json"), "--method", "hc", "--episodes", "4"])
    rows = evaluate(make_policy("hc", robot="jackal"), "hc", level_names(), robot="jackal", episodes=1, seed=0, obs_noise=True)
    assert result["settings"] == "training levels" and sorted(result["per_scenario"]) == sorted(level_names())
    for row in rows:
        got = result["per_scenario"][row["scenario"]]
        assert got["reward"] == pytest.approx(row["reward"], abs=1e-3)
        assert got["contacts"] == int(row["collisions"])
