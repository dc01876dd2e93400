"""Worker processes that are safe to start from any lbgp process.

A forked child gets a copy of the parent's memory, locks included, but none of its threads. Once
torch has run in the parent (its intra-op thread pool, the autograd engine), a forked worker that
uses torch can wait forever on a lock that no thread is left to release: measured, a parent that
ran five backward passes and then forked two workers that each ran one never finished (killed after 30 s;
``tests/test_parallel.py``), and ``benchmarks/ablation_scenarios.py`` hung the same way inside a
test session. Every pool of lbgp's commands and benchmarks therefore starts its workers with
``spawn``: a fresh interpreter that imports what it needs (about a second or two per worker). The
work function must be importable (a module-level function); the spawned worker gets the parent's
``sys.path``.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing


def process_pool(workers: int) -> concurrent.futures.ProcessPoolExecutor:
    """A ``ProcessPoolExecutor`` of ``workers`` (at least 1) spawned processes."""
    return concurrent.futures.ProcessPoolExecutor(max_workers=max(1, int(workers)),
                                                  mp_context=multiprocessing.get_context("spawn"))
