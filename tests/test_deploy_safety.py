"""Deploy safety: every way the process ends leaves the robot stopped, no datagram can crash or
freeze the loop, damaged logs read up to the damage, listeners stay on loopback, training folders
are locked. All traffic is on 127.0.0.1; every loop is bounded in count and time."""

import json
import logging
import signal
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lbgp.real import safety
from lbgp.real.frames import MAX_FRAME_BYTES, FrameError, PoseFrame, decode_command, decode_frame
from lbgp.real.loop import SHUTDOWN, DeployConfig, DeployLoop
from lbgp.real.mcap_log import LogError, read_log
from lbgp.real.replay import ReplayClock
from lbgp.real.throttle import ThrottledLog
from lbgp.real.udp import UdpCommandListener, UdpCommandSink, UdpPoseSource
from lbgp.rollout import ConstantGoalPolicy


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# ---------------------------------------------------------------- every exit path sends zero
class PoseStreamer(threading.Thread):
    """Pose frames at 50 Hz to a deploy process: a person walking +x at 0.5 m/s, the robot standing
    1 m ahead of where the goal will be, so that the planner drives it forward."""

    def __init__(self, port: int, seconds: float = 40.0):
        super().__init__(daemon=True)
        self.port, self.seconds = port, seconds
        self.stop = threading.Event()

    def run(self):
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        start = time.monotonic()
        while not self.stop.is_set() and time.monotonic() - start < self.seconds:
            t = time.monotonic() - start
            msg = {"t": t, "robot": [1.0, 0.0, 0.0], "person": [-2.0 + 0.5 * t, 0.0, 0.0]}
            sock.sendto(json.dumps(msg).encode(), ("127.0.0.1", self.port))
            time.sleep(0.02)
        sock.close()


def _ignore_sigint():
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # what `nohup lbgp deploy ... &` in a script hands down


@pytest.mark.parametrize("sig,code,reason,inherited_ignore", [
    (signal.SIGINT, 130, "interrupted", False), (signal.SIGTERM, 143, "signal SIGTERM", False),
    (signal.SIGHUP, 129, "signal SIGHUP", False), (signal.SIGINT, 130, "interrupted", True)])
def test_a_signal_stops_the_robot_and_writes_the_summary_and_a_closed_log(tmp_path, sig, code, reason, inherited_ignore):
    """Also when the deploy process inherited SIGINT ignored (a background job of a non-interactive
    shell): it hung until killed before deploy installed its own SIGINT handler."""
    pose_port = free_port()
    robot = UdpCommandListener(("127.0.0.1", 0), allowed_senders=("127.0.0.1",))
    summary, log = tmp_path / "summary.json", tmp_path / "run.mcap"
    streamer = PoseStreamer(pose_port)
    proc = subprocess.Popen(
        [sys.executable, "-m", "lbgp.cli", "deploy", "--method", "scripted", "--source", f"udp://127.0.0.1:{pose_port}",
         "--sink", f"udp://127.0.0.1:{robot.address[1]}", "--json", str(summary), "--log", str(log)],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, preexec_fn=_ignore_sigint if inherited_ignore else None)
    received = []
    try:
        streamer.start()
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline and not any(v > 0.05 for _, v, _, _ in received):
            received += robot.poll(timeout=0.1)
            assert proc.poll() is None, proc.stderr.read().decode()
        assert any(v > 0.05 for _, v, _, _ in received), "the robot was never driven"
        proc.send_signal(sig)
        proc.wait(timeout=30)
        end = time.monotonic() + 1.0
        while time.monotonic() < end:
            received += robot.poll(timeout=0.05)
    finally:
        streamer.stop.set()
        if proc.poll() is None:
            proc.kill()
            proc.wait(timeout=10)
        robot.close()
    assert proc.returncode == code
    _, v, w, status = received[-1]
    assert (v, w, status) == (0.0, 0.0, SHUTDOWN)
    result = json.loads(summary.read_text())
    assert result["end"] == reason and result["agent_steps"] > 0
    data = read_log(log)
    assert not data["truncated"] and len(data["/cmd_vel"]) > 5  # finished: the log was closed


