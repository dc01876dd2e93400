"""System identification: fit a robot's ``Dynamics`` (latency, response time constant, acceleration
limits, gains) from a deploy log's commands and motion-capture poses.

    lbgp sysid --excite --robot turtlebot2 --log excite.mcap     # record (sim, or your robot via udp://)
    lbgp sysid excite.mcap --robot turtlebot2 --out dynamics.json [--png fit.png]

The model is the simulator's own drive train (``lbgp.drive_train.DriveTrain``: command latency, the
firmware's acceleration limiter, a first-order lag), then the simulated base's response to its wheel
setpoints (``SIM_BASE_RESPONSE``: its body runs ahead of a smooth setpoint), then gains on v and w
(what the wheels and the floor make of the setpoint: servo gain, skid-steer slip). So the fitted
parameters are the ones that make the simulator reproduce the log. The measured body velocity comes
from the logged robot poses (every mocap frame the loop accepted, ``/mocap/robot``; interpolated to
a uniform grid, Savitzky-Golay derivative), and the model's velocity goes through the very same
differentiator (``as_measured``). The acceleration limiters are fitted as their inverse, the ramp
time per unit of command (0: none), so that "no limiter" is a point of the search. The latency is
searched on a grid up to 0.3 s: every 30 ms with the other parameters at their start values, then
every 10 ms within 60 ms of the best; for each of those, scipy's ``least_squares`` fits the other
five parameters; from the best, all six are refined together with the latency continuous.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from lbgp.actions import MAX_V, MAX_W
from lbgp.conventions import AGENT_PERIOD
from lbgp.dynamics import Dynamics, nominal
from lbgp.drive_train import simulate_setpoints

MIN_DURATION = 5.0  # s of overlapping commands and poses a fit needs
MIN_POSES = 40
LATENCY_GRID = np.arange(0.0, 0.301, 0.01)  # s
VELOCITY_GRID = 0.02  # s, the uniform grid the measured velocity is computed on
MODEL_DT = 0.01  # s, the drive-train simulation step of the fit


@dataclasses.dataclass
class SysidResult:
    dynamics: Dynamics
    latency: float
    time_constant: float
    max_linear_accel: float
    max_angular_accel: float
    gain_v: float  # achieved / commanded forward speed in steady state
    gain_w: float  # achieved / commanded yaw rate
    rms_v: float  # m/s, residual of the fit
    rms_w: float  # rad/s
    duration: float  # s of data used
    samples: int
    series: dict  # t, measured and simulated v and w (for the plot)
    pose_topic: str = "/robot/pose"  # where the poses came from (``pose_topic``)
    poses: int = 0  # how many

    def summary(self) -> dict:
        return {
            "latency_s": round(self.latency, 4), "time_constant_s": round(self.time_constant, 4),
            # None: not limiting (passes the log's largest change within a model step; JSON has no infinity)
            "max_linear_accel": _rounded_or_none(self.max_linear_accel, 3), "max_angular_accel": _rounded_or_none(self.max_angular_accel, 3),
            "gain_v": round(self.gain_v, 3), "gain_w": round(self.gain_w, 3),
            "rms_v": round(self.rms_v, 4), "rms_w": round(self.rms_w, 4),
            "duration_s": round(self.duration, 2), "samples": self.samples,
        }


def _rounded_or_none(value: float, digits: int):
    return None if math.isinf(value) else round(value, digits)


def pose_topic(log: dict) -> str:
    """Where ``log_series`` takes the robot's poses from: ``/mocap/robot``, every mocap frame the loop
    accepted, when the log has them on a source clock that never went back; else ``/robot/pose``,
    one pose per tick (logs written before those topics, or a source clock that restarted mid-log)."""
    from lbgp.real.mcap_log import stamp_of

    frames = log.get("/mocap/robot", [])
    stamps = np.array([stamp_of(m) for _, m in frames], float)
    return "/mocap/robot" if len(frames) >= MIN_POSES and np.all(np.diff(stamps) > 0) else "/robot/pose"


def log_series(log: dict, topic: str | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(command times, commands (v, w), pose times, robot poses (x, y, yaw)) from ``read_log``'s dict.

    The poses come from ``topic`` (default: ``pose_topic(log)``). Mocap frames keep the source's own spacing, put on the log's
    clock by the smallest delay seen (the freshest frame a tick read)."""
    from lbgp.real.mcap_log import pose_of, stamp_of

    cmds = log.get("/cmd_vel", [])
    t_cmd = np.array([t for t, _ in cmds], float)
    u = np.array([[m.linear.x, m.angular.z] for _, m in cmds], float).reshape(-1, 2)
    topic = topic or pose_topic(log)
    poses = log.get(topic, [])
    t_pose = np.array([t for t, _ in poses], float)
    if topic == "/mocap/robot":
        stamps = np.array([stamp_of(m) for _, m in poses], float)
        t_pose = stamps + np.min(t_pose - stamps)
    p = np.array([pose_of(m) for _, m in poses], float).reshape(-1, 3)
    return t_cmd, u, t_pose, p


