"""benchmarks/levels_vs_ceiling.py: each method's return on the training levels as a share of the ceiling."""

import json
import sys
from pathlib import Path

import numpy as np
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


def test_planner_changes_drive_every_method_on_the_changed_planner(tmp_path, capsys):
    """--planner-changes max_vel_x=2.0: the methods play the same episodes on the faster planner, and
    the planner-speed ceiling is read at its speed; an unknown setting is refused with nothing written."""
    from lbgp.planner import planner_config_for
    from _common import level_ceilings

    args = ["--methods", "hc", "--episodes", "2", "--ceiling", CEILING]
    faster = main(args + ["--planner-changes", "max_vel_x=2.0", "--json", str(tmp_path / "fast.json")])
    preset = main(args + ["--json", str(tmp_path / "preset.json")])
    expected = evaluate(make_policy("hc", robot="jackal"), "hc", level_names(), robot="jackal", episodes=2, seed=0,
                        planner_config=planner_config_for("jackal").with_(max_vel_x=2.0))
    rows = faster["methods"]["hc"]
    for row in expected:
        assert rows[row["scenario"]]["mean_return"] == pytest.approx(row["reward"], abs=1e-3)
    assert any(abs(rows[k]["mean_return"] - preset["methods"]["hc"][k]["mean_return"]) > 1e-3 for k in rows)
    assert faster["planner_changes"] == {"max_vel_x": 2.0} and faster["planner_vmax"] == 2.0
    assert preset["planner_vmax"] == planner_config_for("jackal").max_vel_x
    at_two = level_ceilings(CEILING, 2.0)
    assert faster["planner_speed_ceilings"] == {k: at_two[k]["mean_bound"] for k in rows}
    with pytest.raises(SystemExit) as exit_info:
        main(args + ["--planner-changes", "top_speed=2", "--json", str(tmp_path / "bad.json")])
    assert exit_info.value.code == 2 and "top_speed" in capsys.readouterr().err
    assert not (tmp_path / "bad.json").exists()


def test_start_sides_match_the_evaluated_episodes_and_split_their_returns():
    from levels_vs_ceiling import StartSides, by_start

    from lbgp.geometry import distance_and_alpha
    from lbgp.rollout import ConstantGoalPolicy
    from lbgp.viz.trajectory_plot import TrajectoryCollector

    levels, episodes = level_names()[:2], 8
    sides = StartSides()
    evaluate(ConstantGoalPolicy(), "scripted", levels, robot="jackal", episodes=episodes, seed=3, recorder=sides, horizon=3)
    collector = TrajectoryCollector()
    evaluate(ConstantGoalPolicy(), "scripted", levels, robot="jackal", episodes=episodes, seed=3, recorder=collector, horizon=3)
    # one entry per episode, from its spawn (its first logged state), not from a later step
    spawns = [abs(distance_and_alpha(ep["robot"][0], ep["person"][0])[1]) > np.pi / 2 for ep in collector.episodes]
    assert sides.behind == spawns and len(spawns) == 2 * episodes
    assert 0 < sum(spawns) < 2 * episodes  # both sides occur
    ceiling = {"mean_bound_starts_in_front_half": 20.0, "mean_bound_starts_in_back_half": 10.0}
    split = by_start([10.0, 2.0, 8.0], np.array([False, True, False]), ceiling)
    assert split == {"front": {"episodes": 2, "mean_return": 9.0, "share_of_ceiling": 0.45},
                     "behind": {"episodes": 1, "mean_return": 2.0, "share_of_ceiling": 0.2}}
    assert by_start([1.0], np.array([False]), ceiling)["behind"] == {"episodes": 0, "mean_return": None, "share_of_ceiling": None}


def test_ceilings_are_read_at_a_stated_speed_on_the_finest_grid(tmp_path):
    from _common import level_ceilings

    rows = [{"level": "straight", "vmax": v, "grid_m": g, "mean_bound": b} for v, g, b in
            ((1.5, 0.06, 19.3), (2.0, 0.06, 21.9), (1.5, 0.046, 18.9), (2.0, 0.046, 21.4))]
    path = tmp_path / "ceiling.json"
    path.write_text(json.dumps({"results": rows}))
    assert level_ceilings(path)["straight"]["mean_bound"] == 21.4  # top speed, finest grid, whatever the order
    path.write_text(json.dumps({"results": rows[::-1]}))
    assert level_ceilings(path, 1.5)["straight"]["mean_bound"] == 18.9
    with pytest.raises(ValueError, match="no rows at vmax 1.0"):
        level_ceilings(path, 1.0)