def test_an_exception_in_the_loop_still_writes_the_summary(tmp_path, monkeypatch, capsys):
    from lbgp import cli

    class Boom(ConstantGoalPolicy):
        calls = 0

        def act(self, observation):
            Boom.calls += 1
            if Boom.calls == 3:
                raise RuntimeError("policy exploded")
            return super().act(observation)

    monkeypatch.setattr("lbgp.policies.make_policy", lambda *a, **k: Boom())
    out = tmp_path / "s.json"
    code = cli.main(["deploy", "--method", "scripted", "--source", "sim", "--steps", "20", "--json", str(out)])
    assert code == 1
    result = json.loads(out.read_text())
    assert result["end"] == "error" and "policy exploded" in result["error"]
    assert "policy exploded" in capsys.readouterr().err


# ---------------------------------------------------------------- no datagram crashes the source
def send_all(port, payloads):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        for p in payloads:
            s.sendto(p, ("127.0.0.1", port))


json_values = st.recursive(st.none() | st.booleans() | st.floats() | st.integers() | st.text(max_size=5),
                           lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4),
                           max_leaves=20)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(payloads=st.lists(st.binary(max_size=300) | json_values.map(lambda v: json.dumps(v).encode()), min_size=1, max_size=5))
def test_any_datagram_is_either_a_frame_or_counted_and_dropped(payloads):
    source = UdpPoseSource(("127.0.0.1", 0))
    try:
        send_all(source.address[1], payloads)
        frames, deadline = [], time.monotonic() + 2.0
        while time.monotonic() < deadline and len(frames) + source.malformed < len(payloads):
            frames += source.poll(0.0, timeout=0.05)
        assert len(frames) + source.malformed == len(payloads)
        assert all(isinstance(f, PoseFrame) for f in frames)
    finally:
        source.close()


def test_deep_nesting_and_oversize_datagrams_are_malformed_not_fatal():
    nested = b"[" * 5000 + b"]" * 5000  # ~10 kB: RecursionError in json, dropped by size first
    deep_small = b"[" * 1500 + b"]" * 1500  # 3 kB: within the size cap, too deep for the parser
    for data in (nested, deep_small, b'{"t": 1, "robot": [[[0]],0,0], "person": [0,0,0]}'):
        with pytest.raises(FrameError):
            decode_frame(data)
    with pytest.raises(FrameError):
        decode_command(deep_small)
    source = UdpPoseSource(("127.0.0.1", 0))
    try:
        good = json.dumps({"t": 1.0, "robot": [0, 0, 0], "person": [1, 0, 0]}).encode()
        send_all(source.address[1], [nested, deep_small, b"x" * (MAX_FRAME_BYTES + 1), good])
        frames, deadline = [], time.monotonic() + 2.0
        while time.monotonic() < deadline and not frames:
            frames += source.poll(0.0, timeout=0.05)
        assert len(frames) == 1 and source.malformed == 3
    finally:
        source.close()


# ---------------------------------------------------------------- timestamps: a bad stamp blocks for at most 1 s
class StampedPoses:
    """Good poses every tick, stamped by ``stamp(now)``; the robot stands 2 m ahead of the person."""

    def __init__(self, stamp):
        self.stamp = stamp

    def poll(self, now, timeout=0.0):
        return [PoseFrame(self.stamp(now), np.array([0.0, 0.0, 0.0]), np.array([-2.0, 0.0, 0.0]), now)]


class Recorder:
    def __init__(self):
        self.sent = []

    def send(self, t, v, w, status="ok"):
        self.sent.append((t, status))


@pytest.mark.parametrize("fault", ["future_stamp", "clock_reset"])
def test_a_bad_timestamp_blocks_good_data_for_at_most_the_reanchor_time(fault):
    def stamp(now):
        if fault == "future_stamp":
            return 1e12 if abs(now - 1.0) < 1e-6 else now  # one frame far in the future at t = 1 s
        return now if now < 1.0 - 1e-9 else now - 1.0  # the sender's clock restarts from 0 at t = 1 s

    sink = Recorder()
    loop = DeployLoop(StampedPoses(stamp), sink, ConstantGoalPolicy(), DeployConfig(max_duration=4.0), clock=ReplayClock())
    loop.run()
    reanchor = loop.cfg.safety.reanchor_after
    blocked = [t for t, status in sink.sent if status == safety.OUT_OF_ORDER]
    assert blocked, "the fault was not seen"
    assert max(blocked) - min(blocked) <= reanchor + 0.2
    assert all(status == "ok" for t, status in sink.sent if max(blocked) < t < 4.0 - 1e-9)  # driving again


class GappedPoses:
    """Good poses every tick except for ``gap`` (a mocap dropout); the robot stands 2 m ahead."""

    def __init__(self, gap):
        self.gap = gap

    def poll(self, now, timeout=0.0):
        if self.gap[0] <= now < self.gap[1]:
            return []
        return [PoseFrame(now, np.array([0.0, 0.0, 0.0]), np.array([-2.0, 0.0, 0.0]), now)]


