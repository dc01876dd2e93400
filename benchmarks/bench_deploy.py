"""Deployment latency on loopback: from a pose datagram being sent to the command datagram arriving.

    python benchmarks/bench_deploy.py --json results/bench_deploy.json

A pose frame (person walking, robot driven by the commands it gets) is sent over UDP on 127.0.0.1
to the loop's ``UdpPoseSource``; the loop ticks at once (safety checks, observation, policy on
agent steps, TEB planner, clamp) and its ``UdpCommandSink`` sends the command to a listener. The
time from ``sendto`` of the pose to the command's arrival is recorded for every tick (both UDP
hops and all the loop's work), per method, with the planner's anytime budget of ``lbgp deploy``
(2 ms of SQP per call) and without it (fixed iteration counts, as in simulation). Target (issue):
p99 <= 5 ms.
"""

from __future__ import annotations

import argparse
import select
import socket
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.geometry import integrate_unicycle  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.real.frames import PoseFrame, encode_frame  # noqa: E402
from lbgp.real.loop import DEPLOY_DEFAULT_BUDGET, DeployConfig, DeployLoop  # noqa: E402
from lbgp.real.replay import ReplayClock  # noqa: E402
from lbgp.real.udp import UdpCommandListener, UdpCommandSink, UdpPoseSource  # noqa: E402


def bench(method: str, ticks: int, budget: float | None = None) -> dict:
    clock = ReplayClock()
    source, listener = UdpPoseSource(), UdpCommandListener()
    sink = UdpCommandSink(listener.address)
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    loop = DeployLoop(source, sink, make_policy(method), DeployConfig(robot="turtlebot2", planner_time_budget=budget), clock=clock, keep_records=False)
    robot, person = np.array([1.5, 0.0, 0.0]), np.zeros(3)
    latencies, compute = [], []
    try:
        for k in range(ticks):
            t = 0.1 * k
            clock.sleep_until(t)
            t0 = time.perf_counter()
            sender.sendto(encode_frame(PoseFrame(t, robot, person)), source.address)
            select.select([source.sock], [], [], 1.0)  # the loop would be waiting on its socket
            c0 = time.perf_counter()
            loop.tick()
            compute.append(time.perf_counter() - c0)
            (_, v, w, _), = listener.poll(timeout=1.0)
            latencies.append(time.perf_counter() - t0)
            robot = integrate_unicycle(robot, v, w, 0.1)
            person = person + np.array([0.05, 0.0, 0.0])
    finally:
        for s in (source, listener, sink, sender):
            s.close()
    ms = np.array(latencies) * 1e3
    cms = np.array(compute) * 1e3
    return {"method": method, "ticks": ticks, "median_ms": float(np.median(ms)), "p99_ms": float(np.percentile(ms, 99)),
            "max_ms": float(ms.max()), "loop_tick_median_ms": float(np.median(cms)), "loop_tick_p99_ms": float(np.percentile(cms, 99)),
            "meets_p99_5ms": bool(np.percentile(ms, 99) <= 5.0)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", default="results/bench_deploy.json")
    parser.add_argument("--ticks", type=int, default=1000)
    args = parser.parse_args()
    results = []
    for budget in (DEPLOY_DEFAULT_BUDGET, None):
        for method in ("scripted", "lbgp", "hc", "e2e"):
            results.append({"planner_time_budget_ms": None if budget is None else budget * 1e3, **bench(method, args.ticks, budget)})
    write_result(args.json, {"benchmark": "deploy_latency_loopback", "robot": "turtlebot2", "results": results})


if __name__ == "__main__":
    main()
