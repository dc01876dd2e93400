"""One QP of fixed sparsity, solved again and again with OSQP: set up once, then only values change.

The planner solves ~5 small QPs (~110 variables) per call, so the per-solve overhead of OSQP's
Python interface (bound clipping, a copy of every matrix for its derivative cache, a namespace
built from all solver info fields) costs as much as the solve itself. ``SparseQP`` sets the solver
up through the public interface and then talks to the compiled solver object directly: one
``update_data_vec``, one ``update_data_mat`` (values only, the pattern never changes), one
``solve``. ``tests/test_planner_qp.py`` checks it against the public interface.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import osqp
import scipy.sparse as sp

SOLVED = "solved"
PRIMAL_INFEASIBLE = "primal_infeasible"
FAILED = "failed"

RESCUE_RHO_INTERVAL = 25  # ADMM iterations between step-size updates in a rescue solve (OSQP's default here: 50)
_SOLVED = {osqp.SolverStatus.OSQP_SOLVED, osqp.SolverStatus.OSQP_SOLVED_INACCURATE}
_INFEASIBLE = {osqp.SolverStatus.OSQP_PRIMAL_INFEASIBLE, osqp.SolverStatus.OSQP_PRIMAL_INFEASIBLE_INACCURATE}


@dataclasses.dataclass
class QPStats:
    """Counts over every solve: ADMM iterations, iteration-cap hits, inaccurate solutions, and
    solutions whose active set polishing did not confirm (accurate to eps only)."""

    solves: int = 0
    osqp_iterations: int = 0
    max_iter_hits: int = 0
    inaccurate: int = 0
    unpolished: int = 0  # after the refinement pass, where one ran
    rescues: int = 0  # solves that hit the cap, solved again by a fresh solver (``SparseQP._rescue``)
    rescue_failures: int = 0  # ... which did not solve it either (the solve failed)
    refined: int = 0  # solves that polishing did not confirm, continued to ``refine_eps``
    refine_capped: int = 0  # ... whose refinement stopped at its cap (OSQP: "solved inaccurate", or not solved but
    # with smaller residuals than the first pass); the iterate is kept
    refine_fallbacks: int = 0  # ... whose refinement failed or stopped at its cap no better (the first pass's solution kept)
    solver_seconds: float = 0.0  # wall time inside OSQP's compiled calls (set-up, update, solve, rescue, refinement)
    # ... of which: the value updates (update_data_mat refactorises the KKT matrix), polishing (OSQP's own clock),
    # and the refinement passes (their ADMM iterations are also counted apart)
    update_seconds: float = 0.0
    polish_seconds: float = 0.0
    refine_seconds: float = 0.0
    refine_iterations: int = 0

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


class SparseQP:
    """minimize 1/2 x'Px + q'x  subject to  l <= Ax <= u, with P (upper triangle) and A of a fixed
    pattern given once as CSC ``(indices, indptr)``; ``solve`` takes the new values of A (in the
    pattern's order), q, l and u. OSQP warm-starts from the previous solution until ``restart``
    (only iterations change: every solve runs to ``eps`` and is then polished). With ``refine_eps``,
    a solution whose polishing failed is continued to that tolerance and polished again (at most
    ``refine_max_iter`` more iterations; at the cap the iterate with the smaller residuals stands)."""

    def __init__(self, n: int, m: int, P_values: np.ndarray, P_pattern, A_pattern, eps: float, max_iter: int,
                 rho: float = 0.1, refine_eps: float | None = None, refine_max_iter: int = 1000):
        self.n, self.m = n, m
        self._P = sp.csc_matrix((np.array(P_values, dtype=float), *P_pattern), shape=(n, n))  # a copy: set_P_values writes into it
        self._A_pattern = A_pattern
        self._rho = rho  # the initial step size, set explicitly so that restart() can return to it
        self._settings = dict(verbose=False, polishing=True, warm_starting=True, eps_abs=eps, eps_rel=eps, max_iter=max_iter,
                              rho=self._rho)
        # a solve whose active set polishing did not confirm continues (warm) to refine_eps and is
        # polished again; if that pass hits its cap, the iterate with the smaller residuals stands
        self._refine_eps, self._refine_max_iter = refine_eps, refine_max_iter
        self._solver = None
        self._P_pending = False  # P's values changed since the solver last saw them
        self._infinity = 1e30  # OSQP_INFTY: bounds beyond it are infinite
        self.stats = QPStats()
        self.x = np.zeros(n)

    def reset(self) -> None:
        """Forget the warm start (the next solve sets OSQP up again)."""
        self._solver = None
        self._P_pending = False

    def restart(self) -> None:
        """Start the next solve as a fresh solver would: from x = y = 0 with the initial rho (OSQP
        adapts rho from solve to solve, and scales each problem from its own data). A sequence of
        solves after ``restart`` then agrees with a fresh solver's to about its precision (the
        planner's property test: 998 of 1,000 random calls within 1e-6, all within 0.05 m/s and
        0.1 rad/s), whatever was solved before."""
        if self._solver is not None:
            self._solver.warm_start(x=np.zeros(self.n), y=np.zeros(self.m))
            self._solver.update_rho(self._rho)

    def set_P_values(self, P_values: np.ndarray) -> None:
        """New values of P (the pattern's order), used from the next solve on."""
        self._P.data[:] = P_values
        self._P_pending = self._solver is not None

    def solve(self, A_values: np.ndarray, q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> str:
        """Solve with these values; returns ``solved`` (``x`` holds the solution),
        ``primal_infeasible`` or ``failed``."""
        lower = np.maximum(lower, -self._infinity)
        upper = np.minimum(upper, self._infinity)
        t_start = time.perf_counter()
        if self._solver is None:
            wrapper = osqp.OSQP()
            wrapper.setup(self._P, q, sp.csc_matrix((A_values, *self._A_pattern), shape=(self.m, self.n)), lower, upper,
                          **self._settings)
            self._wrapper = wrapper  # keeps the compiled solver's owner alive
            self._solver = wrapper._solver
        else:
            self._solver.update_data_vec(q=q, l=lower, u=upper)
            self._solver.update_data_mat(P_x=self._P.data if self._P_pending else None, P_i=None, A_x=A_values, A_i=None)
            self._P_pending = False
            self.stats.update_seconds += time.perf_counter() - t_start
        self._solver.solve()
        stats = self.stats
        stats.solver_seconds += time.perf_counter() - t_start
        stats.solves += 1
        info = self._solver.info
        stats.osqp_iterations += int(info.iter)
        stats.polish_seconds += float(info.polish_time)
        wrapper = self._wrapper
        if info.status_val == osqp.SolverStatus.OSQP_MAX_ITER_REACHED:
            stats.max_iter_hits += 1
            wrapper = self._rescue(A_values, q, lower, upper)
        status = self._accept(wrapper)
        if wrapper is not self._wrapper and status == SOLVED:  # the main solver goes on from the rescue's solution
            self._solver.warm_start(x=self.x, y=np.array(wrapper._solver.solution.y, dtype=float))
        return status

    def _rescue(self, A_values, q, lower, upper):
        """The iteration cap was hit (rare: ADMM's step size can cycle on a badly conditioned QP).
        The same QP is solved once more by a fresh solver that adapts its step size twice as often
        (``RESCUE_RHO_INTERVAL``); returns that solver, whose outcome counts instead."""
        self.stats.rescues += 1
        t_start = time.perf_counter()
        rescue = osqp.OSQP()
        rescue.setup(self._P, q, sp.csc_matrix((A_values, *self._A_pattern), shape=(self.m, self.n)), lower, upper,
                     **dict(self._settings, adaptive_rho_interval=RESCUE_RHO_INTERVAL))
        rescue._solver.solve()
        self.stats.solver_seconds += time.perf_counter() - t_start
        self.stats.osqp_iterations += int(rescue._solver.info.iter)
        if rescue._solver.info.status_val not in _SOLVED:
            self.stats.rescue_failures += 1
        return rescue

    def _accept(self, wrapper) -> str:
        """Read the solve's outcome off ``wrapper``'s solver into ``x`` (refined where asked); the status."""
        info = wrapper._solver.info
        status = info.status_val
        stats = self.stats
        if status == osqp.SolverStatus.OSQP_SOLVED_INACCURATE:
            stats.inaccurate += 1
        refine = info.status_polish != 1 and self._refine_eps is not None and status in _SOLVED
        if info.status_polish != 1 and not refine:
            stats.unpolished += 1
        if status in _INFEASIBLE:
            return PRIMAL_INFEASIBLE
        if status not in _SOLVED:
            return FAILED
        self.x = np.array(wrapper._solver.solution.x, dtype=float)
        if refine:
            self._refine(wrapper)
        if not np.all(np.isfinite(self.x)):
            return FAILED
        return SOLVED

    def _refine(self, wrapper) -> None:
        stats = self.stats
        stats.refined += 1
        solver = wrapper._solver
        first_residual = max(solver.info.prim_res, solver.info.dual_res)
        wrapper.update_settings(eps_abs=self._refine_eps, eps_rel=self._refine_eps, max_iter=self._refine_max_iter)
        try:
            t_start = time.perf_counter()
            solver.solve()  # from the first pass's iterate
            elapsed = time.perf_counter() - t_start
            stats.solver_seconds += elapsed
            stats.refine_seconds += elapsed
            info = solver.info
            stats.osqp_iterations += int(info.iter)
            stats.refine_iterations += int(info.iter)
            stats.polish_seconds += float(info.polish_time)
            if info.status_val in _SOLVED:
                x = np.array(solver.solution.x, dtype=float)
                if np.all(np.isfinite(x)):
                    self.x = x
                stats.unpolished += info.status_polish != 1
                # at its iteration cap OSQP reports "solved inaccurate" where the residuals are within 10x eps
                stats.refine_capped += info.status_val == osqp.SolverStatus.OSQP_SOLVED_INACCURATE
            elif (info.status_val == osqp.SolverStatus.OSQP_MAX_ITER_REACHED
                  and max(info.prim_res, info.dual_res) < first_residual
                  and np.all(np.isfinite(x := np.array(solver.solution.x, dtype=float)))):
                # stopped at the cap, but closer to optimal than the first pass: the better iterate stands
                self.x = x
                stats.refine_capped += 1
                stats.unpolished += 1
            else:
                stats.refine_fallbacks += 1
                stats.unpolished += 1
        finally:
            settings = self._settings
            wrapper.update_settings(eps_abs=settings["eps_abs"], eps_rel=settings["eps_rel"], max_iter=settings["max_iter"])