class ResetCountingPolicy(ConstantGoalPolicy):
    """The goal ahead, counting ``reset`` calls and the ``act`` calls made since the last one."""

    def __init__(self):
        super().__init__()
        self.resets, self.acts_since_reset = [], 0

    def reset(self):
        self.resets.append(self.acts_since_reset)
        self.acts_since_reset = 0

    def act(self, observation):
        self.acts_since_reset += 1
        return super().act(observation)


@pytest.mark.parametrize("gap_s, resets", [(0.5, 1), (1.5, 2)])
def test_the_policy_is_reset_at_the_start_and_after_a_gap_longer_than_the_reanchor_time(gap_s, resets):
    """A stateful policy (``lbgp train --previous-goal`` remembers its last goal) starts afresh where
    the observation history does: at the first good frame and after a dropout over ``reanchor_after``."""
    policy = ResetCountingPolicy()
    loop = DeployLoop(GappedPoses((1.0, 1.0 + gap_s)), Recorder(), policy, DeployConfig(max_duration=4.0), clock=ReplayClock())
    assert (gap_s > loop.cfg.safety.reanchor_after) == (resets == 2)  # the two gaps lie either side of it
    loop.run()
    assert len(policy.resets) == resets
    assert policy.resets[0] == 0 and all(n >= 4 for n in policy.resets[1:])  # the second one after a second of acting
    assert policy.acts_since_reset >= 4


# ---------------------------------------------------------------- damaged logs
@pytest.fixture(scope="module")
def small_log(tmp_path_factory):
    from lbgp.real.deploy import deploy

    path = tmp_path_factory.mktemp("log") / "small.mcap"
    deploy(ConstantGoalPolicy(), source="sim", steps=2, log=path)
    return path.read_bytes()


def test_every_truncation_of_a_log_reads_a_prefix_or_gives_a_clear_error(small_log, tmp_path):
    """Every cut point of a small log (a few kB): read_log returns the readable prefix marked
    truncated, or raises LogError; nothing else."""
    path = tmp_path / "cut.mcap"
    outcomes = {"prefix": 0, "error": 0}
    for cut in range(len(small_log)):
        path.write_bytes(small_log[:cut])
        try:
            data = read_log(path)
        except LogError:
            outcomes["error"] += 1
        else:
            assert data["truncated"] or cut == len(small_log)
            outcomes["prefix"] += 1
    assert outcomes["prefix"] > 0 and outcomes["error"] > 0


def test_flipped_bytes_never_raise_anything_but_a_log_error(small_log, tmp_path):
    from lbgp.cli import main

    rng = np.random.default_rng(0)
    path = tmp_path / "flipped.mcap"
    for _ in range(300):
        data = bytearray(small_log)
        for at in rng.integers(0, len(data), size=int(rng.integers(1, 4))):
            data[at] ^= 1 << int(rng.integers(0, 8))
        path.write_bytes(bytes(data))
        try:
            read_log(path)
        except LogError:
            pass
    assert main(["replay", str(path)]) in (0, 2)


def test_a_full_disk_stops_logging_but_not_the_robot(tmp_path):
    from lbgp.real.mcap_log import McapLogger

    logger = McapLogger(tmp_path / "full.mcap", metadata={"robot": "turtlebot2"})

    sink = Recorder()
    loop = DeployLoop(StampedPoses(lambda now: now), sink, ConstantGoalPolicy(), DeployConfig(max_duration=1.0),
                      clock=ReplayClock(), logger=logger)
    for _ in range(3):
        loop.tick()

    def full_disk(*args, **kwargs):
        raise OSError(28, "No space left on device")

    logger._writer.write_message = full_disk  # every later write fails as on a full disk
    with pytest.warns(RuntimeWarning, match="logging stopped"):
        loop.run()
    assert logger.failed is not None
    assert sink.sent[-1][1] == SHUTDOWN and len(sink.sent) > 5


# ---------------------------------------------------------------- listeners and sockets stay on loopback
def test_the_command_sink_binds_loopback_and_only_talks_to_its_robot():
    robot = UdpCommandListener(("127.0.0.1", 0))
    sink = UdpCommandSink(("127.0.0.1", robot.address[1]))
    try:
        assert sink.sock.getsockname()[0] == "127.0.0.1"
        assert sink.sock.getpeername() == ("127.0.0.1", robot.address[1])
        sink.send(1.0, 0.2, 0.0)
        deadline, got = time.monotonic() + 2.0, []
        while time.monotonic() < deadline and not got:
            got = robot.poll(timeout=0.05)
        assert got[0][1] == 0.2
    finally:
        sink.close()
        robot.close()


