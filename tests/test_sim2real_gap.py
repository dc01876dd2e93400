"""benchmarks/sim2real_gap.py: the columns' sums, their intervals and the shares kept."""

import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from sim2real_gap import COLUMNS, carried_over, totals  # noqa: E402


def test_totals_sum_rows_combine_intervals_in_quadrature_and_give_the_share_kept():
    rows = {"a": 10.0, "b": 6.0}
    part = {c: dict(rows) for c in COLUMNS}
    part["hardware_like"] = {"a": 8.0, "b": 4.0}
    part["hardware_like_online"] = {"a": 7.0, "b": 5.0}
    part["hardware_like_model"] = {"a": 10.0, "b": 10.0}
    part["hardware_like_model_only"] = {"a": 10.0, "b": 2.0}
    half = {c: {"a": 3.0, "b": 4.0} for c in COLUMNS}
    out = totals(part, half)
    assert out["nominal"] == 16.0 and out["hardware_like"] == 12.0
    assert out["ci95"]["nominal"] == 5.0  # sqrt(3^2 + 4^2)
    assert out["kept"] == 0.75 and out["kept_calibrated"] == 1.0 and out["kept_online"] == 0.75 and out["kept_model"] == 1.25
    assert out["kept_model_only"] == 0.75
    assert out["kept_ci95"] == pytest.approx(0.75 * math.hypot(5 / 12, 5 / 16), abs=1e-3)


def test_a_share_of_a_nonpositive_nominal_sum_is_not_given():
    part = {c: {"a": -1.0} for c in COLUMNS}
    out = totals(part, {c: {"a": 0.5} for c in COLUMNS})
    assert out["kept"] is None and out["kept_ci95"] is None


def test_update_keeps_the_methods_not_rerun_with_the_command_that_made_them():
    earlier = {"command": "old", "methods": {"lbgp": {"scenarios": 1}, "e2e_randomized": {"scenarios": 2},
                                             "hc": {"command": "older", "scenarios": 3}}}
    kept = carried_over(earlier, {"lbgp": None})
    assert kept == {"e2e_randomized": {"scenarios": 2, "command": "old"}, "hc": {"command": "older", "scenarios": 3}}
