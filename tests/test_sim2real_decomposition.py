"""benchmarks/sim2real_decomposition.py: the hardware-like loss by parameter group (a tiny real run)."""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from sim2real_decomposition import groups, main  # noqa: E402

from lbgp.dynamics import HARDWARE_LIKE  # noqa: E402


def test_each_group_changes_only_its_own_parameters():
    hw, parts = HARDWARE_LIKE["jackal"], groups("jackal")
    assert parts["latency"].latency == hw.latency and parts["latency"].time_constant != hw.time_constant
    assert parts["track"].track_scale == hw.track_scale and parts["track"].latency != hw.latency


def test_decomposition_runs_end_to_end_on_one_scenario(tmp_path):
    out = tmp_path / "d.json"
    result = main(["--episodes", "1", "--scenarios", "turning_ahead", "--methods", "hc", "--json", str(out)])
    assert json.loads(out.read_text()) == result
    reward, loss = result["methods"]["hc"]["reward"], result["methods"]["hc"]["loss_vs_nominal"]
    expected = {"nominal", "hardware_like", "hardware_like_calibrated", *(f"only_{g}" for g in groups("jackal"))}
    assert set(reward) == set(loss) == expected
    assert loss["nominal"] == 0.0 and loss["hardware_like"] == round(reward["nominal"] - reward["hardware_like"], 2)
    assert reward["hardware_like"] != reward["nominal"]  # the hardware-like dynamics are applied
    assert result["calibration"]["scale_w"] > 1.0  # the hardware-like Jackal turns less than it is told
