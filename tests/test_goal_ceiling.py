"""benchmarks/goal_ceiling.py: the searched goal sequence is a real, replayable episode."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from goal_ceiling import GoalSequencePolicy, closed_loop_goals, padded_to_horizon, search, turn_onset  # noqa: E402

from lbgp.actions import action_from_goal  # noqa: E402
from lbgp.rollout import run_episode  # noqa: E402
from lbgp.sim import make_env  # noqa: E402


def test_goal_sequence_holds_each_goal_for_its_segment_and_restarts_on_reset():
    goals = [[1.0, 0.0], [2.0, 0.5], [1.5, -0.5]]
    policy = GoalSequencePolicy(goals, segment=2)
    played = [policy.act(None) for _ in range(7)]
    expected = [action_from_goal(goals[k]) for k in (0, 0, 1, 1, 2, 2, 2)]  # the last goal is held past the end
    np.testing.assert_allclose(played, expected, atol=1e-6)
    policy.reset()
    np.testing.assert_allclose(policy.act(None), action_from_goal(goals[0]), atol=1e-6)


def test_a_prefix_is_played_step_by_step_before_the_segments():
    prefix = [[1.2, 0.1], [1.3, -0.1], [1.4, 0.2]]
    policy = GoalSequencePolicy([[2.0, 0.0], [1.0, 0.5]], segment=2, prefix=prefix)
    played = [policy.act(None) for _ in range(8)]
    expected = [action_from_goal(g) for g in prefix] + [action_from_goal(g) for g in ([2.0, 0.0],) * 2 + ([1.0, 0.5],) * 3]
    np.testing.assert_allclose(played, expected, atol=1e-6)


def test_the_turn_onset_is_where_the_persons_heading_first_turns_by_the_angle():
    """The turning scenarios turn from the first step, the trajectories later (trajectory_two's
    path bends before trajectory_three's), a straight walk never."""
    assert turn_onset("turning_ahead", 2.0) == 1
    two, three = turn_onset("trajectory_two", 5.0), turn_onset("trajectory_three", 5.0)
    assert 1 < two < three < 35
    assert turn_onset("trajectory_three", 2.0) < three  # a smaller angle shows sooner
    assert turn_onset("straight_ahead", 2.0) == 35


def test_a_frozen_prefix_replays_lbgps_own_goals_and_only_the_rest_is_searched():
    lbgp, goals = closed_loop_goals("trajectory_three", "lbgp")
    row = search("trajectory_three", population=3, elites=1, iterations=1, segment=2, start=goals, frozen=20)
    np.testing.assert_allclose(row["prefix"], goals[:20])
    assert len(row["goals"]) == 8  # (35 - 20) steps in segments of 2
    env = make_env("trajectory_three", robot="jackal", seed=0, obs_noise=False)
    replay = run_episode(env, GoalSequencePolicy(row["goals"], 2, row["prefix"]))
    assert abs(replay.total_reward - row["best"]) < 1e-6
    # up to the frozen step the episode is LBGP's own: its per-step goals replayed give the same rewards
    whole = run_episode(make_env("trajectory_three", robot="jackal", seed=0, obs_noise=False), GoalSequencePolicy(goals, 1))
    assert abs(whole.total_reward - lbgp) < 1e-3
    np.testing.assert_allclose(replay.rewards[:20], whole.rewards[:20], atol=1e-9)
    with pytest.raises(ValueError, match="frozen prefix needs a start"):
        search("trajectory_three", population=2, iterations=1, frozen=5)


def test_search_never_reports_less_than_the_constant_goal_and_its_best_sequence_replays_to_its_return():
    row = search("turning_ahead", population=3, elites=1, iterations=1, segment=7)
    assert row["best"] >= row["constant_1_5"]
    assert len(row["goals"]) == 5 and row["rollouts"] == 4
    replay = run_episode(make_env("turning_ahead", robot="jackal", seed=0, obs_noise=False),
                         GoalSequencePolicy(row["goals"], 7)).total_reward
    assert abs(replay - row["best"]) < 1e-6  # deterministic: the same goals give the same episode


def test_a_search_started_from_lbgps_goals_starts_at_lbgps_closed_loop_return():
    """The noise-free scenario is deterministic, so the shipped LBGP's goals replayed open-loop
    (one per step) give its own episode back: the search starts where the policy is."""
    lbgp, goals = closed_loop_goals("turning_inside", "lbgp")
    assert goals.shape == (35, 2)
    row = search("turning_inside", population=2, elites=1, iterations=1, segment=1, start=goals)
    assert abs(row["start"] - lbgp) < 1e-3
    assert row["best"] >= row["start"] and row["rollouts"] == 4


def test_a_training_level_episode_is_searched_and_replayed_by_its_seed():
    """--levels: a random-spawn episode is pinned by its evaluation seed, so the searched goals
    replay to the same return, and another seed is another episode."""
    episode = (0, 1, 3)
    row = search("circles", population=2, elites=1, iterations=1, segment=7, episode=episode)
    env = make_env("circles", robot="jackal", seed=0, obs_noise=False)
    env.reseed(list(episode))
    replay = run_episode(env, GoalSequencePolicy(row["goals"], 7)).total_reward
    assert abs(replay - row["best"]) < 1e-6
    env.reseed([0, 1, 4])
    other = run_episode(env, GoalSequencePolicy(row["goals"], 7)).total_reward
    assert abs(other - row["best"]) > 1e-3


def test_a_start_that_ended_early_is_searched_from_its_own_episode():
    """The shipped LBGP's noise-free episode (0, 2, 13) of the smoothed level ends in a contact after
    26 steps, so it asks for 26 goals: the search pads them with the last one (steps never played)
    and starts at LBGP's own return instead of averaging empty segments into NaN goals."""
    episode = (0, 2, 13)
    lbgp, goals = closed_loop_goals("smoothed", "lbgp", episode=episode)
    assert len(goals) < 35
    row = search("smoothed", population=2, elites=1, iterations=1, segment=1, start=goals, episode=episode)
    assert abs(row["start"] - lbgp) < 1e-3 and np.isfinite(row["goals"]).all() and row["best"] >= row["start"]
    assert padded_to_horizon(goals).shape == (35, 2) and (padded_to_horizon(goals)[len(goals):] == goals[-1]).all()


def test_the_written_result_names_the_command_that_made_it(tmp_path):
    import json

    from goal_ceiling import main

    out = tmp_path / "gc.json"
    args = ["--scenarios", "straight_ahead", "--iterations", "1", "--population", "2", "--segment", "35",
            "--workers", "1", "--json", str(out)]
    result = main(args)
    assert json.loads(out.read_text()) == result
    assert result["command"] == "python benchmarks/goal_ceiling.py " + " ".join(args)
    row = result["scenarios"]["straight_ahead"]
    assert row["best"] >= row["constant_1_5"] - 1e-9  # the search keeps the constant goal if nothing beats it


def test_react_after_needs_lbgps_goals_to_hold(capsys):
    from goal_ceiling import main

    with pytest.raises(SystemExit):
        main(["--scenarios", "trajectory_three", "--react-after-deg", "5", "--json", "unused.json"])
    assert "--react-after-deg needs --start-from lbgp" in capsys.readouterr().err


def test_finished_jobs_are_kept_in_a_progress_file_and_resume_runs_only_the_rest(tmp_path, capsys):
    """A run records each finished job's row as it comes; --resume with the same settings keeps
    those rows (a planted one comes back unchanged) and runs only the missing jobs; other settings
    are refused by name; a finished run leaves no progress file."""
    import json

    from goal_ceiling import main

    out = tmp_path / "gc.json"
    args = ["--scenarios", "straight_ahead,straight_behind", "--iterations", "1", "--population", "2", "--segment", "35",
            "--workers", "1", "--json", str(out)]
    first = main(args)
    progress = tmp_path / "gc.json.progress.jsonl"
    assert not progress.exists()
    settings = {**first["settings"], "jobs": [[s, "jackal", None] for s in ("straight_ahead", "straight_behind")]}
    planted = {**first["scenarios"]["straight_behind"], "best": 123.0}
    progress.write_text(json.dumps({"settings": settings}) + "\n" + json.dumps({"index": 1, "row": planted}) + "\n")
    resumed = main(args + ["--resume"])
    assert resumed["scenarios"]["straight_behind"]["best"] == 123.0
    assert resumed["scenarios"]["straight_ahead"] == first["scenarios"]["straight_ahead"]
    assert not progress.exists()
    progress.write_text(json.dumps({"settings": {**settings, "iterations": 5}}) + "\n")
    with pytest.raises(SystemExit):
        main(args + ["--resume"])
    assert "other settings" in capsys.readouterr().err and progress.exists()
