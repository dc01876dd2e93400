"""SparseQP (the planner's direct use of the compiled OSQP solver) against OSQP's public interface."""

from pathlib import Path

import numpy as np
import osqp
import scipy.sparse as sp

from lbgp.planner.qp import FAILED, PRIMAL_INFEASIBLE, SOLVED, SparseQP


def random_problem(rng, n=12, m=18):
    """A strictly convex QP with a fixed sparsity pattern (box rows plus random sparse rows)."""
    L = sp.random(n, n, density=0.3, random_state=rng) + sp.eye(n)
    P = sp.csc_matrix(sp.triu(L @ L.T))
    pattern = sp.vstack([sp.eye(n), sp.random(m - n, n, density=0.4, random_state=rng) + sp.eye(m - n, n)]).tocsc()
    pattern.data[:] = 1.0
    return P, pattern


def values(rng, pattern, n, m):
    A = pattern.copy()
    A.data = rng.normal(size=A.nnz)
    q = rng.normal(size=n)
    lower = -1.0 - rng.uniform(size=m)
    upper = 1.0 + rng.uniform(size=m)
    lower[: n // 2] = -np.inf
    return A, q, lower, upper


def test_sequence_of_solves_matches_the_public_interface():
    rng = np.random.default_rng(0)
    n, m = 12, 18
    P, pattern = random_problem(rng, n, m)
    qp = SparseQP(n, m, P.data, (P.indices, P.indptr), (pattern.indices, pattern.indptr), eps=1e-8, max_iter=20000)
    for _ in range(6):
        A, q, lower, upper = values(rng, pattern, n, m)
        assert qp.solve(A.data, q, lower, upper) == SOLVED
        reference = osqp.OSQP()
        reference.setup(P, q, A, lower, upper, verbose=False, eps_abs=1e-10, eps_rel=1e-10, max_iter=100000, polishing=True)
        x = reference.solve(raise_error=False).x
        np.testing.assert_allclose(qp.x, x, atol=1e-6)
    assert qp.stats.solves == 6 and qp.stats.osqp_iterations > 0 and qp.stats.max_iter_hits == 0


def test_time_inside_osqp_is_counted_and_is_part_of_the_solve_time():
    """``stats.solver_seconds`` adds up the time inside OSQP's compiled calls: it grows with every
    solve and never exceeds the wall time of the solves around it."""
    import time

    rng = np.random.default_rng(1)
    n, m = 12, 18
    P, pattern = random_problem(rng, n, m)
    qp = SparseQP(n, m, P.data, (P.indices, P.indptr), (pattern.indices, pattern.indptr), eps=1e-8, max_iter=20000)
    counted = []
    t0 = time.perf_counter()
    for _ in range(3):
        A, q, lower, upper = values(rng, pattern, n, m)
        assert qp.solve(A.data, q, lower, upper) == SOLVED
        counted.append(qp.stats.solver_seconds)
    elapsed = time.perf_counter() - t0
    assert 0.0 < counted[0] < counted[1] < counted[2] <= elapsed
    # its parts: the value updates (every solve after the set-up), polishing (on for every solve), refinement
    stats = qp.stats
    assert stats.update_seconds > 0.0 and stats.polish_seconds > 0.0 and stats.refine_seconds >= 0.0
    assert stats.update_seconds + stats.polish_seconds + stats.refine_seconds <= stats.solver_seconds
    assert 0 <= stats.refine_iterations <= stats.osqp_iterations


def test_infeasible_and_capped_problems_say_so():
    rng = np.random.default_rng(1)
    n, m = 12, 18
    P, pattern = random_problem(rng, n, m)
    qp = SparseQP(n, m, P.data, (P.indices, P.indptr), (pattern.indices, pattern.indptr), eps=1e-8, max_iter=20000)
    A, q, lower, upper = values(rng, pattern, n, m)
    rows, cols = A.indices, np.repeat(np.arange(n), np.diff(A.indptr))
    A.data[rows == 0] = 1.0  # row 0: x_0 = 2
    lower[0] = upper[0] = 2.0
    A.data[rows == n] = np.where(cols[rows == n] == 0, 1.0, 0.0)  # row n: x_0 <= 1
    lower[n], upper[n] = -1.0, 1.0
    assert qp.solve(A.data, q, lower, upper) == PRIMAL_INFEASIBLE
    capped = SparseQP(n, m, P.data, (P.indices, P.indptr), (pattern.indices, pattern.indptr), eps=1e-12, max_iter=1)
    A, q, lower, upper = values(rng, pattern, n, m)
    assert capped.solve(A.data, q, lower, upper) == FAILED
    assert capped.stats.max_iter_hits == 1


def test_restart_returns_to_the_configured_initial_rho():
    """``rho`` reaches OSQP at setup and at every ``restart``: after other solves, a restarted solver
    repeats its first solve iteration for iteration, and another rho takes another path."""
    rng = np.random.default_rng(2)
    n, m = 12, 18
    P, pattern = random_problem(rng, n, m)
    first, second = values(rng, pattern, n, m), values(rng, pattern, n, m)

    def iterations(rho):
        qp = SparseQP(n, m, P.data, (P.indices, P.indptr), (pattern.indices, pattern.indptr), eps=1e-7, max_iter=20000, rho=rho)
        counts = []
        for A, q, lower, upper in (first, second, first):
            before = qp.stats.osqp_iterations
            qp.restart()
            assert qp.solve(A.data, q, lower, upper) == SOLVED
            counts.append(qp.stats.osqp_iterations - before)
        return counts

    fast, slow = iterations(0.1), iterations(0.001)
    assert fast[0] == fast[2] and slow[0] == slow[2]
    assert fast[0] != slow[0]


def test_refinement_makes_unpolished_solutions_accurate():
    """A solve that polishing could not confirm is continued to ``refine_eps`` (counted as refined);
    polished solves are left alone. Without refinement such solutions are accurate to eps only."""
    rng = np.random.default_rng(3)
    n, m = 12, 18
    P, pattern = random_problem(rng, n, m)
    plain = SparseQP(n, m, P.data, (P.indices, P.indptr), (pattern.indices, pattern.indptr), eps=1e-2, max_iter=20000)
    refined = SparseQP(n, m, P.data, (P.indices, P.indptr), (pattern.indices, pattern.indptr), eps=1e-2, max_iter=20000,
                       refine_eps=1e-8, refine_max_iter=20000)
    errors_plain, errors_refined = [], []
    for _ in range(60):
        A, q, lower, upper = values(rng, pattern, n, m)
        reference = osqp.OSQP()
        reference.setup(P, q, A, lower, upper, verbose=False, eps_abs=1e-10, eps_rel=1e-10, max_iter=100000, polishing=True)
        x = reference.solve(raise_error=False).x
        for qp, errors in ((plain, errors_plain), (refined, errors_refined)):
            unpolished = qp.stats.unpolished + qp.stats.refined
            qp.restart()
            assert qp.solve(A.data, q, lower, upper) == SOLVED
            if qp.stats.unpolished + qp.stats.refined > unpolished:  # this one was not confirmed by polishing
                errors.append(np.max(np.abs(qp.x - x)))
    assert plain.stats.unpolished >= 2 and refined.stats.refined == plain.stats.unpolished
    assert refined.stats.refine_fallbacks == 0
    assert max(errors_refined) < 1e-5 < max(errors_plain)


def test_a_stalled_solve_is_rescued_by_a_fresh_solver():
    """A QP recorded from the planner (Jackal, N = 20, a turn-around band) on which OSQP's ADMM
    stalls: 4,000 iterations without reaching eps 1e-3 from a fresh start with the planner's
    settings. ``SparseQP`` counts the cap hit and solves it again with a solver that adapts its step
    size more often; the answer is polished and feasible. Without the rescue the solve fails."""
    d = np.load(Path(__file__).parent / "data" / "planner_stalling_qp.npz")
    m, n = len(d["lower"]), len(d["q"])
    args = (n, m, d["P_data"], (d["P_indices"], d["P_indptr"]), (d["A_indices"], d["A_indptr"]))
    A = sp.csc_matrix((d["A_data"], d["A_indices"], d["A_indptr"]), shape=(m, n))

    qp = SparseQP(*args, eps=1e-3, max_iter=4000, rho=0.1)
    assert qp.solve(d["A_data"], d["q"], d["lower"], d["upper"]) == SOLVED
    assert qp.stats.max_iter_hits == 1 and qp.stats.rescues == 1 and qp.stats.rescue_failures == 0
    assert qp.stats.unpolished == 0  # the rescue's answer was confirmed by polishing
    Ax = A @ qp.x
    assert np.all(Ax >= d["lower"] - 1e-6) and np.all(Ax <= d["upper"] + 1e-6)

    plain = SparseQP(*args, eps=1e-3, max_iter=4000, rho=0.1)
    plain._rescue = lambda *a: plain._wrapper  # the capped first pass stands
    assert plain.solve(d["A_data"], d["q"], d["lower"], d["upper"]) == FAILED
