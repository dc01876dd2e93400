"""benchmarks/episode_profile.py: per-step reward, D and alpha on one scenario's sim-table episodes."""

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from episode_profile import main, profile  # noqa: E402


def test_the_steps_add_up_to_the_tables_episode_reward_and_methods_differ():
    result = profile("turning_inside", episodes=2, methods=("hc", "lbgp"))
    for method in ("hc", "lbgp"):
        row = result[method]
        assert row["terminated_early"] == 0
        steps = row["per_step"]
        assert {len(v) for v in steps.values()} == {35}  # one entry per agent step
        assert sum(steps["reward"]) == pytest.approx(row["reward"], abs=35 * 1e-4 + 1e-3)
        assert all(0.5 < d < 5.0 for d in steps["distance"])
    assert result["hc"]["per_step"]["person_yaw_deg"] == result["lbgp"]["per_step"]["person_yaw_deg"]  # the same person
    assert result["hc"]["per_step"]["alpha_deg"] != result["lbgp"]["per_step"]["alpha_deg"]


def test_the_cli_writes_json_and_refuses_unknown_methods(tmp_path, capsys):
    out = tmp_path / "p.json"
    assert main(["--scenario", "straight_ahead", "--episodes", "1", "--methods", "hc", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["scenario"] == "straight_ahead" and list(data["methods"]) == ["hc"]
    for bad in (["--methods", "hc,teleport"], ["--episodes", "0"]):
        with pytest.raises(SystemExit) as exit_info:
            main(bad)
        assert exit_info.value.code == 2 and bad[0] in capsys.readouterr().err  # the error names the option
