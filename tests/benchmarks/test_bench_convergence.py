"""Issue 6, targets 4 and 6: convergence studies in parallel through any Executor, and in bounded memory.

* Target 4: the grids of a study run as parallel jobs through any ``concurrent.futures.Executor`` —
  verimono's own process pool (forked workers: the catalog's lambdas and closures need no pickling), a
  user's ``ProcessPoolExecutor`` (problems travel by pickle, by catalog name, or by cloudpickle), threads,
  and ``dask.distributed``'s ``Client.get_executor()`` (tested when dask is installed) — with results
  identical to the serial study.  Timed: the process pool against the serial study on the same 2 cores.
* Target 6: a 10^6-step, n = 10 study holds no trajectory: with an exact solution each job streams its
  states through an error accumulator.  Peak traced memory (tracemalloc) of the whole study, run
  serially in-process (one worker), against the bare baseline of allocating one (10^6+1) × 10 trajectory.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

import verimono as vm
from verimono.core.convergence import convergence_study
from verimono.run.performance import check_memory
from verimono.reference import get, subdifferential


def _same(a, b):
    return a.errors == b.errors and a.steps == b.steps and a.order.slope == b.order.slope


@pytest.mark.parametrize("name", ["t|x| (n=3)", "moving box", "translating ball", "Lipschitz field and input"])
def test_executors_give_the_serial_results(name):
    p = get(name)  # built from lambdas and closures
    serial = convergence_study(vm.solve, p, executor="serial")
    assert _same(serial, convergence_study(vm.solve, p, executor="process"))
    with ProcessPoolExecutor(2) as ex:
        assert _same(serial, convergence_study(vm.solve, p, executor=ex))
    with ThreadPoolExecutor(2) as ex:
        assert _same(serial, convergence_study(vm.solve, p, executor=ex))


def test_a_problem_travels_with_its_captured_parameters():
    """log_barrier(c) captures c in closures; a study of it through a user's process pool is the serial
    study of the same c (an earlier version sent catalog problems by name, and the worker rebuilt c = 1:
    errors 0.0414 instead of 0.0828 at c = 4)."""
    p = subdifferential.log_barrier(4.0)
    serial = convergence_study(vm.solve, p, p.steps[:3], executor="serial")
    assert serial.errors != convergence_study(vm.solve, subdifferential.log_barrier(1.0), p.steps[:3],
                                              executor="serial").errors
    with ProcessPoolExecutor(1) as ex:
        assert _same(serial, convergence_study(vm.solve, p, p.steps[:3], executor=ex))


def test_an_object_cloudpickle_cannot_send_is_a_clear_error():
    import threading

    p = get("moving box")
    lock = threading.Lock()                      # neither pickle nor cloudpickle serialise a lock
    mine = vm.Problem(p.operator, p.x0, p.T, exact=lambda t: (lock, p.exact(t))[1], name="holds a lock")
    with ProcessPoolExecutor(1) as ex, pytest.raises(vm.InvalidProblem, match="cannot send"):
        convergence_study(vm.solve, mine, p.steps[:2], executor=ex)


def test_fine_grid_reference_runs_as_a_job_too():
    p = vm.Problem(vm.Linear([[2.0, 1.0], [-1.0, 0.5]]), [1.0, 1.0], 1.0)
    a = convergence_study(vm.solve, p, [0.1, 0.05, 0.025], executor="serial")
    b = convergence_study(vm.solve, p, [0.1, 0.05, 0.025], executor="process")
    assert _same(a, b) and "fine-grid" in b.reference


def test_dask_distributed_executor():
    distributed = pytest.importorskip("distributed", reason="dask.distributed is not installed (optional: "
                                      "pip install 'dask[distributed]' to run studies on a cluster)")
    p = get("t|x| (n=3)")
    serial = convergence_study(vm.solve, p, executor="serial")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl, \
            distributed.Client(cl) as client:
        assert _same(serial, convergence_study(vm.solve, p, executor=client.get_executor()))


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="a parallel speed-up needs at least 2 cores")
def test_parallel_study_speedup(gate):
    p = subdifferential.t_norm(np.linspace(0.2, 1.0, 3) / np.linalg.norm(np.linspace(0.2, 1.0, 3)))
    K = gate.size(200_000, 20_000)
    steps = [p.T / k for k in (K // 4, K // 2, K // 2 + 2, K)]  # two balanced halves for two workers
    gate.benchmark.extra_info.update({"steps": [int(round(p.T / h)) for h in steps], "workers": os.cpu_count()})
    # parallel wall time vs serial wall time: the pool must pay for itself — a speed-up can only show
    # on cores that are not busy with other work, so on a loaded machine the ratio is recorded, not gated
    cores = os.cpu_count() or 1
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
    gate.benchmark.extra_info["loadavg_1min"] = load
    busy = load > 0.5 * cores
    try:
        gate.measure(lambda: convergence_study(vm.solve, p, steps, executor="process"),
                     lambda: convergence_study(vm.solve, p, steps, executor="serial"),
                     target=1.0 if busy else 1.25, lower_is_better=False, rounds=3, rounds_disabled=1)
    except AssertionError:
        if busy:
            pytest.skip(f"machine busy (load {load:.1f} on {cores} cores): speed-up "
                        f"{gate.benchmark.extra_info['ratio']:.2f} recorded, not gated")
        raise


def test_streaming_study_memory(gate):
    """Peak traced memory of a 10^6-step, n = 10 study over the bytes of one trajectory (target ≤ 1)."""
    rec = check_memory(steps=gate.size(1_000_000, 100_000))
    gate.benchmark.pedantic(lambda: None, rounds=1, iterations=1)  # the figure is memory, not time
    gate.check(rec, sanity=False)  # memory is not noisy: the real target in every run
    assert rec.details["study_ok"]


INPUTS = {"u (Gauss-Legendre)": dict(u=lambda t: np.array([math.cos(t), 0.0, 0.0])),
          "U (antiderivative)": dict(U=lambda t: np.array([math.sin(t), 0.0, t * t]))}
X0 = {"single": [1.0, 2.0, 3.0], "batch": [[1.0, 2.0, 3.0], [-0.5, 0.0, 0.25]]}


@pytest.mark.parametrize("x0", list(X0), ids=list(X0))
@pytest.mark.parametrize("given", list(INPUTS), ids=list(INPUTS))
@pytest.mark.parametrize("block", [2, 3, 64, 10_000])
def test_stream_pieces_are_the_solve_trajectory(block, given, x0):
    from verimono.core.stepping import stream

    p = vm.Problem(vm.NormSubdifferential(lambda t: 0.1 + t, dim=3), X0[x0], 1.0,
                   f=lambda x: -0.5 * x, **INPUTS[given])
    t = vm.random_grid(1.0, 777, seed=2)
    pieces = [(tb.copy(), xb.copy()) for tb, xb in stream(p, t, block=block)]
    assert all(len(tb) <= block for tb, _ in pieces)
    assert np.array_equal(np.concatenate([tb for tb, _ in pieces]), t)
    assert np.array_equal(np.concatenate([xb for _, xb in pieces]), vm.solve(p, t).x)


def test_stream_with_an_input_holds_one_block_of_increments():
    """The input increments ∫u are computed block by block: doubling the steps of a streamed n = 10 solve
    adds grid-sized arrays only (the validated grid and its steps: ≤ 3 floats per step), never a (K, n)
    array of increments (10 floats per step; it added 100 MiB at 2·10^5 steps before)."""
    import tracemalloc

    n = 10
    p = vm.Problem(vm.NormSubdifferential(1.0, dim=n), np.ones(n), 1.0, u=lambda t: np.full(n, math.cos(t)))

    def peak(K):
        t = vm.uniform_grid(1.0, steps=K)
        tracemalloc.start()
        try:
            for _ in vm.stream(p, t):
                pass
            return tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()

    K = 100_000
    growth = peak(2 * K) - peak(K)
    assert growth <= 3 * 8 * K, f"peak grew by {growth / K:.1f} bytes per added step"
