"""lbgp.parallel: worker pools that do not hang after torch has run in the parent."""

import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent("""
    import sys
    import torch
    from lbgp.parallel import process_pool

    def backward(i):
        x = torch.randn(256, 256, requires_grad=True)
        (x @ x).sum().backward()
        return i

    if __name__ == "__main__":
        torch.set_num_threads(2)
        x = torch.randn(512, 512, requires_grad=True)
        for _ in range(5):  # the parent's autograd engine and intra-op threads have run
            (x @ x).relu().sum().backward()
        with process_pool(2) as pool:
            print("done", sorted(pool.map(backward, range(4))))
""")


def test_workers_using_torch_finish_after_the_parent_used_torch(tmp_path):
    """With forked workers this script never finishes (measured: killed after 30 s); the pool's
    spawned workers finish it. Bounded: the subprocess is killed after 120 s (the test then fails)."""
    script = tmp_path / "pool_after_torch.py"
    script.write_text(SCRIPT)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().endswith("done [0, 1, 2, 3]")


def test_the_pool_has_at_least_one_worker():
    from lbgp.parallel import process_pool

    with process_pool(0) as pool:
        assert pool._max_workers == 1
        assert list(pool.map(abs, [-2, 3])) == [2, 3]
