"""Online command calibration: learn while driving how much the robot turns (and drives) per command.

``lbgp.calibration.CommandCalibration`` scales commands by gains identified offline (``lbgp sysid``).
``OnlineCalibration`` needs no identification run: at every controller tick it compares the motion
the robot made since the previous tick (from the measured poses: mocap on the real robot, the
physics in the simulator) with the command it was sent then, estimates the base's gains
(achieved / sent, least squares through the origin over the last ``window`` seconds), and scales the
next commands by the reference gain over the estimated one, the way the offline calibration does.

Only steady samples count: the same command sent for the last ``LAGS`` ticks (0.5 s) and the
measured motion no longer changing (by at most ``steady_tolerance`` of the base's rated top speed
over ``SETTLE_SAMPLES`` samples), so that latency, motor lag and a firmware acceleration limiter
have played out: a base that is slow to reach a speed is not mistaken for one that never reaches
it, which a scale cannot fix. Commands beyond ``linear_share`` of the base's rated top speeds (v:
all of it; w: 60 %) are not used either: there a base may saturate (the TurtleBot 2 turning on the
spot at 2.5 rad/s does 0.6 of it), which is a limit, not a gain.

Guards, so that a robot that already answers like the simulated one is left alone:
* a gain is estimated only after enough excitation (the steady commands' mean square over the window;
  driving straight says nothing about the yaw gain), and holds its last value otherwise;
* a dead band: corrections within ``deadband`` (relative) of 1 are not made, larger ones are shrunk
  by it (continuously: the correction is exp(sign(l) max(|l| - log(1 + deadband), 0)), l = log(ref / gain));
* corrections are bounded to ``lbgp.calibration.MAX_CORRECTION`` either way, and change by at most
  ``max_rate`` (in log) per second;
* an estimate below ``MIN_GAIN`` is ignored (a robot held or pushing against something);
* a sample is used only when exactly one command was sent between its two poses (a missed or stale
  frame, a safety stop in between: skipped), and only over 0 < dt <= ``max_dt``.

``reset()`` (each new run) keeps what was learned, as a robot on the same floor keeps its gains;
``forget()`` starts from nothing.

The reference gains (``ONLINE_REFERENCE_GAINS``) are what this estimator sees on the nominal simulated
robots while following (``benchmarks/online_calibration_reference.py`` measures them): a skid-steer
base's yaw gain depends on how it drives, so the offline excitation's reference would not do here.
"""

from __future__ import annotations

import collections
import math

import numpy as np

from lbgp.calibration import MAX_CORRECTION
from lbgp.geometry import wrap_angle
from lbgp.robots import get_robot

# (gain_v, gain_w) the estimator sees on the nominal simulated robots over the paper's scenarios
# (and for the TurtleBot 2 the real-world protocol): benchmarks/online_calibration_reference.py
# (rerun with the planner's QP refinement, 2026-12-02: Jackal (1.000, 0.796), TurtleBot 2 (0.987,
# 0.734), inside the dead band below; the values here, from the run before, were kept so that the
# sim-to-real results made with them stay reproducible)
ONLINE_REFERENCE_GAINS: dict[str, tuple[float, float]] = {"jackal": (1.001, 0.796), "turtlebot2": (0.987, 0.712)}
# the dead band per robot: about the spread of those estimates across manoeuvres (10th to 90th
# percentile of the yaw gain: Jackal 0.778-0.859; TurtleBot 2 0.613-0.871, whose yaw answer depends
# on how it turns), so that the nominal robot is left alone whatever it does
ONLINE_DEADBAND: dict[str, float] = {"jackal": 0.1, "turtlebot2": 0.25}


MIN_GAIN = 0.1  # estimates below this are not used (a robot pushing against something is not a slippery one)


