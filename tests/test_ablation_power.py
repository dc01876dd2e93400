"""benchmarks/ablation_power.py: the seed-to-seed spread of the ablations and the runs a difference needs."""

import json
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from ablation_power import main, pooled_sd, runs_needed, t_test_power, variant_groups  # noqa: E402
from goal_ceiling import TRAJECTORIES, TURNING  # noqa: E402

ROWS = ("straight_ahead", "straight_behind", *TURNING, *TRAJECTORIES)


def test_runs_needed_matches_cohens_tables():
    # two-sided 5 %, 80 % power, equal groups: d = 1 -> 17, d = 0.8 -> 26, d = 0.5 -> 64 per group
    assert [runs_needed(d, 1.0) for d in (1.0, 0.8, 0.5)] == [17, 26, 64]
    assert runs_needed(2.0, 2.0) == 17  # only the ratio matters
    assert t_test_power(1.0, 1.0, 17) >= 0.8 > t_test_power(1.0, 1.0, 16)
    with pytest.raises(ValueError, match="positive"):
        runs_needed(0.0, 1.0)


def test_pooled_sd_pools_each_sample_about_its_own_mean():
    sd, df = pooled_sd([[1.0, 3.0], [2.0, 4.0, 6.0], [100.0, 100.0]])
    assert df == 4 and sd == pytest.approx(math.sqrt((2.0 + 8.0) / 4))  # the offsets between samples do not count
    with pytest.raises(ValueError):
        pooled_sd([[5.0]])


def _scores(path: Path, variants: dict[str, list[float]]) -> None:
    """An ablation_scenarios-format file: each run's rows all equal to its value / 9, so its sum is the value."""
    runs, info = {}, {}
    for variant, values in variants.items():
        names = [f"{variant}_s{k}" for k in range(len(values))]
        info[variant] = {"runs": names}
        for name, value in zip(names, values):
            runs[name] = {"policy": f"runs/{name}/policy.pt", "per_scenario": {r: value / 9 for r in ROWS}}
    path.write_text(json.dumps({"variants": info, "runs": runs, "hc": {}}))


def test_each_set_of_runs_counts_once_and_only_plain_lbgp_variants_by_default(tmp_path):
    _scores(tmp_path / "a.json", {"LBGP": [160.0, 162.0, 164.0], "LBGP@nomirror": [1.0, 50.0, 99.0],
                                  "E2E": [100.0, 150.0, 200.0], "LBGP-x": [170.0, 170.0]})
    _scores(tmp_path / "b.json", {"LBGP": [161.0, 165.0, 166.0]})  # the same policy files scored again
    (tmp_path / "c.json").write_text(json.dumps({"something": "else"}))
    groups = variant_groups(sorted(tmp_path.glob("*.json")))
    assert sorted(groups) == ["a.json:LBGP", "a.json:LBGP-x"]
    assert groups["a.json:LBGP"]["sum"] == pytest.approx([160.0, 162.0, 164.0])
    assert groups["a.json:LBGP"]["turning"] == pytest.approx([160.0 * 4 / 9, 162.0 * 4 / 9, 164.0 * 4 / 9])
    assert sorted(variant_groups(sorted(tmp_path.glob("*.json")), ["E2E"])) == ["a.json:E2E"]

    out = tmp_path / "power.json"
    assert main(["--results", str(tmp_path), "--differences", "2,8", "--json", str(out)]) == 0
    result = json.loads(out.read_text())["quantities"]["sum"]
    assert result["df"] == 3 and result["pooled_sd"] == pytest.approx(math.sqrt(8.0 / 3), abs=1e-3)
    assert result["runs_per_variant"] == {"2": runs_needed(2.0, math.sqrt(8.0 / 3)), "8": runs_needed(8.0, math.sqrt(8.0 / 3))}


def test_bad_differences_and_an_empty_folder_are_refused(tmp_path, capsys):
    for bad in ("0", "two", "-1,2"):
        with pytest.raises(SystemExit) as exit_info:
            main(["--results", str(tmp_path), "--differences", bad])
        assert exit_info.value.code == 2 and "--differences" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_info:
        main(["--results", str(tmp_path)])
    assert exit_info.value.code == 2 and "no ablation_scenarios results" in capsys.readouterr().err
    (tmp_path / "broken.json").write_text('{"variants": ')  # a truncated file is named, not a traceback
    with pytest.raises(SystemExit) as exit_info:
        main(["--results", str(tmp_path)])
    assert exit_info.value.code == 2 and "broken.json is not readable JSON" in capsys.readouterr().err