def _rate(t: np.ndarray, values: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """d/dt of samples ``values`` at times ``t``: linearly interpolated onto the uniform ``grid``,
    then a Savitzky-Golay derivative over ~0.2 s. The one differentiator of the measurement and of
    the model (which is put through it too, so that both see the same smoothing and phase)."""
    from scipy.signal import savgol_filter

    dt = float(grid[1] - grid[0])
    window = max(5, int(round(0.2 / dt)) | 1)  # ~0.2 s, odd
    return savgol_filter(np.interp(grid, t, values), window, 2, deriv=1, delta=dt)


def _unique_times(t_pose: np.ndarray, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(t_pose)
    t, p = t_pose[order], poses[order]
    keep = np.concatenate([[True], np.diff(t) > 1e-6])
    return t[keep], p[keep]


def measured_velocity(t_pose: np.ndarray, poses: np.ndarray, dt: float = VELOCITY_GRID) -> tuple[np.ndarray, np.ndarray]:
    """(grid times, (v, w) per time): body velocity from poses, on a uniform grid."""
    t, p = _unique_times(t_pose, poses)
    grid = np.arange(t[0], t[-1], dt)
    yaw = np.unwrap(p[:, 2])
    dx, dy, dyaw = (_rate(t, c, grid) for c in (p[:, 0], p[:, 1], yaw))
    yw = np.interp(grid, t, yaw)
    v = dx * np.cos(yw) + dy * np.sin(yw)
    return grid, np.stack([v, dyaw], axis=1)


def as_measured(t_model: np.ndarray, velocity: np.ndarray, t_pose: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """What ``measured_velocity`` makes of a body moving with ``velocity`` ((v, w) held over each
    step of the uniform ``t_model``): distance travelled and heading, sampled at the log's pose
    times, then the same differentiator. (Interpolating and smoothing the poses spreads a velocity
    step over ~0.2-0.3 s, centred, so a model compared with the raw measurement would have to lead it.)"""
    dt = float(t_model[1] - t_model[0])
    travelled = np.concatenate([np.zeros((1, 2)), np.cumsum(velocity * dt, axis=0)])  # at t_model[0] + k dt
    t_edges = t_model[0] - dt + dt * np.arange(len(travelled))  # velocity[i] acts over (t_model[i] - dt, t_model[i]]
    return np.stack([_rate(t_pose, np.interp(t_pose, t_edges, travelled[:, i]), grid) for i in (0, 1)], axis=1)


# The simulated bases do not follow a smooth wheel setpoint exactly: the body's velocity runs ahead
# of it (docs/simulation.md), like a lead-lag (1 + lead s) / (1 + lag s) per channel (v, w).
# Measured by ``measure_base_response`` (seconds; tests/test_sysid.py re-measures them).
SIM_BASE_RESPONSE: dict[str, tuple[tuple[float, float], tuple[float, float]]] = {
    "turtlebot2": ((0.137, 0.020), (0.155, 0.031)),
    "jackal": ((0.100, 0.061), (0.100, 0.052)),
}


def lead_lag(signal: np.ndarray, lead: float, lag: float, dt: float) -> np.ndarray:
    """(1 + lead s) / (1 + lag s) applied to a signal sampled every ``dt`` (bilinear transform), from rest."""
    from scipy.signal import lfilter

    a = 2.0 / dt
    a0 = 1.0 + lag * a
    return lfilter([(1.0 + lead * a) / a0, (1.0 - lead * a) / a0], [1.0, (1.0 - lag * a) / a0], signal, axis=0)


def base_response(setpoints: np.ndarray, robot: str, dt: float) -> np.ndarray:
    """The simulated base's body velocity for wheel setpoints (v, w) sampled every ``dt``, before its gains."""
    (lead_v, lag_v), (lead_w, lag_w) = SIM_BASE_RESPONSE[robot]
    return np.stack([lead_lag(setpoints[:, 0], lead_v, lag_v, dt), lead_lag(setpoints[:, 1], lead_w, lag_w, dt)], axis=1)


def measure_base_response(robot: str, time_constants=(0.05, 0.12, 0.2), seed: int = 0) -> tuple[tuple[float, float], ...]:
    """Re-measure ``SIM_BASE_RESPONSE`` for a robot: play the excitation (``excitation_schedule``,
    ramped like the deploy loop's acceleration clamp, one command per 0.1 s tick) to the simulated
    base with nominal dynamics but for a lag of each of ``time_constants``, record the wheel
    setpoints and the true body velocity every physics step, and fit a gain times a lead-lag per
    channel by least squares. Returns ((lead_v, lag_v), (lead_w, lag_w)) in seconds."""
    from scipy.optimize import least_squares

    from lbgp.planner import clamp_command
    from lbgp.real.sim_world import SimWorld
    from lbgp.stack import planner_limits

    limits = planner_limits(robot)  # the deploy loop's: its tick as the control period
    ticks_per_step = int(round(AGENT_PERIOD / limits.control_period))  # the schedule holds each command one agent step
    schedule = np.repeat(excitation_schedule(limits.max_vel_x, limits.max_vel_theta), ticks_per_step, axis=0)
    runs = []
    for tau in time_constants:
        world = SimWorld("standing_person", robot=robot, seed=seed, dynamics=nominal(robot).replace(time_constant=tau))
        physics = world.physics
        command, rows = (0.0, 0.0), []
        for target in schedule:
            command = clamp_command(*target, *command, limits)
            world.set_command(*command)
            for _ in range(int(round(limits.control_period / physics.timestep()))):
                physics.step_physics(1)
                rows.append((*physics.drivetrain.output, *physics.robot_velocity()))
        runs.append(np.array(rows))
    dt = float(physics.timestep())
    out = []
    for i in (0, 1):
        def residual(theta):
            gain, lead, lag = theta
            return np.concatenate([gain * lead_lag(r[:, i], lead, lag, dt) - r[:, 2 + i] for r in runs])

        sol = least_squares(residual, [1.0, 0.05, 0.01], bounds=([0.3, 0.0, 0.001], [2.0, 0.5, 0.5]))
        out.append((round(float(sol.x[1]), 3), round(float(sol.x[2]), 3)))
    return tuple(out)


def _check_log(t_cmd, u, t_pose, p) -> None:
    if len(t_cmd) < 10 or len(t_pose) < MIN_POSES:
        raise ValueError(f"log too short for system identification: {len(t_cmd)} commands and {len(t_pose)} robot poses "
                         f"(need >= 10 and >= {MIN_POSES}); record one with `lbgp sysid --excite`")
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(p))):
        raise ValueError("log holds non-finite commands or poses")
    overlap = min(t_cmd[-1], t_pose[-1]) - max(t_cmd[0], t_pose[0])
    if overlap < MIN_DURATION:
        raise ValueError(f"log too short for system identification: {overlap:.1f} s of commands and poses together "
                         f"(need >= {MIN_DURATION:.0f} s)")
    if np.ptp(u[:, 0]) < 0.05 and np.ptp(u[:, 1]) < 0.1:
        raise ValueError("the log's commands hardly change: nothing to identify (record an excitation with `lbgp sysid --excite`)")


def fit(log: dict, robot: str) -> SysidResult:
    """Fit the drive-train parameters to a log (``read_log``'s dict)."""
    from scipy.optimize import least_squares

    topic = pose_topic(log)
    t_cmd, u, t_pose, p = log_series(log, topic)
    _check_log(t_cmd, u, t_pose, p)
    t_pose, p = _unique_times(t_pose, p)
    grid, measured = measured_velocity(t_pose, p)
    t_model = np.arange(grid[0], grid[-1] + MODEL_DT, MODEL_DT)
    inside = (grid >= t_cmd[0] + 0.3) & (grid <= t_cmd[-1]) & (grid >= t_pose[0] + 0.3) & (grid <= t_pose[-1] - 0.3)  # filter edges
    scale = np.array([max(np.std(measured[inside, 0]), 0.02), max(np.std(measured[inside, 1]), 0.05)])
    base = nominal(robot)

    # the limiters are fitted as their inverse, the ramp time per unit of command (s per m/s, s per
    # rad/s): 0 is no limiter, and the fit moves continuously from a step to a ramp. (A limiter just
    # above the commands' rate of change still turns each tick's step into a ramp as long as the tick,
    # like a delay of half a tick; as a bound at that rate it pulled the lag and latency short.)
    def model(theta, latency):
        tau, r_v, r_w, k_v, k_w = theta
        dyn = base.replace(latency=latency, time_constant=tau, max_linear_accel=_limit(r_v), max_angular_accel=_limit(r_w),
                           latency_jitter=0.0)
        velocity = base_response(simulate_setpoints(dyn, t_cmd, u, t_model, MODEL_DT), robot, MODEL_DT) * np.array([k_v, k_w])
        return as_measured(t_model, velocity, t_pose, grid)[inside]

    measured_inside = measured[inside]

    def residual(theta, latency):
        return ((model(theta, latency) - measured_inside) / scale).ravel()

    # the largest command change between two commands: a limiter that ramps it within one model
    # step acts as none (reported as not limiting)
    steps = np.maximum(np.max(np.abs(np.diff(u, axis=0)), axis=0), [0.01, 0.02])
    lo = np.array([0.0, 0.0, 0.0, 0.3, 0.3])
    hi = np.array([1.0, 1.0 / 0.05, 1.0 / 0.1, 2.0, 2.0])
    start = np.array([0.05, 0.02 / steps[0], 0.02 / steps[1], 1.0, 1.0])  # a 20 ms ramp on the largest change
    ramp_scale = 0.05 / steps
    x_scale = np.array([0.05, ramp_scale[0], ramp_scale[1], 0.2, 0.2])
    best = None
    coarse = [(float(np.sum(residual(start, lat) ** 2)), float(lat)) for lat in LATENCY_GRID[::3]]
    centre = min(coarse)[1]
    candidates = LATENCY_GRID[np.abs(LATENCY_GRID - centre) <= 0.061]
    for latency in candidates:
        sol = least_squares(residual, start, bounds=(lo, hi), args=(float(latency),), x_scale=x_scale, max_nfev=60)
        if best is None or sol.cost < best[0].cost:
            best = (sol, float(latency))
    sol, latency = best

    # then latency continuous too (between two model steps: the two neighbouring runs interpolated),
    # so that a latency between grid points (the mocap's own is 10-30 ms) is not pushed into the lag
    def model_at(latency, theta):
        k = math.floor(latency / MODEL_DT + 1e-9)
        frac = latency / MODEL_DT - k
        low = model(theta, k * MODEL_DT)
        return low if frac < 1e-9 else (1.0 - frac) * low + frac * model(theta, (k + 1) * MODEL_DT)

    def residual_all(theta):
        return ((model_at(float(theta[0]), theta[1:]) - measured_inside) / scale).ravel()

    refined = least_squares(residual_all, np.concatenate([[latency], sol.x]), bounds=(np.concatenate([[0.0], lo]), np.concatenate([[LATENCY_GRID[-1]], hi])),
                            x_scale=np.concatenate([[0.01], x_scale]), max_nfev=40)
    if refined.cost <= sol.cost:
        latency, theta = float(refined.x[0]), refined.x[1:]
    else:
        theta = sol.x
    tau, r_v, r_w, k_v, k_w = (float(x) for x in theta)
    simulated = model_at(latency, theta)
    # not limiting: the log's largest change passes within one model step
    a_v, a_w = (math.inf if r * step <= MODEL_DT else _limit(r) for r, step in ((r_v, steps[0]), (r_w, steps[1])))
    err = simulated - measured_inside
    dynamics = base.replace(latency=latency, time_constant=tau, max_linear_accel=a_v, max_angular_accel=a_w,
                            track_scale=float(np.clip(base.track_scale * k_w / k_v, 0.05, 20.0)))
    return SysidResult(
        dynamics, latency, tau, a_v, a_w, k_v, k_w,
        float(np.sqrt(np.mean(err[:, 0] ** 2))), float(np.sqrt(np.mean(err[:, 1] ** 2))),
        float(grid[inside][-1] - grid[inside][0]), int(np.sum(inside)),
        {"t": grid[inside], "measured": measured_inside, "simulated": simulated}, topic, len(t_pose),
    )


def _limit(ramp_time: float) -> float:
    """An acceleration limit from its inverse (s per unit of command; 0: no limiter)."""
    return math.inf if ramp_time <= 1e-9 else 1.0 / ramp_time


def identify(log_path, robot: str) -> SysidResult:
    from lbgp.real.mcap_log import read_log

    log = read_log(log_path)
    try:
        return fit(log, robot)
    except ValueError as exc:
        raise ValueError(f"{log_path}: {exc}") from None


def plot_fit(result: SysidResult, path) -> None:
    """PNG: measured vs simulated v and w over time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from lbgp.files import atomic_file

    s = result.series
    fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
    for ax, i, label in ((axes[0], 0, "v (m/s)"), (axes[1], 1, "w (rad/s)")):
        ax.plot(s["t"], s["measured"][:, i], lw=1, label="measured (mocap)")
        ax.plot(s["t"], s["simulated"][:, i], lw=1, label="fitted model")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right")
    axes[1].set_xlabel("time (s)")
    r = {k: ("not limiting" if v is None else v) for k, v in result.summary().items()}
    fig.suptitle(f"latency {r['latency_s']} s, tau {r['time_constant_s']} s, accel {r['max_linear_accel']} m/s^2 / "
                 f"{r['max_angular_accel']} rad/s^2, rms {r['rms_v']} m/s / {r['rms_w']} rad/s", fontsize=9)
    fig.tight_layout()
    with atomic_file(path, "wb") as f:
        fig.savefig(f, format="png", dpi=100)
    plt.close(fig)


# --------------------------------------------------------------------------- excitation
def excitation_schedule(max_v: float, max_w: float, period: float = 0.2) -> np.ndarray:
    """(v, w) per agent step: holds, steps and a chirp within 60 % of the limits, mostly turning in
    place so that the robot stays within ~2 m of where it started. About 40 s."""
    v, w = 0.6 * max_v, 0.6 * max_w
    seq: list[tuple[float, float]] = []

    def hold(cmd, seconds):
        seq.extend([cmd] * int(round(seconds / period)))

    hold((0.0, 0.0), 1.0)
    for sign in (1, -1):
        hold((0.0, sign * w), 2.0)
        hold((0.0, 0.0), 1.5)
        hold((0.0, sign * 0.5 * w), 1.6)
        hold((0.0, 0.0), 1.5)
    for fraction in (1.0, 0.5):
        hold((fraction * v, 0.0), 1.6)
        hold((0.0, 0.0), 1.5)
        hold((0.0, w), 1.0 * math.pi / w)  # turn around ...
        hold((0.0, 0.0), 1.0)
    hold((0.5 * v, 0.5 * w), 2.0)
    hold((0.0, 0.0), 1.5)
    chirp_t = np.arange(0.0, 8.0, period)
    freq = 0.1 + (1.2 - 0.1) * chirp_t / 8.0  # Hz, up to below the 2.5 Hz agent-step Nyquist limit
    phase = 2 * np.pi * np.cumsum(freq) * period
    seq.extend((0.0, 0.5 * w * math.sin(ph)) for ph in phase)
    hold((0.0, 0.0), 1.5)
    return np.array(seq, float)


class ExcitationPolicy:
    """Plays ``excitation_schedule`` as E2E-style velocity actions (the deploy loop's safety checks,
    acceleration clamp and logging stay on), then zero."""

    control = "velocity"

    def __init__(self, max_v: float, max_w: float):
        self.schedule = excitation_schedule(max_v, max_w)
        self.k = 0

    def reset(self) -> None:
        self.k = 0

    def act(self, observation) -> np.ndarray:
        v, w = self.schedule[self.k] if self.k < len(self.schedule) else (0.0, 0.0)
        self.k += 1
        return np.array([v / MAX_V, w / MAX_W], np.float32)

    @property
    def steps(self) -> int:
        return len(self.schedule) + 5


def record_excitation(robot: str, log, source: str | None = None, sink: str | None = None, dynamics=None, seed: int = 0,
                      on_open=None):
    """Drive the excitation through the deploy loop (safety checks on) and log it to ``log``; the
    default source is the simulator with a person standing 6 m away (mocap noise, latency and
    dropped frames on). Returns the finished loop."""
    from lbgp.planner import planner_config_for
    from lbgp.real.deploy import deploy
    from lbgp.real.sim_world import MocapDisturbance

    limits = planner_config_for(robot)
    policy = ExcitationPolicy(limits.max_vel_x, limits.max_vel_theta)
    source = source or "sim://standing_person"  # lbgp.sim.tasks.TOOL_SETTINGS
    return deploy(policy, source=source, sink=sink, robot=robot, steps=policy.steps, log=log, seed=seed,
                  disturbance=MocapDisturbance() if source.startswith("sim") else None, dynamics=dynamics,
                  metadata={"method": "sysid-excitation"}, on_open=on_open)