def test_a_busy_port_or_foreign_address_is_a_clear_error():
    source = UdpPoseSource(("127.0.0.1", 0))
    try:
        with pytest.raises(ValueError, match="cannot listen on 127.0.0.1"):
            UdpPoseSource(source.address)
        with pytest.raises(ValueError, match="cannot listen on 203.0.113.7"):
            UdpPoseSource(("203.0.113.7", 0))  # TEST-NET-3: not an address of this machine
    finally:
        source.close()


def test_warnings_are_rate_limited_to_one_line_per_second():
    clock = [0.0]
    records = []

    class Capture(logging.Handler):
        def emit(self, record):
            records.append(record.getMessage())

    logger = logging.getLogger("lbgp.test.throttle")
    logger.addHandler(Capture())
    log = ThrottledLog(logger, period=1.0, clock=lambda: clock[0])
    for i in range(5000):  # a flood: 5,000 bad datagrams in 5 s
        clock[0] = i * 0.001
        log.warning("malformed", "dropped a malformed pose datagram")
    assert len(records) == 5
    assert "and 999 more" in records[1]


# ---------------------------------------------------------------- training folders
def test_a_second_training_on_a_folder_in_use_is_refused_and_changes_nothing(tmp_path, capsys):
    from lbgp.agent.train import RunLock
    from lbgp.cli import main

    run = tmp_path / "run"
    run.mkdir()
    holder = RunLock(run)  # as a running `lbgp train --out run` holds it from its first moment
    (run / "curve.csv").write_text("env_steps,wall_time_s,level,exploit_return\n1,0.1,straight,2.0\n")
    before = (run / "curve.csv").read_text()
    try:
        assert main(["train", "--out", str(run), "--steps", "10", "--backend", "inline"]) == 2
        assert "in use by another lbgp train" in capsys.readouterr().err
        assert (run / "curve.csv").read_text() == before and not (run / "config.json").exists()
    finally:
        holder.release()
    again = RunLock(run)  # released (or its process died): the folder can be locked again
    again.release()


def test_resume_removes_stale_temporary_files(tmp_path):
    from lbgp.agent.train import remove_stale_temporaries

    (tmp_path / ".checkpoint.pt.123.tmp").write_bytes(b"half")
    (tmp_path / "curve.csv.tmp").write_text("x")
    (tmp_path / "curve.csv").write_text("keep")
    removed = remove_stale_temporaries(tmp_path)
    assert sorted(p.name for p in removed) == [".checkpoint.pt.123.tmp", "curve.csv.tmp"]
    assert (tmp_path / "curve.csv").exists()


def test_a_failed_atomic_save_leaves_no_temporary_file(tmp_path, monkeypatch):
    import torch

    from lbgp.agent.checkpoint import save_atomic

    def full_disk(obj, f):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(torch, "save", full_disk)
    with pytest.raises(OSError):
        save_atomic({"a": 1}, tmp_path / "checkpoint.pt")
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- a deploy never waits silently
def test_deploy_says_what_it_waits_for_and_gives_up_after_the_first_pose_timeout(tmp_path):
    port = free_port()
    robot = UdpCommandListener(("127.0.0.1", 0))
    out = tmp_path / "s.json"
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "lbgp.cli", "deploy", "--method", "scripted", "--source", f"udp://127.0.0.1:{port}",
             "--sink", f"udp://127.0.0.1:{robot.address[1]}", "--first-pose-timeout", "2.5", "--json", str(out)],
            capture_output=True, text=True, timeout=60)
        received, deadline = [], time.monotonic() + 1.0
        while time.monotonic() < deadline:
            received += robot.poll(timeout=0.05)
    finally:
        robot.close()
    assert proc.returncode == 1
    assert f"listening for poses on udp://127.0.0.1:{port}" in proc.stderr
    assert proc.stderr.count("waiting for the first valid pose") >= 2  # once a second
    assert "no valid pose from" in proc.stderr and "Traceback" not in proc.stderr
    assert json.loads(out.read_text())["end"] == "no_pose"
    assert received and all(v == 0.0 and w == 0.0 for _, v, w, _ in received)  # held stopped throughout
