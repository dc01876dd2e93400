"""Timed-elastic-band local planner solved as a sequence of QPs with OSQP.

The band is N poses (x, y, theta) and the N-1 time intervals dt between them (TEB's formulation).
One planner call runs a few sequential-QP iterations; each iteration

1. times the band: the dt that make it as fast as the velocity and acceleration limits allow,
   starting from the robot's current velocity and arriving with the goal velocity
   (``lbgp.planner.timing``; TEB's minimal-total-time objective and its velocity/acceleration
   edges, solved in closed form instead of inside the QP, which keeps the QP well conditioned);
2. linearises the rest of TEB's objective and constraints around the current band, with the
   person's position predicted (constant velocity) at each pose's time, and solves one QP for a step
   ``d`` of the poses with OSQP, inside a trust region.

The QP's sparsity is fixed at construction: OSQP is set up once, and every later solve only
``update``s values and warm-starts.

Variable layout of one QP (N = n_poses; all entries are steps from the current band):

    d = [ dx_0 .. dx_{N-1} | dy_0 .. dy_{N-1} | dtheta_0 .. dtheta_{N-1} | s_1 .. s_{N-1} ]
          0 .. N-1           N .. 2N-1          2N .. 3N-1                  3N .. 4N-2

where s_i >= 0 is the slack of pose i's clearance constraint (elastic mode: the QP stays feasible
when one step cannot clear the person; slack costs an exact L1 penalty plus a quadratic one).

Objective (soft, Gauss-Newton on squared residuals): goal position and heading of the last pose;
elastic band (squared segment lengths: short, evenly spaced band, i.e. short travel time);
non-holonomic kinematics (TEB's residual: each segment along the mean of its end headings);
squared heading changes (turning takes time);
forward-drive preference (backward segments penalised); a small proximal term.
Constraints (linearised): first pose fixed at the robot; trust region; at every later pose a
distance of at least the safety distance from the person's predicted position, as a half-plane
through the linearisation point (elastic, see the slacks above). If after the step the next pose
(the one the command drives to) is inside the safety distance and closer to the person than the
robot is now, the call returns a safe stop with status ``infeasible``: the robot never drives
deeper into the person's safety radius (moving out of it, e.g. away from a person who walks
towards the robot, is allowed).

If the person's predicted path crosses the band within the next ``slowdown_horizon`` seconds at
its time-optimal timing, the band is re-timed slower (``slowdown_factors`` of the speed limits)
until it clears: the robot waits for the person to pass rather than racing them.

The command is the first segment's (v, w), clamped to the velocity limits and to the acceleration
limits over one control period, so the hard limits hold even when the band is only approximately
feasible. Failures (bad input, goal inside the person's safety radius, infeasible QP, solver error,
diverging band) return a safe stop (decelerate within limits) with a status that says why.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import osqp
import scipy.sparse as sp

from lbgp.geometry import wrap_angle
from lbgp.planner.band import Band, band_is_sane, initial_band, shifted_band
from lbgp.planner.config import PlannerConfig
from lbgp.planner.timing import time_segments

OK = "ok"
INVALID_INPUT = "invalid_input"
GOAL_IN_COLLISION = "goal_in_collision"
INFEASIBLE = "infeasible"
SOLVER_ERROR = "solver_error"
DIVERGED = "diverged"

_SOLVED = {osqp.SolverStatus.OSQP_SOLVED, osqp.SolverStatus.OSQP_SOLVED_INACCURATE, osqp.SolverStatus.OSQP_MAX_ITER_REACHED}
_INFEASIBLE = {osqp.SolverStatus.OSQP_PRIMAL_INFEASIBLE, osqp.SolverStatus.OSQP_PRIMAL_INFEASIBLE_INACCURATE}


@dataclasses.dataclass
class Plan:
    """What one planner call returns. ``status`` is ``ok`` or says why a safe stop was commanded."""

    v: float
    w: float
    status: str
    poses: np.ndarray  # (N, 3) band poses, world frame (empty on invalid input)
    times: np.ndarray  # (N,) time of each pose from now, s
    person_prediction: np.ndarray  # (N, 2) predicted person positions at those times
    iterations: int = 0
    solve_time: float = 0.0  # s, wall time of this call

    @property
    def ok(self) -> bool:
        return self.status == OK


def clamp_command(v: float, w: float, v_now: float, w_now: float, cfg: PlannerConfig) -> tuple[float, float]:
    """Clamp (v, w) to the velocity limits and to what the acceleration limits allow in one period."""
    dv = cfg.acc_lim_x * cfg.control_period
    dw = cfg.acc_lim_theta * cfg.control_period
    v = min(max(v, v_now - dv), v_now + dv)
    w = min(max(w, w_now - dw), w_now + dw)
    # v_now itself may be outside the limits (e.g. the robot was pushed): the velocity limit wins
    v = min(max(v, -cfg.max_vel_x_backwards), cfg.max_vel_x)
    w = min(max(w, -cfg.max_vel_theta), cfg.max_vel_theta)
    return float(v), float(w)


def safe_stop(v_now: float, w_now: float, cfg: PlannerConfig) -> tuple[float, float]:
    """Decelerate towards zero as fast as the acceleration limits allow (never a jump)."""
    v_now = v_now if math.isfinite(v_now) else 0.0
    w_now = w_now if math.isfinite(w_now) else 0.0
    v = math.copysign(max(abs(v_now) - cfg.acc_lim_x * cfg.control_period, 0.0), v_now)
    w = math.copysign(max(abs(w_now) - cfg.acc_lim_theta * cfg.control_period, 0.0), w_now)
    return clamp_command(v, w, v_now, w_now, cfg)


class TebPlanner:
    """Plan a band from the robot to a goal around a moving person; see the module docstring."""

    def __init__(self, config: PlannerConfig | None = None):
        self.cfg = config or PlannerConfig()
        N = self.cfg.n_poses
        if N < 3:
            raise ValueError(f"n_poses must be at least 3, got {N}")
        self.N = N
        self.nvar = 3 * N + (N - 1)  # poses, then one clearance slack per pose 1..N-1
        self.islack = 3 * N + np.arange(N - 1)
        self.ix, self.iy, self.ith = np.arange(N), N + np.arange(N), 2 * N + np.arange(N)
        self._k = np.arange(N - 1)
        self._band: Band | None = None
        self._goal: np.ndarray | None = None
        self._solver = None
        self._setup_structure()

    # ------------------------------------------------------------------ public
    def reset(self) -> None:
        """Forget the previous band (the next call re-initialises) and OSQP's state (warm start,
        adapted step size), so that an episode's plans do not depend on the episodes before it."""
        self._forget_band()
        self._solver = None

    def _forget_band(self) -> None:
        self._band = None
        self._goal = None

    def plan(self, robot_pose, robot_velocity, goal, person_pose, person_velocity, goal_velocity=(0.0, 0.0)) -> Plan:
        """One planner call.

        ``goal`` is (x, y) or (x, y, yaw) in the world now; its yaw defaults to the person's
        heading. ``person_velocity`` is the person's world (vx, vy). ``goal_velocity`` is the goal's
        world (vx, vy): a goal carried along by a walking person moves with it, so the band ends
        where the goal will be when the robot gets there and arrives with the goal's speed
        ((0, 0): a fixed goal, stop there). Never raises on bad numbers: returns a safe-stop plan
        whose status says why.
        """
        t_start = time.perf_counter()
        cfg = self.cfg
        try:
            robot_pose = np.asarray(robot_pose, dtype=float).reshape(3)
            v_now, w_now = (float(x) for x in np.asarray(robot_velocity, dtype=float).reshape(2))
            person_pose = np.asarray(person_pose, dtype=float).reshape(3)
            person_vel = np.asarray(person_velocity, dtype=float).reshape(2)
            goal = np.asarray(goal, dtype=float).reshape(-1)
            if goal.size == 2:
                goal = np.array([goal[0], goal[1], person_pose[2]])
            goal = goal.reshape(3)
            goal_vel = np.asarray(goal_velocity, dtype=float).reshape(2)
        except (TypeError, ValueError):
            return self._stop(0.0, 0.0, INVALID_INPUT, t_start)
        values = np.concatenate([robot_pose, [v_now, w_now], goal_vel, person_pose, person_vel, goal])
        if not np.all(np.isfinite(values)):
            return self._stop(v_now, w_now, INVALID_INPUT, t_start)
        if np.linalg.norm(goal[:2] - person_pose[:2]) < cfg.safety_distance:
            self._forget_band()
            return self._stop(v_now, w_now, GOAL_IN_COLLISION, t_start)

        warm = self._band is not None and np.linalg.norm(goal[:2] - self._goal[:2]) <= cfg.reinit_goal_jump
        goal_speed = float(np.hypot(*goal_vel))
        if warm:
            band = shifted_band(self._band, robot_pose, cfg.dt_min)
        else:
            # aim the first band where the goal will be after a rough travel-time estimate
            closing = max(cfg.max_vel_x - goal_speed, 0.2 * cfg.max_vel_x)
            eta = min(np.linalg.norm(goal[:2] - robot_pose[:2]) / closing, 5.0)
            ahead = np.r_[goal[:2] + goal_vel * eta, goal[2]]
            band = initial_band(robot_pose, ahead, person_pose[:2], cfg.safety_distance + 0.1, self.N)
        iterations = cfg.sqp_iterations if warm else cfg.sqp_iterations_init
        scale = float(np.linalg.norm(goal[:2] - robot_pose[:2])) + 1.0
        status, done = OK, 0
        t_loop = time.perf_counter()
        for done in range(1, iterations + 1):
            if cfg.sqp_time_budget is not None and done > 1:
                spent = time.perf_counter() - t_start
                if spent + (time.perf_counter() - t_loop) / (done - 1) > cfg.sqp_time_budget:
                    done -= 1
                    break  # anytime: the band keeps improving from the next call (warm start)
            band.dt = self._timing(band, v_now, w_now, goal_speed)
            goal_then = np.r_[goal[:2] + goal_vel * band.times[-1], goal[2]]
            step, status = self._sqp_step(band, goal_then, person_pose[:2], person_vel)
            if status != OK:
                break
            step[[self.ix[0], self.iy[0], self.ith[0]]] = 0.0  # exact, not just to OSQP's tolerance
            band.poses[:, 0] += step[self.ix]
            band.poses[:, 1] += step[self.iy]
            band.poses[:, 2] += step[self.ith]
            if not band_is_sane(band, scale):
                status = DIVERGED
                break
            if float(np.max(np.abs(step))) < cfg.step_tolerance:
                break
        if status != OK:
            self._forget_band()
            return self._stop(v_now, w_now, status, t_start, band, person_pose[:2], person_vel, done)
        band.dt = self._timing(band, v_now, w_now, goal_speed)
        clear_soon, clearance = self._clear_soon(band, person_pose[:2], person_vel)
        if not clear_soon:
            # the person would cross the band soon while we drive it: wait for them, drive it slower
            for slower in cfg.slowdown_factors:
                timed = Band(band.poses, self._timing(band, v_now, w_now, goal_speed, speed_scale=slower))
                clear_soon, c = self._clear_soon(timed, person_pose[:2], person_vel)
                if clear_soon:
                    band.dt, clearance = timed.dt, c
                    break
        if clearance[1] < cfg.safety_distance - cfg.clearance_tolerance and clearance[1] < clearance[0]:
            self._forget_band()
            return self._stop(v_now, w_now, INFEASIBLE, t_start, band, person_pose[:2], person_vel, done)
        self._band, self._goal = band.copy(), goal.copy()

        d = band.poses[1] - band.poses[0]
        heading = band.poses[0, 2]
        v = (math.cos(heading) * d[0] + math.sin(heading) * d[1]) / band.dt[0]
        w = d[2] / band.dt[0]
        v, w = clamp_command(v, w, v_now, w_now, cfg)
        return self._result(v, w, OK, band, person_pose[:2], person_vel, done, t_start)

    # ------------------------------------------------------------------ helpers
    def _timing(self, band: Band, v_now, w_now, goal_speed, speed_scale: float = 1.0) -> np.ndarray:
        cfg = self.cfg
        poses = band.poses
        d = poses[1:] - poses[:-1]
        mid = poses[:-1, 2] + 0.5 * d[:, 2]
        length = np.cos(mid) * d[:, 0] + np.sin(mid) * d[:, 1]
        return time_segments(
            length, d[:, 2], v_now, w_now, goal_speed,
            cfg.max_vel_x * speed_scale, cfg.max_vel_x_backwards * speed_scale, cfg.max_vel_theta,
            cfg.acc_lim_x, cfg.acc_lim_theta, cfg.dt_min,
        )

    def _result(self, v, w, status, band, person_xy, person_vel, iterations, t_start) -> Plan:
        times = band.times
        prediction = person_xy[None, :] + times[:, None] * person_vel[None, :]
        poses = band.poses.copy()
        poses[:, 2] = wrap_angle(poses[:, 2])
        return Plan(v, w, status, poses, times, prediction, iterations, time.perf_counter() - t_start)

    def _stop(self, v_now, w_now, status, t_start, band=None, person_xy=None, person_vel=None, iterations=0) -> Plan:
        v, w = safe_stop(v_now, w_now, self.cfg)
        if band is None or not band_is_sane(band, 1e6):
            return Plan(v, w, status, np.zeros((0, 3)), np.zeros(0), np.zeros((0, 2)), iterations, time.perf_counter() - t_start)
        return self._result(v, w, status, band, person_xy, person_vel, iterations, t_start)

    # ------------------------------------------------------------------ the QP
    # Soft residual rows, in order: goal (x, y, heading) | elastic dx_i | elastic dy_i |
    # non-holonomic_i | turn_i | forward-drive_i  (i = 0 .. N-2). The Jacobian J of these residuals
    # has fixed entries (goal, elastic, turn: +-1) written once, and entries that change with the
    # band (non-holonomic, forward drive) written at fixed flat positions every iteration.

    def _setup_structure(self) -> None:
        """Weights, constant Jacobian entries, the constant part of the constraints, and the fixed
        sparsity of P and A (from a generic random band with every hinge active)."""
        cfg, N, n = self.cfg, self.N, self.nvar
        ix, iy, ith, k = self.ix, self.iy, self.ith, self._k
        self._n_res = 3 + 5 * (N - 1)
        self._weights = np.concatenate([
            [cfg.weight_goal, cfg.weight_goal, cfg.weight_goal_heading],
            np.full(2 * (N - 1), cfg.weight_elastic),
            np.full(N - 1, cfg.weight_nonholonomic),
            np.full(N - 1, cfg.weight_turn),
            np.full(N - 1, cfg.weight_forward_drive),
        ])
        J = np.zeros((self._n_res, n))
        J[0, ix[-1]] = J[1, iy[-1]] = J[2, ith[-1]] = 1.0
        row_dx, row_dy, row_nh, row_turn, row_fwd = (3 + j * (N - 1) + k for j in range(5))
        for rows, idx in ((row_dx, ix), (row_dy, iy), (row_turn, ith)):
            J[rows, idx[:-1]] = -1.0
            J[rows, idx[1:]] = 1.0
        self._J = J
        flat = lambda rows, cols: rows * n + cols  # noqa: E731
        self._J_dynamic = np.concatenate([
            flat(row_nh, ix[:-1]), flat(row_nh, ix[1:]), flat(row_nh, iy[:-1]), flat(row_nh, iy[1:]),
            flat(row_nh, ith[:-1]), flat(row_nh, ith[1:]),
            flat(row_fwd, ix[:-1]), flat(row_fwd, ix[1:]), flat(row_fwd, iy[:-1]), flat(row_fwd, iy[1:]),
        ])
        # constraints: rows 0..n-1 trust region (first pose fixed); rows n.. person clearance
        self._m = n + (N - 1)
        self._diag = np.diag_indices(n)
        self._A = np.zeros((self._m, n))
        self._A[self._diag] = 1.0
        self._A[n + k, self.islack] = 1.0
        self._A_dynamic = np.concatenate([flat(n + k, ix[1:]), flat(n + k, iy[1:])])
        trust = np.concatenate([np.full(2 * N, cfg.trust_region_position), np.full(N, cfg.trust_region_heading)])
        trust[[ix[0], iy[0], ith[0]]] = 0.0
        self._lo = np.concatenate([-trust, np.zeros(N - 1), np.zeros(N - 1)])
        self._hi = np.concatenate([trust, np.full(N - 1, np.inf), np.full(N - 1, np.inf)])
        self._slack_q = np.zeros(n)
        self._slack_q[self.islack] = cfg.weight_clearance_slack
        rng = np.random.default_rng(0)
        band = Band(rng.normal(size=(N, 3)), rng.uniform(0.1, 0.5, N - 1))
        P, _, A, _, _ = self._assemble(band, rng.normal(size=3), rng.normal(size=2), rng.normal(size=2), pattern=True)
        P_pat = sp.csc_matrix(np.triu(P) != 0)
        A_pat = sp.csc_matrix(A != 0)
        self._P_struct = (P_pat.indices.copy(), P_pat.indptr.copy())
        self._A_struct = (A_pat.indices.copy(), A_pat.indptr.copy())
        self._P_at = (P_pat.indices.copy(), np.repeat(np.arange(n), np.diff(P_pat.indptr)))
        self._A_at = (A_pat.indices.copy(), np.repeat(np.arange(n), np.diff(A_pat.indptr)))

    def _assemble(self, band: Band, goal, person_xy, person_vel, pattern: bool = False):
        """Dense P, q, A, l, u of the QP for the step d around ``band`` (module docstring).
        With ``pattern`` every hinge counts as active, so that P shows every possible non-zero."""
        cfg, N = self.cfg, self.N
        poses = band.poses
        X, Y, TH = poses[:, 0], poses[:, 1], poses[:, 2]
        d = poses[1:] - poses[:-1]
        dX, dY, dTH = d[:, 0], d[:, 1], d[:, 2]
        c, s = np.cos(TH), np.sin(TH)
        cs, ss = c[:-1] + c[1:], s[:-1] + s[1:]
        mid = TH[:-1] + 0.5 * dTH
        cm, sm = np.cos(mid), np.sin(mid)
        ds = cm * dX + sm * dY
        fwd = np.ones(N - 1) if pattern else (ds < 0.0).astype(float)
        # residuals, in the row order above
        r = np.concatenate([
            [X[-1] - goal[0], Y[-1] - goal[1], wrap_angle(TH[-1] - goal[2])],
            dX, dY, cs * dY - ss * dX, dTH, ds * fwd,
        ])
        # Jacobian entries that change: non-holonomic (TEB) and forward-drive hinge
        J = self._J
        cmf, smf = cm * fwd, sm * fwd
        J.flat[self._J_dynamic] = np.concatenate([
            ss, -ss, -cs, cs, -s[:-1] * dY - c[:-1] * dX, -s[1:] * dY - c[1:] * dX,
            -cmf, cmf, -smf, smf,
        ])
        JW = J * self._weights[:, None]
        P = 2.0 * (J.T @ JW)
        P[self._diag] += cfg.regularization
        P[self.islack, self.islack] += 2.0 * cfg.weight_clearance_slack
        q = 2.0 * (JW.T @ r) + self._slack_q
        # person clearance at poses 1..N-1: n_i . (p_i - q_i) >= d_safe, q_i predicted at t_i
        t = np.cumsum(band.dt)
        diff = poses[1:, :2] - person_xy - t[:, None] * person_vel
        dist = np.sqrt(np.einsum("ij,ij->i", diff, diff))
        normal = diff / np.maximum(dist, 1e-9)[:, None]
        A = self._A
        A.flat[self._A_dynamic] = normal.T.ravel()
        lo = self._lo
        lo[self.nvar :] = cfg.safety_distance - dist
        return P, q, A, lo, self._hi

    def _clear_soon(self, band: Band, person_xy, person_vel) -> tuple[bool, np.ndarray]:
        """Whether the poses within ``slowdown_horizon`` (after the first) keep the safety distance
        from the predicted person; also returns every pose's clearance."""
        cfg = self.cfg
        clearance = self._clearance(band, person_xy, person_vel)
        near = band.times <= cfg.slowdown_horizon
        near[0] = False
        return bool(not near.any() or clearance[near].min() >= cfg.safety_distance - cfg.clearance_tolerance), clearance

    def _clearance(self, band: Band, person_xy, person_vel) -> np.ndarray:
        """Distance of each band pose from the person's predicted position at that pose's time."""
        diff = band.poses[:, :2] - person_xy - band.times[:, None] * person_vel
        return np.sqrt(np.einsum("ij,ij->i", diff, diff))

    def _sqp_step(self, band: Band, goal, person_xy, person_vel):
        """Solve one QP around ``band``; returns (step, status)."""
        P, q, A, lo, hi = self._assemble(band, goal, person_xy, person_vel)
        Px, Ax = P[self._P_at], A[self._A_at]
        if not (np.all(np.isfinite(Px)) and np.all(np.isfinite(Ax)) and np.all(np.isfinite(q)) and np.all(np.isfinite(lo))):
            return None, DIVERGED
        if self._solver is None:
            self._solver = osqp.OSQP()
            self._solver.setup(
                sp.csc_matrix((Px, *self._P_struct), shape=(self.nvar, self.nvar)),
                q,
                sp.csc_matrix((Ax, *self._A_struct), shape=(self._m, self.nvar)),
                lo,
                hi,
                verbose=False,
                polishing=False,
                warm_starting=True,
                eps_abs=self.cfg.osqp_eps,
                eps_rel=self.cfg.osqp_eps,
                max_iter=self.cfg.osqp_max_iter,
            )
        else:
            self._solver.update(Px=Px, Ax=Ax, q=q, l=lo, u=hi)
        result = self._solver.solve(raise_error=False)
        status = result.info.status_val
        if status in _INFEASIBLE:
            return None, INFEASIBLE
        if status not in _SOLVED:
            return None, SOLVER_ERROR
        step = np.asarray(result.x, dtype=float)
        if not np.all(np.isfinite(step)):
            return None, SOLVER_ERROR
        return step, OK
