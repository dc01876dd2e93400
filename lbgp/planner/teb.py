"""Timed-band local planner solved as a sequence of QPs with OSQP: goal in, (v, w) out, the person
as a moving obstacle.

The band is N poses timed at a fixed interval h (``band_dt``, the control period), so pose i is
where the robot will be at t_i = i h. The band is parameterised by the M = N - 1 commands
(v_k, w_k) between its poses (``lbgp.planner.kinematics``): diff-drive kinematics hold exactly,
velocity limits are bounds and acceleration limits are linear constraints, both exact.

Objective (least squares, SI units): every pose i tracks the goal's *predicted* position at its
own time g(t_i): a goal carried by a walking person rides the person's predicted arc (velocity and
turn rate), a free goal moves at its own velocity (a goal slightly behind the robot is met by
slowing down, never by looping back to where it was), with extra weight on the last pose and on
its heading; small costs on changes of v and w
(smooth commands) and on w. Constraints: velocity and acceleration limits (the first segment from
the robot's current velocity over one control period), a trust region per SQP iteration, and a
clearance of at least the safety distance from the person's predicted position (constant
velocity and turn rate) at every pose's time, linearised as half-planes, elastic (slack with an exact L1 plus a
quadratic penalty) so that the QP is always feasible.

Sequential QP (Gauss-Newton): each iteration rolls the commands out, linearises, and solves one QP
for the command step with OSQP, to a stated accuracy (``osqp_eps``, then polished); iterations
stop when no command moves more than ``step_tolerance``, or after ``sqp_iterations`` (3: short of
convergence on most bands, a trade measured in benchmarks/sqp_iterations.py). The QP's sparsity is fixed: OSQP is set
up once, every later solve only updates values.

No hidden state: every call starts from the same deterministic first guess (a pursuit of the
moving goal within the limits, ``pursuit_commands``), and OSQP starts each call as a fresh solver
would (x = y = 0, the initial rho; its warm start only carries from one QP to the next within a
candidate band, and every band starts afresh), so the command is a function of (robot pose and
velocity, person pose and velocity, goal) alone, exactly: where two candidate bands score alike, solver noise cannot tip the choice.
Local minima (TEB's remedy: bands in distinct topologies): for a goal that will still be behind
the robot at the end of the horizon, a forwards-only band that turns the robot around is solved
beside the one that may back up; when the band passes near the person's predicted path, one that
starts by braking (let the person cross first); when the band is stuck behind the person on the
line to the goal (robot, person and goal in one line leave the SQP no side to lean to), one that
passes the person on one side. The cheapest band is kept, its cost including the
time it leaves to the goal (at the speed its last pose allows towards the goal).

A goal within the person's safety distance, bad input, a failed QP, or a next pose that would go
deeper into the person's safety radius returns a safe stop (decelerate within limits) with a
status that says why.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import scipy.sparse as sp

from lbgp.geometry import predict_person, wrap_angle
from lbgp.planner.config import PlannerConfig
from lbgp.planner.kinematics import pursuit_commands, rollout
from lbgp.planner.qp import PRIMAL_INFEASIBLE, SOLVED, SparseQP

OK = "ok"
INVALID_INPUT = "invalid_input"
GOAL_IN_COLLISION = "goal_in_collision"
INFEASIBLE = "infeasible"
SOLVER_ERROR = "solver_error"
DIVERGED = "diverged"


@dataclasses.dataclass
class Plan:
    """What one planner call returns. ``status`` is ``ok`` or says why a safe stop was commanded."""

    v: float
    w: float
    status: str
    poses: np.ndarray  # (N, 3) band poses, world frame (empty on invalid input)
    times: np.ndarray  # (N,) time of each pose from now, s
    person_prediction: np.ndarray  # (N, 2) predicted person positions at those times
    iterations: int = 0  # SQP iterations, all candidate bands together
    solve_time: float = 0.0  # s, wall time of this call
    candidate: str = ""  # which first guess the kept band came from ("keep", "turn", "wait", "left" or "right")
    tried: tuple[str, ...] = ()  # the candidate bands solved, in order

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


def _value_positions(shape, rows, cols) -> np.ndarray:
    """(shape) array: where entry (i, j) of a sparse pattern with these rows and columns (in its CSC
    values' order) sits among the values, -1 where the pattern has none."""
    position = np.full(shape, -1)
    position[rows, cols] = np.arange(len(rows))
    return position


@dataclasses.dataclass
class _Problem:
    """Everything one call's QPs share (world frame)."""

    pose0: np.ndarray
    v_ref: float
    w_ref: float
    goal_path: np.ndarray  # (M, 2) goal position at each pose's time
    goal_yaw: np.ndarray  # (M,) the goal's heading at each pose's time
    person_path: np.ndarray  # (N, 2) predicted person position at each pose's time, from now
    lateral_clear: float | None = None  # the lateral acceleration limit clear of the person, this call (``_lateral_limit``)


class TebPlanner:
    """Plan a timed band from the robot to a moving goal around a moving person; see the module
    docstring. ``stats`` counts OSQP solves, iterations and how often the iteration cap was hit."""

    def __init__(self, config: PlannerConfig | None = None):
        self.cfg = config or PlannerConfig()
        N = self.cfg.n_poses
        if N < 3:
            raise ValueError(f"n_poses must be at least 3, got {N}")
        self.N, self.M = N, N - 1
        self.h = float(self.cfg.band_dt)
        self._last_band = None  # (commands, poses, distances) of this call's last band: see _band
        self._setup_structure()

    @property
    def stats(self) -> dict:
        """OSQP solves, ADMM iterations, iteration-cap hits, inaccurate and unpolished solutions."""
        return self._qp.stats.as_dict()

    # ------------------------------------------------------------------ public
    def reset(self) -> None:
        """Drop OSQP's warm start (plans never depended on it beyond the solver's tolerance)."""
        self._qp.reset()

    def plan(self, robot_pose, robot_velocity, goal, person_pose, person_velocity, goal_velocity=(0.0, 0.0),
             person_turn_rate: float = 0.0, goal_moves_with_person: bool = False, command_scale_w: float = 1.0) -> Plan:
        """One planner call.

        ``goal`` is (x, y) or (x, y, yaw) in the world now; its yaw defaults to the person's
        heading. The person is predicted on a constant-turn arc: world velocity ``person_velocity``
        (vx, vy) turning at ``person_turn_rate`` (rad/s). Every band pose tracks where the goal will
        be at that pose's time: with ``goal_moves_with_person`` the goal is fixed in the person's
        frame and rides the person's arc (what a follow-ahead goal does); otherwise it moves at
        ``goal_velocity`` ((0, 0): a fixed goal, stop there). ``command_scale_w``: what a command
        calibration will multiply the turn rate by on its way to the wheels (``lbgp.calibration``);
        ``lateral_acc_limit_clear`` bounds the command sent, so the band may use at most that
        limit over this scale (never less than ``lateral_acc_limit``), and ``weight_turn`` prices the
        turn rate sent, so the band's squared turn rate weighs ``weight_turn`` times its square.
        Never raises on bad numbers: returns a safe-stop plan whose status says why.
        """
        t_start = time.perf_counter()
        cfg = self.cfg
        self._last_band = None
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
            turn = float(person_turn_rate)
            scale_w = float(command_scale_w)
        except (TypeError, ValueError):
            return self._stop(0.0, 0.0, INVALID_INPUT, t_start)
        values = np.concatenate([robot_pose, [v_now, w_now, turn, scale_w], goal_vel, person_pose, person_vel, goal])
        if not np.all(np.isfinite(values)) or not scale_w > 0:
            return self._stop(v_now, w_now, INVALID_INPUT, t_start)
        if np.linalg.norm(goal[:2] - person_pose[:2]) < cfg.safety_distance:
            return self._stop(v_now, w_now, GOAL_IN_COLLISION, t_start)

        person_path, rotation = predict_person(person_pose[:2], person_vel, turn, self._times)
        if goal_moves_with_person:
            offset = goal[:2] - person_pose[:2]
            c, s_ = np.cos(rotation[1:]), np.sin(rotation[1:])
            goal_path = person_path[1:] + np.stack([c * offset[0] - s_ * offset[1], s_ * offset[0] + c * offset[1]], axis=1)
            goal_vel = person_vel + turn * np.array([-offset[1], offset[0]])  # the goal's velocity now
            goal_yaw = goal[2] + rotation[1:]
        else:
            goal_path = goal[None, :2] + self._times[1:, None] * goal_vel[None, :]
            goal_yaw = np.full(self.M, goal[2])
        problem = _Problem(
            pose0=robot_pose,
            v_ref=min(max(v_now, -cfg.max_vel_x_backwards), cfg.max_vel_x),
            w_ref=min(max(w_now, -cfg.max_vel_theta), cfg.max_vel_theta),
            goal_path=goal_path,
            goal_yaw=goal_yaw,
            person_path=person_path,
            lateral_clear=None if cfg.lateral_acc_limit_clear is None else
            max(cfg.lateral_acc_limit, cfg.lateral_acc_limit_clear / scale_w),
        )
        self._price_turns(cfg.weight_turn * scale_w**2)
        candidates = ["keep"]
        if cfg.turn_around_candidate and self._goal_off_heading(problem):
            candidates.append("turn")
        best, iterations, tried = None, 0, []
        while candidates:
            name = candidates.pop(0)
            if name in tried:
                continue  # a band's outcome depends on its problem and name only: solving it twice changes nothing
            tried.append(name)
            if name != "keep" and self._over_budget(t_start, iterations):
                break
            # every band from a fresh start: no state from earlier calls or from the band before (the same
            # input gives the same QPs, solved the same way; a warm start from another band can stall OSQP)
            self._qp.restart()
            guide = self._passing_guide(problem, name) if name in ("left", "right") else problem.goal_path
            v0, w0 = pursuit_commands(robot_pose, problem.v_ref, problem.w_ref, guide, goal_vel, self.h,
                                      cfg.control_period, self.M, cfg, reverse=(name != "turn"), wait=(name == "wait"))
            lower = self._forward_only(problem) if name == "turn" else self._u_lo  # turning around: forwards only
            band_problem = self._facing_goal(problem) if name == "turn" else problem
            u, status, done = self._solve_band(band_problem, np.concatenate([v0, w0]), t_start, iterations, lower)
            iterations += done
            if status != OK:
                if best is not None:
                    continue  # an extra candidate that failed is just not a candidate
                return self._stop(v_now, w_now, status, t_start, None, problem, iterations)
            poses, distance = self._band(problem, u)
            clearance = distance[1:]
            cost = self._candidate_score(problem, u, poses, clearance)
            if best is None or cost < best[0] - 1e-9:
                best = (cost, u, name, poses, clearance)
            if name != "wait" and cfg.wait_candidate and clearance.min() < cfg.safety_distance + cfg.wait_margin:
                candidates.append("wait")  # the band passes near the person's path: also try letting them pass
            if name == "keep" and cfg.pass_candidate and (side := self._blocked_side(problem, poses)):
                candidates.append(side)  # the band is stuck behind the person: also try passing them on one side
        _, u, name, poses, clearance = best
        now = float(np.hypot(*(robot_pose[:2] - person_pose[:2])))
        if clearance[0] < cfg.safety_distance - cfg.clearance_tolerance and clearance[0] < now:
            return self._stop(v_now, w_now, INFEASIBLE, t_start, poses, problem, iterations)
        v, w = clamp_command(float(u[0]), float(u[self.M]), v_now, w_now, cfg)
        return self._result(v, w, OK, poses, problem, iterations, t_start, name, tuple(tried))

    # ------------------------------------------------------------------ helpers
    def _goal_off_heading(self, problem: _Problem) -> bool:
        """Whether the goal, where it will be at the end of the horizon, lies behind or beside the
        robot (more than ``turn_candidate_angle`` off its heading, and farther than
        ``turn_candidate_distance``). A moving goal that will have caught up by then is met by
        slowing down or waiting: only a goal still behind (or beside: a diff-drive robot cannot
        move sideways) makes turning to face it worth trying."""
        x, y, th = problem.pose0
        g = problem.goal_path[-1]
        dx, dy = g[0] - x, g[1] - y
        dist = math.hypot(dx, dy)
        ahead = math.cos(th) * dx + math.sin(th) * dy
        return dist > self.cfg.turn_candidate_distance and ahead < math.cos(self.cfg.turn_candidate_angle) * dist

    def _blocked_side(self, problem: _Problem, poses: np.ndarray) -> str:
        """The side to pass the person on when the band is stuck behind them, else "".

        Stuck: the person stands within the safety distance of the straight line from the robot to
        where the goal will be (between the two), and the band ends behind the person (on the far
        side from the goal) within the safety distance of the person's line to the goal. With the
        robot, the person and the goal in one line, every linearised clearance half-plane faces
        straight back and no SQP step leans to either side (docs/planner.md, "A person straight
        between the robot and the goal"). The side is the one the robot already leans to, left
        when it is exactly on the line (a deterministic tie-break). Only a robot that can outrun
        the person by the safety distance over the band's horizon tries (a TurtleBot 2 behind a
        person walking at 0.6 m/s cannot pass them, so it does not pay for the band)."""
        cfg, safety = self.cfg, self.cfg.safety_distance
        robot, person, goal = problem.pose0[:2], problem.person_path[0], problem.goal_path[-1]
        person_speed = float(np.hypot(*(problem.person_path[1] - person))) / self.h
        if (cfg.max_vel_x - person_speed) * self._times[-1] < safety:
            return ""
        d, r = goal - robot, person - robot
        length = float(np.hypot(*d))
        if length < 1e-9 or not 0.0 < float(r @ d) < length**2:
            return ""
        lean = float(d[0] * r[1] - d[1] * r[0]) / length  # > 0: the person is left of the robot's line to the goal
        if abs(lean) >= safety:
            return ""
        person_end = problem.person_path[-1]
        ahead, end = goal - person_end, poses[-1, :2] - person_end
        length = float(np.hypot(*ahead))
        if length < 1e-9 or float(end @ ahead) >= 0.0 or abs(float(ahead[0] * end[1] - ahead[1] * end[0])) >= safety * length:
            return ""
        return "right" if lean > 0.0 else "left"

    def _passing_guide(self, problem: _Problem, side: str) -> np.ndarray:
        """The first guess of a band that passes the person on ``side``: a pursuit of the goal's
        path shifted sideways (perpendicular to the robot's line to the person) by the safety
        distance plus ``wait_margin``; the SQP then pulls the band back onto the goal."""
        d = problem.person_path[0] - problem.pose0[:2]
        normal = np.array([-d[1], d[0]]) / max(float(np.hypot(*d)), 1e-9)
        shift = (self.cfg.safety_distance + self.cfg.wait_margin) * (1.0 if side == "left" else -1.0)
        return problem.goal_path + shift * normal[None, :]

    @staticmethod
    def _facing_goal(problem: _Problem) -> _Problem:
        """The "turn" band's problem: its poses are asked to face the goal (the bearing from the
        robot to where the goal will be), not to hold the goal's heading. Turning around to a goal
        behind the robot means pointing away from that heading on the way; tracking it along the
        band would pull the band back to a half turn. The band's score still uses the goal's own
        heading (the turn still to come counts in its time to go)."""
        d = problem.goal_path - problem.pose0[None, :2]
        return dataclasses.replace(problem, goal_yaw=np.arctan2(d[:, 1], d[:, 0]))

    def _forward_only(self, problem: _Problem) -> np.ndarray:
        """Command lower bounds of a forwards-only band: v >= 0 from the moment the robot can have
        braked to 0 (a robot that is backing up now cannot stop at once)."""
        cfg, M = self.cfg, self.M
        lower = self._u_lo_forward.copy()
        reachable = problem.v_ref + cfg.acc_lim_x * (cfg.control_period + self.h * np.arange(M))
        lower[:M] = np.minimum(0.0, reachable)
        return lower

    def _band(self, problem: _Problem, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The band of the commands ``u``: its poses (N, 3) and each pose's distance from the
        person's predicted position at its time (N,; the clearance of poses 1..M is ``[1:]``), both
        read-only. The bounds, the QP and the band's score each ask for the band of the same
        commands: the last one is kept, keyed on the commands alone (every band of a call starts at
        the same pose against the same person prediction; ``plan`` forgets it at every call), so a
        band is rolled out once, not up to four times."""
        key = u.tobytes()
        if self._last_band is not None and self._last_band[0] == key:
            return self._last_band[1], self._last_band[2]
        poses = rollout(problem.pose0, u[: self.M], u[self.M :], self.h)
        diff = poses[:, :2] - problem.person_path
        distance = np.hypot(diff[:, 0], diff[:, 1])
        poses.flags.writeable = distance.flags.writeable = False
        self._last_band = (key, poses, distance)
        return poses, distance

    def _over_budget(self, t_start: float, iterations: int) -> bool:
        budget = self.cfg.sqp_time_budget
        if budget is None or iterations == 0:
            return False
        spent = time.perf_counter() - t_start
        return spent + spent / iterations > budget

    def _result(self, v, w, status, poses, problem, iterations, t_start, candidate="", tried=()) -> Plan:
        poses = poses.copy()
        poses[:, 2] = wrap_angle(poses[:, 2])
        return Plan(v, w, status, poses, self._times.copy(), problem.person_path.copy(), iterations, time.perf_counter() - t_start,
                    candidate, tried)

    def _stop(self, v_now, w_now, status, t_start, poses=None, problem=None, iterations=0) -> Plan:
        v, w = safe_stop(v_now, w_now, self.cfg)
        if poses is None or problem is None or not np.all(np.isfinite(poses)):
            return Plan(v, w, status, np.zeros((0, 3)), np.zeros(0), np.zeros((0, 2)), iterations, time.perf_counter() - t_start)
        return self._result(v, w, status, poses, problem, iterations, t_start)

    # ------------------------------------------------------------------ the QP
    # Multiple shooting: the QP's variables are the steps of the poses AND of the commands, tied by
    # the linearised kinematics as equality rows, which keeps the QP sparse and well conditioned
    # (condensed to commands only, the Hessian's condition number grows like M^4 and OSQP needs
    # ~1,000 iterations). After each QP only the command step is kept and the poses are rolled out
    # again, so the band always satisfies the kinematics exactly.
    # Variables: [dx_1..dx_M | dy_1..dy_M | dth_1..dth_M | dv_0..dv_{M-1} | dw_0..dw_{M-1} | s_1..s_M]
    # Rows: [0, 3M) kinematics (= 0) | [3M, 5M) command bounds and trust region | [5M, 6M) s >= 0 |
    # [6M, 7M) v changes (acceleration) | [7M, 8M) w changes | [8M, 9M) clearance of pose 1..M.

    def _setup_structure(self) -> None:
        cfg, M, h = self.cfg, self.M, self.h
        self.n, self.m = 6 * M, 9 * M
        n, m = self.n, self.m
        X, Y, TH, V, W, S = (j * M for j in range(6))
        k = np.arange(M)
        self._times = h * np.arange(self.N)
        # tracking weight grows along the band (ramp from weight_track_start to weight_track): the
        # robot is asked to be on the goal's path later, not at once, so it converges smoothly
        ramp = np.linspace(cfg.weight_track_start, 1.0, M)
        track = cfg.weight_track * ramp
        track[-1] += cfg.weight_goal
        self._w_track = np.concatenate([track, track])
        # constant residual rows on the commands: v changes, w changes, w (and the last heading,
        # which is a pose variable here)
        diff = np.eye(M) - np.eye(M, k=-1)
        Jc = np.zeros((3 * M, 2 * M))
        Jc[:M, :M] = diff
        Jc[M : 2 * M, M:] = diff
        Jc[2 * M :, M:] = np.eye(M)
        self._Jc = Jc
        self._w_const = np.concatenate([np.full(M, cfg.weight_acc), np.full(M, cfg.weight_alpha), np.full(M, cfg.weight_turn)])
        P = np.zeros((n, n))
        P[X : X + M, X : X + M] = np.diag(2.0 * track)
        P[Y : Y + M, Y : Y + M] = np.diag(2.0 * track)
        heading = cfg.weight_heading_track * ramp
        heading[-1] += cfg.weight_goal_heading
        self._w_heading = heading
        P[TH + np.arange(M), TH + np.arange(M)] = 2.0 * heading
        P[V : W + M, V : W + M] = 2.0 * Jc.T @ (self._w_const[:, None] * Jc)
        P[np.arange(S), np.arange(S)] += 2.0 * cfg.regularization
        P[S:, S:] += 2.0 * cfg.weight_clearance_slack * np.eye(M)
        # constraints; the kinematics rows' entries that depend on the band are listed in _kin_at
        A = np.zeros((m, n))
        A[X + k, X + k] = A[M + k, Y + k] = A[2 * M + k, TH + k] = 1.0  # pose k+1
        A[X + k[1:], X + k[:-1]] = A[M + k[1:], Y + k[:-1]] = A[2 * M + k[1:], TH + k[:-1]] = -1.0  # pose k
        A[2 * M + k, W + k] = -h
        rows_x, rows_y = X + k, M + k
        self._kin_at = (
            np.concatenate([rows_x, rows_x, rows_y, rows_y, rows_x[1:], rows_y[1:]]),
            np.concatenate([V + k, W + k, V + k, W + k, TH + k[:-1], TH + k[:-1]]),
        )
        A[3 * M + np.arange(2 * M), V + np.arange(2 * M)] = 1.0
        A[5 * M + k, S + k] = 1.0
        A[6 * M : 7 * M, V : V + M] = diff
        A[7 * M : 8 * M, W : W + M] = diff
        A[8 * M + k, S + k] = 1.0
        self._clear_at = (np.concatenate([8 * M + k, 8 * M + k]), np.concatenate([X + k, Y + k]))
        A[self._kin_at] = 1.0  # pattern only
        A[self._clear_at] = 1.0
        P_pat, A_pat = sp.csc_matrix(np.triu(P) != 0), sp.csc_matrix(A != 0)
        A_rows, A_cols = A_pat.indices.copy(), np.repeat(np.arange(n), np.diff(A_pat.indptr))
        P_at = (P_pat.indices.copy(), np.repeat(np.arange(n), np.diff(P_pat.indptr)))
        # where each band-dependent entry sits in A's CSC values: the QP is updated in place
        position = _value_positions((m, n), A_rows, A_cols)
        self._kin_pos, self._clear_pos = position[self._kin_at], position[self._clear_at]
        self._Ax = A[A_rows, A_cols]  # the constant entries; band-dependent ones are set per QP
        # the turn rate's weight prices the rate *sent*: a calibration that scales it by s on its way to
        # the wheels scales the weight by s^2 (``_price_turns``); where its entries sit in P's values
        self._P_turn_pos = _value_positions((n, n), *P_at)[W + k, W + k]
        self._P_values = np.triu(P)[P_at]
        self._qp = SparseQP(n, m, self._P_values, (P_pat.indices, P_pat.indptr), (A_pat.indices, A_pat.indptr),
                            cfg.osqp_eps, cfg.osqp_max_iter, cfg.osqp_rho,
                            cfg.osqp_refine_eps, cfg.osqp_refine_max_iter)
        self._q = np.zeros(n)
        self._q[S:] = cfg.weight_clearance_l1
        self._lo = np.zeros(m)
        self._hi = np.zeros(m)
        self._hi[5 * M : 6 * M] = np.inf
        self._hi[8 * M :] = np.inf
        self._u_lo = np.concatenate([np.full(M, -cfg.max_vel_x_backwards), np.full(M, -cfg.max_vel_theta)])
        self._u_lo_forward = np.concatenate([np.zeros(M), np.full(M, -cfg.max_vel_theta)])  # the "turn" band
        self._u_hi = np.concatenate([np.full(M, cfg.max_vel_x), np.full(M, cfg.max_vel_theta)])
        self._trust = np.concatenate([np.full(M, cfg.trust_region_v), np.full(M, cfg.trust_region_w)])
        self._acc_v = np.full(M, cfg.acc_lim_x * h)
        self._acc_v[0] = cfg.acc_lim_x * cfg.control_period
        self._braking_w = cfg.acc_lim_theta * (cfg.control_period + h * np.arange(M))  # how far |w| can have dropped by segment k
        self._acc_w = np.full(M, cfg.acc_lim_theta * h)
        self._acc_w[0] = cfg.acc_lim_theta * cfg.control_period

    def _price_turns(self, weight: float) -> None:
        """Weigh the band's squared turn rate by ``weight`` (the objective's, the QP's and the
        candidates' score); a function of this call's input only, so no call leaves state behind."""
        turn = self._w_const[2 * self.M :]  # the weight in use: the score's entries, which the QP's P follows
        if turn[0] == weight:
            return
        values = self._P_values.copy()
        values[self._P_turn_pos] += 2.0 * (weight - self.cfg.weight_turn)
        turn[:] = weight
        self._qp.set_P_values(values)

    def _residuals(self, problem: _Problem, u: np.ndarray, poses: np.ndarray):
        """Tracking residuals (2M,), heading errors (M,), and the command residuals (3M,)."""
        M = self.M
        track = (poses[1:, :2] - problem.goal_path).T.ravel()
        v, w = u[:M], u[M:]
        heading = wrap_angle(poses[1:, 2] - problem.goal_yaw)
        const = np.empty(3 * M)  # [v changes | w changes | w], the first change from the current command
        const[:M], const[M : 2 * M], const[2 * M :] = v, w, w
        const[1:M] -= v[:-1]
        const[M + 1 : 2 * M] -= w[:-1]
        const[0] -= problem.v_ref
        const[M] -= problem.w_ref
        return track, heading, const

    def _candidate_score(self, problem: _Problem, u: np.ndarray, poses: np.ndarray, clearance: np.ndarray) -> float:
        """How candidate bands are ranked: the objective's position, command and clearance terms
        over the band (not the headings along it: turning around costs heading on the way), plus
        what the band leaves undone, ``weight_time_to_go`` times the time to cover the remaining
        distance to the goal at the speed the band's last pose allows towards it (forwards if the
        goal is in front of it, backwards otherwise) and to turn to the goal's heading there."""
        cfg = self.cfg
        track, heading, const = self._residuals(problem, u, poses)
        violation = np.maximum(cfg.safety_distance - clearance, 0.0)
        end = poses[-1]
        d = problem.goal_path[-1] - end[:2]
        ahead = math.cos(end[2]) * d[0] + math.sin(end[2]) * d[1]
        speed = cfg.max_vel_x if ahead >= 0.0 else max(cfg.max_vel_x_backwards, 1e-3)
        time_to_go = float(np.hypot(*d)) / speed + abs(float(heading[-1])) / cfg.max_vel_theta
        return float(self._w_track @ track**2 + self._w_const @ const**2 + cfg.weight_clearance_slack * violation @ violation
                     + cfg.weight_clearance_l1 * violation.sum() + cfg.weight_time_to_go * time_to_go)

    def _solve_band(self, problem: _Problem, u: np.ndarray, t_start: float, spent_iterations: int, lower: np.ndarray):
        """SQP from the commands ``u``; returns (u, status, iterations). Converged when no command
        moves more than ``step_tolerance`` in an iteration."""
        cfg = self.cfg
        floor = abs(problem.w_ref) - self._braking_w  # the turn-rate cap never below this (see _bounds)
        u, lo, hi = self._clipped(problem, u, lower, floor)
        done = 0
        for done in range(1, cfg.sqp_iterations + 1):
            if done > 1 and self._over_budget(t_start, spent_iterations + done - 1):
                done -= 1
                break
            step, status = self._sqp_step(problem, u, lo, hi)
            if status != OK:
                return u, status, done
            u, lo, hi = self._clipped(problem, u + step, lower, floor)
            if not np.all(np.isfinite(u)):
                return u, DIVERGED, done
            if float(np.max(np.abs(step))) < cfg.step_tolerance:
                break
        return u, OK, done

    def _clipped(self, problem: _Problem, u: np.ndarray, lower: np.ndarray, floor: np.ndarray):
        """``u`` clipped to its command bounds, and the bounds for the next step: recomputed at the
        clipped commands where clipping changed a v (the turn-rate cap divides by v); where it changed
        only a w, those of ``u``, whose band differs a little from the clipped one's (with
        ``lateral_acc_limit_clear`` the cap also depends on the band's clearance from the person)."""
        M = self.M
        lo, hi = self._bounds(problem, u, lower, floor)
        clipped = np.clip(u, lo, hi)
        if not np.array_equal(clipped[:M], u[:M]):
            lo, hi = self._bounds(problem, clipped, lower, floor)
        return clipped, lo, hi

    def _lateral_limit(self, problem: _Problem, u: np.ndarray):
        """The lateral acceleration |v w| each segment may reach: ``lateral_acc_limit``, or where
        ``lateral_acc_limit_clear`` is set, rising linearly from it (the segment's start pose at the
        safety distance from the person's predicted position) to ``lateral_acc_limit_clear`` over
        the command calibration's turn scale (at ``lateral_acc_ramp`` beyond it; ``plan``'s
        ``command_scale_w``). Near the person a hard turn at speed that the base does not follow
        could cost clearance (measured: a flat 2 m/s^2 let HC come within 0.5 m of the person on
        straight_behind, docs/planner.md, "Turning at speed")."""
        cfg = self.cfg
        if problem.lateral_clear is None:
            return cfg.lateral_acc_limit
        clearance = self._band(problem, u)[1][:-1]  # of each segment's start pose
        share = np.clip((clearance - cfg.safety_distance) / cfg.lateral_acc_ramp, 0.0, 1.0)
        return cfg.lateral_acc_limit + (problem.lateral_clear - cfg.lateral_acc_limit) * share

    def _bounds(self, problem: _Problem, u: np.ndarray, lower: np.ndarray, floor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Command bounds: the velocity limits, and |w| <= the lateral acceleration limit / |v|
        (``_lateral_limit``, evaluated at the current v and band; a fast robot turns gently), never
        tighter than ``floor``, what the angular acceleration limit lets the robot reach from its
        current turn rate."""
        cfg, M = self.cfg, self.M
        cap = np.minimum(cfg.max_vel_theta, self._lateral_limit(problem, u) / np.maximum(np.abs(u[:M]), 1e-6))
        np.maximum(cap, floor, out=cap)
        lo, hi = lower.copy(), self._u_hi.copy()
        np.maximum(lo[M:], -cap, out=lo[M:])
        np.minimum(hi[M:], cap, out=hi[M:])
        return lo, hi

    def _sqp_step(self, problem: _Problem, u: np.ndarray, lower: np.ndarray, upper: np.ndarray):
        cfg, M, h = self.cfg, self.M, self.h
        v, w = u[:M], u[M:]
        poses, distance = self._band(problem, u)
        dist = distance[1:]
        phi = poses[:-1, 2] + 0.5 * h * w
        c, s = np.cos(phi), np.sin(phi)
        hv = h * v
        Ax = self._Ax
        # d/d(v_k, w_k) and d/d(theta_k) of x_{k+1} - x_k - h v_k cos(phi_k) (and y), k >= 1 for theta
        Ax[self._kin_pos] = np.concatenate([
            -h * c, 0.5 * h * hv * s, -h * s, -0.5 * h * hv * c, hv[1:] * s[1:], -hv[1:] * c[1:],
        ])
        normal = (poses[1:, :2] - problem.person_path[1:]) / np.maximum(dist, 1e-9)[:, None]
        Ax[self._clear_pos] = normal.T.ravel()
        q = self._q
        track, heading, const = self._residuals(problem, u, poses)
        q[: 2 * M] = 2.0 * self._w_track * track
        q[2 * M : 3 * M] = 2.0 * self._w_heading * heading
        q[3 * M : 5 * M] = 2.0 * self._Jc.T @ (self._w_const * const)
        lo, hi = self._lo, self._hi
        lo[3 * M : 5 * M] = np.maximum(lower - u, -self._trust)
        hi[3 * M : 5 * M] = np.maximum(np.minimum(upper - u, self._trust), lo[3 * M : 5 * M])
        dv, dw = const[:M], const[M : 2 * M]  # changes of v and w between segments (from the current command)
        lo[6 * M : 7 * M], hi[6 * M : 7 * M] = -self._acc_v - dv, self._acc_v - dv
        lo[7 * M : 8 * M], hi[7 * M : 8 * M] = -self._acc_w - dw, self._acc_w - dw
        # the current commands satisfy the limits up to rounding: never ask for less than nothing
        hi[6 * M : 8 * M] = np.maximum(hi[6 * M : 8 * M], lo[6 * M : 8 * M])
        lo[8 * M :] = cfg.safety_distance - dist
        if not math.isfinite(float(Ax.sum()) + float(q.sum()) + float(lo.sum())):  # a NaN or inf anywhere
            return None, DIVERGED
        status = self._qp.solve(Ax, q, lo, hi)
        if status == PRIMAL_INFEASIBLE:
            return None, INFEASIBLE
        if status != SOLVED:
            return None, SOLVER_ERROR
        return self._qp.x[3 * M : 5 * M], OK
