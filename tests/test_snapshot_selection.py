"""Policy snapshots during training (``snapshot_every_s``) and benchmarks/snapshot_selection.py,
which picks a run's actor by held-out training-level episodes."""

import json
import shutil
import sys
from pathlib import Path

import pytest
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from snapshot_selection import main, select  # noqa: E402

from lbgp.agent import load_policy  # noqa: E402
from lbgp.agent.checkpoint import load_checked, save_atomic  # noqa: E402
from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.policy import FORMAT  # noqa: E402
from lbgp.agent.train import train  # noqa: E402
from lbgp.policies import default_policy_path  # noqa: E402

SHIPPED = default_policy_path("lbgp")


def test_a_run_writes_a_policy_snapshot_every_interval_of_wall_time(tmp_path):
    cfg = D4PGConfig(total_steps=600, min_replay=100, num_actors=2, checkpoint_every_s=1.0, horizon=10, hidden=(32, 32),
                     batch_size=32, seed=3, snapshot_every_s=1.0)
    summary = train(cfg, tmp_path / "run", progress=False)
    files = sorted((tmp_path / "run" / "snapshots").glob("policy_*s.pt"))
    seconds = [int(f.stem.split("_")[1].rstrip("s")) for f in files]
    assert len(files) >= 2 and seconds == sorted(set(seconds)) and seconds[-1] <= summary["wall_time_s"]
    metas = [load_policy(f).meta["extra"] for f in files]
    assert [m["env_steps"] for m in metas] == sorted(m["env_steps"] for m in metas)
    assert metas[-1]["learner_updates"] > metas[0]["learner_updates"]  # later snapshots hold later actors
    assert all(int(m["wall_time_s"]) == s for m, s in zip(metas, seconds))
    with pytest.raises(ValueError, match="snapshot_every_s"):
        D4PGConfig(snapshot_every_s=0.5).validate()


def test_a_resumed_run_continues_the_snapshot_schedule_without_overwriting(tmp_path):
    cfg = D4PGConfig(total_steps=400, min_replay=100, horizon=10, hidden=(16,), batch_size=16, seed=4, snapshot_every_s=1.0)
    first = train(cfg, tmp_path / "run", backend="inline", progress=False)
    before = {f.name: f.read_bytes() for f in (tmp_path / "run" / "snapshots").glob("policy_*s.pt")}
    assert before, "the first part should have lasted over a second"
    train(D4PGConfig(total_steps=800), tmp_path / "run", resume=True, backend="inline", progress=False)
    files = sorted((tmp_path / "run" / "snapshots").glob("policy_*s.pt"))
    later = [f for f in files if f.name not in before]
    assert all(f.read_bytes() == before[f.name] for f in files if f.name in before)  # none rewritten
    assert later, "the resumed part should have written snapshots too"
    for f in later:  # named by the run's wall time, counted on from the checkpoint, with later actors
        meta = load_policy(f).meta["extra"]
        assert int(f.stem.split("_")[1].rstrip("s")) > first["wall_time_s"] - 1 and meta["env_steps"] > first["env_steps"]


def _run_with_a_bad_snapshot(root: Path) -> Path:
    """A run folder whose final policy and 200 s snapshot are the shipped policy and whose 100 s
    snapshot is that policy with its residual pushed to the edge of its box (goal 0.75 m off)."""
    run = root / "LBGP-test_s0"
    (run / "snapshots").mkdir(parents=True)
    shutil.copy(SHIPPED, run / "policy.pt")
    shutil.copy(SHIPPED, run / "snapshots" / "policy_000200s.pt")
    bad = load_checked(SHIPPED, FORMAT)
    bad["actor"]["net.5.bias"] = torch.tensor([-20.0, 20.0])
    save_atomic(bad, run / "snapshots" / "policy_000100s.pt")
    return run


def test_the_rule_picks_by_validation_and_reports_against_the_final_policy(tmp_path):
    _run_with_a_bad_snapshot(tmp_path / "runs")
    out = tmp_path / "selection.json"
    result = main(["--runs", str(tmp_path / "runs"), "--json", str(out), "--validation-episodes", "2",
                   "--scenarios", "straight_ahead", "--episodes", "1"])
    assert json.loads(out.read_text()) == result
    run = result["runs"]["LBGP-test_s0"]
    assert list(run["policies"]) == ["000100s", "000200s", "final"]
    scores = {n: p["validation"]["sum"] for n, p in run["policies"].items()}
    assert scores["000100s"] < scores["final"] - 5  # the pushed residual loses on the training levels
    assert scores["000200s"] == scores["final"]  # the same policy on the same episodes
    assert run["policies"]["000100s"]["test"]["sum"] < run["policies"]["final"]["test"]["sum"]
    assert run["selection"]["chosen"] != "000100s" and run["selection"]["chosen_minus_final"] == 0.0
    assert result["chosen_minus_final"]["per_run"] == [0.0] and result["chosen_minus_final"]["ci95_half_width"] is None


def test_the_rule_only_chooses_from_the_given_wall_time_on():
    def policy(t, val, test):
        return {"wall_time_s": t, "validation": {"sum": val}, "test": {"sum": test}}

    run = {"policies": {"000100s": policy(100, 9.0, 150.0), "000200s": policy(200, 5.0, 160.0), "final": policy(300, 4.0, 158.0)}}
    early = select(run, from_s=0)
    assert early["chosen"] == "000100s" and early["chosen_minus_final"] == pytest.approx(-8.0)
    late = select(run, from_s=150)
    assert late["chosen"] == "000200s" and late["chosen_minus_final"] == pytest.approx(2.0)
    assert late["best_test_sum_in_hindsight"] == 160.0 and late["spearman_validation_test"] == pytest.approx(-0.5)


