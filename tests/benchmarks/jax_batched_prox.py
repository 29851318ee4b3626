"""Benchmark (not a test): ``check_operator`` of a jitted, vmapped JAX prox at n = 100 (issue 23: ≤ 5 s).

    OPENBLAS_NUM_THREADS=1 python tests/benchmarks/jax_batched_prox.py [n] [profile]

Prints the load average, the wall and CPU time of one warm-up run (JIT compilation included) and of the
median of three measured runs at the given profile (default ``ci``), and the prox's calls and rows.  Needs
JAX and jaxopt (``pip install 'verimono[arrays]'``).  The figure is quoted in docs/prox-libraries.md.
"""

from __future__ import annotations

import os
import statistics
import sys
import time


def main(n: int = 100, profile: str = "ci") -> None:
    os.environ["HYPOTHESIS_PROFILE"] = profile
    import jax
    import jax.numpy as jnp
    from jaxopt.prox import prox_lasso

    import verimono as vm

    calls = {"calls": 0, "rows": 0}
    kernel = jax.jit(jax.vmap(lambda x, scaling: prox_lasso(x, 2.0, scaling)))

    def prox(X, scaling):
        calls["calls"] += 1
        calls["rows"] += X.shape[0]
        return kernel(X, scaling)
    value = jax.jit(lambda x: 2.0 * jnp.sum(jnp.abs(x)))
    op = vm.operator_from_prox(prox, step="scaling", batched=True, value=value, shape=n,
                               name=f"jaxopt lasso, jitted and vmapped, n={n}")

    def run(seed):
        w, c = time.perf_counter(), time.process_time()
        rep = vm.check_operator(op, seed=seed)
        return time.perf_counter() - w, time.process_time() - c, rep

    print(f"load average before: {os.getloadavg()}")
    wall, cpu, rep = run(0)
    print(f"warm-up (JIT compilation included): wall {wall:.2f} s, CPU {cpu:.2f} s; {rep.counts}; "
          f"dtypes {sorted({str(r.details.get('dtype')) for r in rep})}")
    for r in rep.failures:
        print("  FAILED", r.check, r.message[:200])
    calls.update(calls=0, rows=0)
    runs = [run(seed)[:2] for seed in (1, 2, 3)]
    print(f"measured (seeds 1-3, median): wall {statistics.median(r[0] for r in runs):.2f} s, "
          f"CPU {statistics.median(r[1] for r in runs):.2f} s; prox calls {calls['calls'] / 3:.0f}, "
          f"rows {calls['rows'] / 3:.0f} per check_operator")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main(*(int(a) if i == 0 else a for i, a in enumerate(sys.argv[1:])))