class OnlineCalibration:
    """Scale each command sent by the robot's gains relative to the simulated robot's, estimated
    online; see the module docstring. ``observe(t, pose)`` before ``apply(v, w)`` at every tick."""

    source = "online"
    LAGS = 5  # a sample is steady when the last LAGS commands sent were the same (within steady_tolerance) ...
    SETTLE_SAMPLES = 3  # ... and the measured motion changed by no more than that over this many samples
    # (0.3 s: a base still ramping up at its firmware's 0.5 m/s^2 changes speed by 0.15 m/s)

    def __init__(self, robot: str, window: float = 3.0, min_excitation: tuple[float, float] = (0.09, 0.09),
                 deadband: float | None = None, max_dt: float = 0.35, max_rate: float = 0.5, steady_tolerance: float = 0.1,
                 min_steady: float = 0.5, linear_share: tuple[float, float] = (1.0, 0.6)):
        if robot not in ONLINE_REFERENCE_GAINS:
            raise ValueError(f"no online reference gains for robot {robot!r}; use one of {', '.join(ONLINE_REFERENCE_GAINS)}")
        deadband = ONLINE_DEADBAND[robot] if deadband is None else deadband
        if not (window > 0 and deadband >= 0 and max_dt > 0 and max_rate > 0 and all(e > 0 for e in min_excitation)
                and all(0 < x <= 1 for x in linear_share)):
            raise ValueError("online calibration: window, max_dt, max_rate and min_excitation must be > 0, deadband >= 0, "
                             "linear_share (v, w) in (0, 1]")
        spec = get_robot(robot)
        self.robot = robot
        self.reference = ONLINE_REFERENCE_GAINS[robot]
        self.rated = (spec.max_speed, spec.max_yaw_rate)  # the base's published top speeds
        self.linear_share = linear_share  # only commands within this share of them are used: beyond, a base may saturate
        self.window, self.min_excitation, self.deadband, self.max_dt = window, min_excitation, deadband, max_dt
        self.max_rate = max_rate  # the correction's log changes by at most this per second
        self.steady_tolerance = steady_tolerance  # share of the rated limit the steady commands may spread over
        self.min_steady = min_steady  # s of steady samples in the window before a gain is estimated
        self.forget()

    @property
    def is_identity(self) -> bool:
        return False  # it may scale at any time

    def reset(self) -> None:
        """A new run of the same robot: the samples start afresh, what was learned (the gains and
        the correction) stays, as a robot on the same floor keeps its gains from run to run."""
        self._samples: collections.deque = collections.deque()  # (t, dt, sent (LAGS, 2) newest first, achieved (2,), earlier achieved (2,))
        self._sent: collections.deque = collections.deque(maxlen=self.LAGS)  # commands sent, newest first
        self._anchor: tuple[float, np.ndarray] | None = None
        self._sent_count = 0
        self._chain: collections.deque = collections.deque(maxlen=self.SETTLE_SAMPLES + 1)  # (t, achieved) of consecutive samples

    def forget(self) -> None:
        """Start from nothing: no correction until the new robot's gains have been estimated."""
        self.gains = [math.nan, math.nan]  # the latest estimates (nan: not enough excitation yet)
        self.scale_v, self.scale_w = 1.0, 1.0
        self.reset()

    def observe(self, t: float, pose) -> None:
        """The robot's measured pose (x, y, yaw) at time ``t`` (s, increasing)."""
        pose = np.asarray(pose, dtype=float).reshape(3)
        if not np.all(np.isfinite(pose)) or not math.isfinite(t):
            self._anchor, self._sent_count = None, 0
            return
        if self._anchor is not None and t <= self._anchor[0]:
            return  # no new pose since the last one: the commands sent meanwhile make its sample unusable
        if self._anchor is not None and self._sent_count == 1 and len(self._sent) == self.LAGS:
            t0, p0 = self._anchor
            dt = t - t0
            if 0.0 < dt <= self.max_dt:
                turn = float(wrap_angle(pose[2] - p0[2]))
                mid = p0[2] + 0.5 * turn
                forward = math.cos(mid) * (pose[0] - p0[0]) + math.sin(mid) * (pose[1] - p0[1])
                achieved = np.array([forward / dt, turn / dt])
                if self._chain and self._chain[-1][0] != t0:
                    self._chain.clear()  # a gap: the chain of consecutive samples starts again
                self._chain.append((float(t), achieved))
                # the motion SETTLE_SAMPLES samples earlier (nan if the chain is shorter)
                earlier = self._chain[0][1] if len(self._chain) > self.SETTLE_SAMPLES else np.full(2, np.nan)
                self._samples.append((t, dt, np.array(self._sent), achieved, earlier))
                self._update(t, dt)
        self._anchor, self._sent_count = (float(t), pose), 0

    def _update(self, t: float, dt: float) -> None:
        while self._samples and self._samples[0][0] <= t - self.window:
            self._samples.popleft()
        weights = np.array([s[1] for s in self._samples])
        sent = np.stack([s[2] for s in self._samples])  # (K, LAGS, 2), newest first
        achieved = np.stack([s[3] for s in self._samples])  # (K, 2)
        earlier = np.stack([s[4] for s in self._samples])  # (K, 2), nan where the chain is too short
        scales = [self.scale_v, self.scale_w]
        for i in (0, 1):
            # steady samples only: the same command for LAGS ticks and the robot's motion no longer
            # changing (latency, lag and acceleration limits have played out: a transient says
            # nothing about the gain), none saturating
            c, tolerance = sent[:, :, i], self.steady_tolerance * self.rated[i]
            with np.errstate(invalid="ignore"):
                settled = np.abs(achieved[:, i] - earlier[:, i]) <= tolerance  # nan: not settled
            linear = np.abs(c[:, 0]) <= self.linear_share[i] * self.rated[i]
            steady = (np.ptp(c, axis=1) <= tolerance) & linear & settled
            w, c, a = weights[steady], c[steady, 0], achieved[steady, i]
            energy = float(w @ c**2)
            if w.sum() < self.min_steady or energy / self.window < self.min_excitation[i]:
                continue  # not enough of this command held in the window: keep the last estimate
            gain = float(w @ (c * a)) / energy
            if gain < MIN_GAIN:
                continue  # the robot hardly answers (stuck, or held): not a gain to correct for
            self.gains[i] = gain
            target = math.log(self._correction(self.reference[i], gain))
            step = self.max_rate * dt
            scales[i] = math.exp(min(max(target, math.log(scales[i]) - step), math.log(scales[i]) + step))
        self.scale_v, self.scale_w = scales

    def _correction(self, reference: float, gain: float) -> float:
        log_ratio = math.log(reference / gain)
        shrunk = math.copysign(max(abs(log_ratio) - math.log1p(self.deadband), 0.0), log_ratio)
        return min(max(math.exp(shrunk), 1.0 / MAX_CORRECTION), MAX_CORRECTION)

    def apply(self, v: float, w: float) -> tuple[float, float]:
        """The command to send for the wanted (v, w); remembered for the next ``observe``."""
        sent = (v * self.scale_v, w * self.scale_w)
        self._sent.appendleft(sent)
        self._sent_count += 1
        return sent

    def to_dict(self) -> dict:
        return {"source": self.source, "robot": self.robot, "window": self.window, "deadband": self.deadband,
                "scale_v": self.scale_v, "scale_w": self.scale_w}
