"""Every lbgp process runs BLAS on one thread (the planner issue: oversubscribed cores)."""

import os
import subprocess
import sys

import pytest

SCRIPT = """
import numpy  # loaded before lbgp: only threadpoolctl can limit it now
import lbgp
from threadpoolctl import threadpool_info
print(max(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"))
"""


@pytest.mark.parametrize("env_value,expected", [(None, "1"), ("2", "2")])
def test_blas_is_pinned_even_when_numpy_was_imported_first(env_value, expected):
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")}
    if env_value is not None:
        env["LBGP_BLAS_THREADS"] = env_value
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == expected
