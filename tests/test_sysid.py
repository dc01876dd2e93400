"""System identification from deploy logs recorded in the simulator with known, non-default dynamics
(mocap noise, latency and dropped frames on), and clear errors for logs it cannot use."""

import math

import pytest

from lbgp.calibration import SIM_REFERENCE_GAINS
from lbgp.cli import main
from lbgp.dynamics import Dynamics, load_dynamics
from lbgp.real.mcap_log import LogError
from lbgp.real.sysid import identify, record_excitation

KNOWN = Dynamics(latency=0.12, time_constant=0.05, max_linear_accel=0.45, max_angular_accel=1.6)


@pytest.fixture(scope="module")
def excitation_log(tmp_path_factory):
    path = tmp_path_factory.mktemp("sysid") / "excite.mcap"
    loop = record_excitation("turtlebot2", path, dynamics=KNOWN, seed=2)
    assert loop.error is None and loop.end_reason == "steps"
    return path


def test_fit_recovers_known_latency_and_acceleration_limits(excitation_log):
    r = identify(excitation_log, "turtlebot2")
    assert abs(r.latency - KNOWN.latency) <= 0.1  # within one control tick
    assert r.max_linear_accel == pytest.approx(KNOWN.max_linear_accel, rel=0.1)
    assert r.max_angular_accel == pytest.approx(KNOWN.max_angular_accel, rel=0.1)
    assert r.gain_v == pytest.approx(1.0, rel=0.1) and r.gain_w == pytest.approx(1.0, rel=0.1)
    assert r.rms_v < 0.05 and r.rms_w < 0.15


def test_nominal_robot_fits_without_acceleration_limits(tmp_path):
    path = tmp_path / "nominal.mcap"
    record_excitation("turtlebot2", path, seed=1)
    r = identify(path, "turtlebot2")
    assert math.isinf(r.max_linear_accel) or r.max_linear_accel > 0.9  # the loop's own clamp is 1 m/s^2
    assert r.latency <= 0.1
    # the command calibration's reference: what sysid makes of the simulated robot
    assert (r.gain_v, r.gain_w) == pytest.approx(SIM_REFERENCE_GAINS["turtlebot2"], rel=0.03)


def test_calibration_reference_gains_of_the_simulated_jackal(tmp_path):
    path = tmp_path / "jackal.mcap"
    record_excitation("jackal", path, seed=1)
    r = identify(path, "jackal")
    assert (r.gain_v, r.gain_w) == pytest.approx(SIM_REFERENCE_GAINS["jackal"], rel=0.03)


def test_cli_writes_dynamics_that_load_and_a_plot(excitation_log, tmp_path, capsys):
    out, png = tmp_path / "dyn.json", tmp_path / "fit.png"
    assert main(["sysid", str(excitation_log), "--robot", "turtlebot2", "--out", str(out), "--png", str(png)]) == 0
    fitted = load_dynamics(out, "turtlebot2")
    assert fitted.max_linear_accel == pytest.approx(KNOWN.max_linear_accel, rel=0.1)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "rms_v" in capsys.readouterr().out


def test_corrupt_and_short_logs_give_clear_errors(excitation_log, tmp_path):
    corrupt = tmp_path / "corrupt.mcap"
    corrupt.write_bytes(b"not an mcap file at all" * 10)
    with pytest.raises((LogError, ValueError)):
        identify(corrupt, "turtlebot2")
    short = tmp_path / "short.mcap"
    data = excitation_log.read_bytes()
    from lbgp.real.mcap_log import read_log

    full = read_log(excitation_log)
    assert len(full["/cmd_vel"]) > 100
    from lbgp.real.sysid import fit

    cut = {topic: msgs[:30] if isinstance(msgs, list) else msgs for topic, msgs in full.items()}
    with pytest.raises(ValueError, match="too short"):
        fit(cut, "turtlebot2")
    short.write_bytes(data[: len(data) // 50])
    with pytest.raises(ValueError):
        identify(short, "turtlebot2")
    assert main(["sysid", str(corrupt), "--robot", "turtlebot2"]) == 2
