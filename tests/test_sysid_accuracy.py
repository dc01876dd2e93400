"""benchmarks/sysid_accuracy.py: its per-robot summary of the fits and its seed ranges."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from sysid_accuracy import parse_seeds, summarise  # noqa: E402


def fit(robot, lag, fitted_lag, linear_limit=None, fitted_linear=None, fitted_angular=2.0, latency=0.12):
    return {"robot": robot, "lag": lag, "linear_limit": linear_limit, "seed": 0, "lag_error": fitted_lag / lag - 1.0,
            "fit": {"time_constant_s": fitted_lag, "latency_s": latency, "max_linear_accel": fitted_linear,
                    "max_angular_accel": fitted_angular}}


def test_summary_counts_lags_within_ten_percent_and_limiters_found_missed_or_invented():
    fits = [fit("jackal", 0.1, 0.105), fit("jackal", 0.1, 0.12, linear_limit=2.0, fitted_linear=2.5, latency=0.14),
            fit("jackal", 0.2, 0.17, fitted_angular=None), fit("jackal", 0.2, 0.2, fitted_linear=9.0),
            fit("turtlebot2", 0.1, 0.1, linear_limit=0.5, fitted_linear=None)]
    s = summarise(fits)
    j = s["jackal"]
    assert j["fits"] == 4 and j["lag_within_10_percent"] == 2  # +5 %, 0 % in; +20 %, -15 % out
    assert j["lag_error_min"] == pytest.approx(-0.15) and j["lag_error_max"] == pytest.approx(0.2)
    assert j["latency_range_s"] == [0.12, 0.14]
    assert j["angular_limit_range"] == [2.0, 2.0] and j["angular_limit_missed"] == 1
    assert j["linear_limit_range"] == [2.5, 2.5] and j["linear_limit_missed"] == 0 and j["linear_limit_where_none"] == 1
    t = s["turtlebot2"]
    assert t["linear_limit_range"] is None and t["linear_limit_missed"] == 1


def test_seed_ranges():
    assert parse_seeds("0-5") == [0, 1, 2, 3, 4, 5] and parse_seeds("2,7") == [2, 7] and parse_seeds("3") == [3]
