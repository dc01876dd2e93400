"""benchmarks/target_status.py: the open issues' targets read from a results folder."""

import csv
import json
import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from target_status import main  # noqa: E402

RESULTS = Path(__file__).resolve().parents[1] / "results"
READ = ("sim_table.csv", "sim_table.md", "goal_ceiling_turning_long.json", "goal_ceiling_trajectories_react5.json",
        "levels_vs_ceiling.json", "goal_ceiling_levels_20.json", "real_protocol_table.csv",
        "safety_sweep.json", "bench_planner.json", "bench_env.json", "goal_sweep.json", "goal_jitter.json")


@pytest.fixture
def results(tmp_path):
    folder = tmp_path / "results"
    folder.mkdir()
    for name in READ:
        shutil.copy(RESULTS / name, folder / name)
    return folder


def _row(result, start):
    (row,) = [r for r in result["rows"] if r["target"].startswith(start)]
    return row


def _edit_csv(path, change):
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    for row in rows:
        change(row)
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return rows


def test_the_leads_are_the_tables_row_sums_and_flip_at_their_targets(results, tmp_path):
    """The trajectory lead is LBGP - HC summed over the three rows of the CSV; raising LBGP's
    trajectory_three reward until the sum passes +5 turns that target met, and nothing else."""
    before = main(["--results", str(results), "--json", str(tmp_path / "before.json")])
    with (results / "sim_table.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    reward = {(r["scenario"], r["method"]): float(r["reward"]) for r in rows}
    lead = sum(reward[(s, "lbgp")] - reward[(s, "hc")] for s in ("trajectory_one", "trajectory_two", "trajectory_three"))
    row = _row(before, "LBGP - HC summed over the trajectory rows")
    assert row["value"].startswith(f"{lead:+.2f} ± ") and row["met"] == (lead >= 5)
    raise_by = 5.01 - lead

    def lift(r):
        if r["scenario"] == "trajectory_three" and r["method"] == "lbgp":
            r["reward"] = str(float(r["reward"]) + raise_by)
    _edit_csv(results / "sim_table.csv", lift)
    after = main(["--results", str(results)])
    assert _row(after, "LBGP - HC summed over the trajectory rows")["met"]
    assert after["met"] == before["met"] + (0 if lead >= 5 else 1)
    assert json.loads((tmp_path / "before.json").read_text())["rows"] == before["rows"]


def test_a_lost_row_contacts_and_a_slow_planner_are_reported_missed(results):
    """HC above LBGP on a row, one contact in the safety sweep and a planner call median above
    0.5 ms each make their target missed, with the row named."""
    def hc_wins(r):
        if r["scenario"] == "turning_ahead":
            r["winner_ours"] = "hc"
    _edit_csv(results / "sim_table.csv", hc_wins)
    sweep = json.loads((results / "safety_sweep.json").read_text())
    sweep["contacts"] = 1
    (results / "safety_sweep.json").write_text(json.dumps(sweep))
    bench = json.loads((results / "bench_planner.json").read_text())
    bench["jackal_N20"]["median_ms"] = 0.4
    bench["jackal_N20"]["osqp_ms"]["median"] = 0.3
    (results / "bench_planner.json").write_text(json.dumps(bench))
    before = main(["--results", str(results)])
    search = json.loads((results / "goal_ceiling_levels_20.json").read_text())
    found = search["levels"]["smoothed"]["share_of_ceiling"]["best_known"]
    assert _row(before, "LBGP's return on the smoothed level")["bound"] == f"{found:.0%}"
    search["levels"]["smoothed"]["share_of_ceiling"]["best_known"] = 0.7
    (results / "goal_ceiling_levels_20.json").write_text(json.dumps(search))
    result = main(["--results", str(results)])
    smoothed = _row(result, "LBGP's return on the smoothed level")
    assert smoothed["bound"] == "70%" and smoothed["beyond_bound"] is False and not smoothed["met"]
    every_row = _row(result, "LBGP wins or ties every row")
    assert not every_row["met"] and "turning_ahead" in every_row["note"]
    assert not _row(result, ">= 1,000 seeded episodes")["met"]
    assert _row(result, "jackal: planner call median")["met"]
    assert _row(result, "jackal: planner call median")["bound"] == 0.3
    assert _row(result, "jackal: planner call median")["beyond_bound"] is False


def test_a_missing_or_broken_file_is_named_and_nothing_is_written(results, tmp_path, capsys):
    out = tmp_path / "status.json"
    (results / "goal_jitter.json").unlink()
    with pytest.raises(SystemExit) as stop:
        main(["--results", str(results), "--json", str(out)])
    assert stop.value.code == 2 and "goal_jitter.json: missing" in capsys.readouterr().err and not out.exists()
    (results / "goal_jitter.json").write_text("{not json")
    with pytest.raises(SystemExit):
        main(["--results", str(results), "--json", str(out)])
    assert "goal_jitter.json: not valid JSON" in capsys.readouterr().err and not out.exists()
    (results / "goal_jitter.json").write_text("{}")
    with pytest.raises(SystemExit):
        main(["--results", str(results), "--markdown", str(tmp_path / "status.md")])
    assert "goal_jitter.json: has no kept" in capsys.readouterr().err and not (tmp_path / "status.md").exists()
    shutil.copy(RESULTS / "goal_jitter.json", results / "goal_jitter.json")
    bench = json.loads((results / "bench_planner.json").read_text())
    del bench["turtlebot2_N20"]["osqp_ms"]["p99"]
    (results / "bench_planner.json").write_text(json.dumps(bench))
    with pytest.raises(SystemExit):
        main(["--results", str(results), "--json", str(out)])
    assert "bench_planner.json: has no turtlebot2_N20/osqp_ms/p99" in capsys.readouterr().err and not out.exists()
    shutil.copy(RESULTS / "bench_planner.json", results / "bench_planner.json")
    _edit_csv(results / "sim_table.csv", lambda r: r.pop("winner_ours"))
    with pytest.raises(SystemExit):
        main(["--results", str(results), "--json", str(out)])
    assert "sim_table.csv: has no column winner_ours" in capsys.readouterr().err and not out.exists()