def test_a_run_without_snapshots_is_refused(tmp_path):
    run = tmp_path / "runs" / "LBGP-test_s0"
    run.mkdir(parents=True)
    shutil.copy(SHIPPED, run / "policy.pt")
    with pytest.raises(SystemExit, match="snapshot_every_s"):
        main(["--runs", str(tmp_path / "runs"), "--json", str(tmp_path / "x.json")])


def test_the_rule_can_see_other_episodes_of_the_test_scenarios_but_never_the_test_seed(tmp_path, capsys):
    _run_with_a_bad_snapshot(tmp_path / "runs")
    result = main(["--runs", str(tmp_path / "runs"), "--json", str(tmp_path / "selection.json"), "--validation", "scenarios",
                   "--validation-episodes", "2", "--validation-seed", "7", "--scenarios", "straight_ahead", "--episodes", "1"])
    assert result["validation"] == {"scenarios": ["straight_ahead"], "episodes_per_scenario": 2, "seed": 7}
    run = result["runs"]["LBGP-test_s0"]
    validation = {n: p["validation"] for n, p in run["policies"].items()}
    assert all(list(v["per_scenario"]) == ["straight_ahead"] for v in validation.values())
    assert validation["000100s"]["sum"] < validation["final"]["sum"] - 5  # the pushed residual loses there too
    assert validation["000200s"] == validation["final"]
    # other episodes than the test's: the same policy scores differently on them
    assert validation["final"]["sum"] != run["policies"]["final"]["test"]["sum"]
    assert run["selection"]["chosen"] != "000100s"
    with pytest.raises(SystemExit):
        main(["--runs", str(tmp_path / "runs"), "--json", str(tmp_path / "same.json"), "--validation", "scenarios",
              "--validation-seed", "0", "--seed", "0"])
    assert "the rule would see the test's episodes" in capsys.readouterr().err
    assert not (tmp_path / "same.json").exists()


def test_runs_scored_earlier_are_summarised_with_new_ones_without_scoring_them_again(tmp_path, capsys):
    settings = ["--validation", "scenarios", "--validation-episodes", "1", "--validation-seed", "7",
                "--scenarios", "straight_ahead", "--episodes", "1"]
    first = _run_with_a_bad_snapshot(tmp_path / "runs")
    earlier = main(["--runs", str(tmp_path / "runs"), "--json", str(tmp_path / "first.json")] + settings)
    for f in [first / "policy.pt", *(first / "snapshots").glob("*.pt")]:
        f.write_bytes(b"not a checkpoint")  # scoring the first run again would fail on these
    second = shutil.copytree(first, tmp_path / "runs" / "LBGP-test_s1")  # a second run: the shipped policy throughout
    for f in [second / "policy.pt", *(second / "snapshots").glob("*.pt")]:
        shutil.copy(SHIPPED, f)
    both = main(["--runs", str(tmp_path / "runs"), "--reuse", str(tmp_path / "first.json"),
                 "--json", str(tmp_path / "both.json")] + settings)
    assert list(both["runs"]) == ["LBGP-test_s0", "LBGP-test_s1"] and both["reused"] == [str(tmp_path / "first.json")]
    assert both["runs"]["LBGP-test_s0"]["policies"] == earlier["runs"]["LBGP-test_s0"]["policies"]
    assert both["runs"]["LBGP-test_s1"]["policies"]["000100s"]["test"] == earlier["runs"]["LBGP-test_s0"]["policies"]["final"]["test"]
    assert len(both["chosen_minus_final"]["per_run"]) == 2 and both["chosen_minus_final"]["ci95_half_width"] is not None
    # only the reused file, chosen again from a later wall time: no run folder needed
    shutil.rmtree(tmp_path / "runs")
    later = main(["--reuse", str(tmp_path / "both.json"), "--from-s", "150", "--json", str(tmp_path / "later.json")] + settings)
    assert later["runs"]["LBGP-test_s0"]["selection"]["chosen"] in ("000200s", "final")
    assert all(later["runs"][r]["policies"] == both["runs"][r]["policies"] for r in both["runs"])
    # scored on other episodes: refused, nothing written
    with pytest.raises(SystemExit):
        main(["--reuse", str(tmp_path / "first.json"), "--json", str(tmp_path / "other.json")] + settings[:-1] + ["2"])
    assert "other test episodes" in capsys.readouterr().err and not (tmp_path / "other.json").exists()
    with pytest.raises(SystemExit):
        main(["--json", str(tmp_path / "none.json")] + settings)
    assert "give --runs, --reuse or both" in capsys.readouterr().err


def test_rank_correlation_is_none_where_it_is_undefined():
    from snapshot_selection import spearman

    assert spearman([1.0, 2.0], [2.0, 1.0]) is None  # too few
    assert spearman([1.0, 1.0, 1.0], [1.0, 2.0, 3.0]) is None  # constant: no ranking
    assert spearman([1.0, 2.0, 3.0], [3.0, 2.0, 1.0]) == -1.0
