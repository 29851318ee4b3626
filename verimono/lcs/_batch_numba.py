"""The compiled batch kernel of :meth:`verimono.lcs.kernel.StepKernel.run_batch` (optional: needs ``numba``,
``pip install verimono[fast]``; used only when a batch runs with it, never imported by ``import verimono``).

:func:`load` returns ``advance(...)``, which steps every live row of a batch from step ``k0``, step by step (all
rows at step ``k`` before step ``k + 1``), doing for each row what the NumPy kernel does with whole columns,
**in the same order and with the same IEEE operations**: its pattern's candidate ``y = c + a_0 x_0 + … +
a_{n−1} x_{n−1} + b_0 e_0 + …`` (summed left to right, a multiply then an add: numba's default
``fastmath=False`` contracts nothing into a fused multiply-add), ``τ = ra·max_j |x_j| + re·em + rb`` and its
test (every sign row ``> τ``, every step row finite); when it fails, the patterns the violated signs point to
(at most ``m`` in turn), then — for few patterns — every pattern in ``itertools.product`` order.  So its states
and outputs are bit-identical to the NumPy kernel's and to single runs (``tests/lcs/test_lcs_batch_kernel.py``).

A row whose step needs a pattern not built yet (its map's LU and check are Python's), or none of whose
candidates passes (a degenerate step, the solver), is left to Python: ``need[i]`` is set, the row's state at
``k + 1``, its outputs at ``k`` and ``pid[i]`` are not touched, and ``advance`` returns ``k`` once the other rows
have made step ``k``.  ``badk[i]`` (``K`` when none) is the first step at which row ``i``'s multiplier or output,
as this kernel made it, is not finite.  ``table[code]`` (``code = Σ s_i 3^i``) is a pattern's id, −1 for an unusable pattern
(:meth:`StepKernel.pattern` returned None), −2 for one not built yet.

The row's usual step (its pattern's candidate passes) is straight-line code generated for the shapes ``(n, L,
L + 2m, ne)`` — the rows in scalars, not in an array: 4× faster than loops over a buffer (21 against 82 ns per
trajectory-step on DiodeBridge).  numba caches compiled code by source file, so the generated module is written
to a file named by the hash of its source, in ``VERIMONO_NUMBA_DIR`` or ``~/.cache/verimono/numba`` (else a
temporary directory), and compiled with ``cache=True``: a process compiles a shape once per machine
(seconds), later processes load it.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile

_HELPERS = '''\
import numpy as np
from numba import njit


@njit(cache=True, nogil=True, boundscheck=False)
def _rows(st, p, XA, k, i, E, ii, n, ne, y, r0, r1):
    x0 = XA[k, 0, i]
    for r in range(r0, r1):
        y[r] = st[p, 0, r] + st[p, 1, r] * x0
    for j in range(1, n):
        xj = XA[k, j, i]
        for r in range(r0, r1):
            y[r] = y[r] + st[p, 1 + j, r] * xj
    for j in range(ne):
        ej = E[k, ii, j]
        for r in range(r0, r1):
            y[r] = y[r] + st[p, 1 + n + j, r] * ej


@njit(cache=True, nogil=True, boundscheck=False)
def _passes(mg, p, XA, k, i, EM, ii, n, L, ne, y):
    a = abs(XA[k, 0, i])
    for j in range(1, n):
        b = abs(XA[k, j, i])
        if b > a or b != b:
            a = b
    tau = a * mg[p, 0]
    if ne:
        tau = tau + mg[p, 1] * EM[k, ii]
    tau = tau + mg[p, 2]
    inf = np.inf
    for r in range(n):
        if not (y[r] > -inf and y[r] < inf):
            return False
    for r in range(n, L):
        if not (y[r] > tau and y[r] < inf):
            return False
    return True


@njit(cache=True, nogil=True, boundscheck=False)
def _flip(s, pstate, pcomp, pnew, p, y, n, L):
    for c in range(s.size):
        s[c] = pstate[p, c]
    for r in range(L - n):
        if y[n + r] <= 0.0:
            s[pcomp[p, r]] = pnew[p, r]


@njit(cache=True, nogil=True, boundscheck=False)
def _settle(st, mg, table, enum_codes, pstate, pcomp, pnew, w3, p, XA, k, i, E, EM, ii, n, L, ne, m, y, s):
    if p >= 0:
        _rows(st, p, XA, k, i, E, ii, n, ne, y, 0, L)
        _flip(s, pstate, pcomp, pnew, p, y, n, L)
    else:
        s[:] = 0
    for _ in range(m):
        code = 0
        for c in range(m):
            code += s[c] * w3[c]
        q = table[code]
        if q == -2:
            return -3
        if q == -1:
            break
        _rows(st, q, XA, k, i, E, ii, n, ne, y, 0, L)
        if _passes(mg, q, XA, k, i, EM, ii, n, L, ne, y):
            return q
        _flip(s, pstate, pcomp, pnew, q, y, n, L)
    for e in range(enum_codes.size):
        q = table[enum_codes[e]]
        if q == -2:
            return -3
        if q == -1:
            continue
        _rows(st, q, XA, k, i, E, ii, n, ne, y, 0, L)
        if _passes(mg, q, XA, k, i, EM, ii, n, L, ne, y):
            return q
    return -3
'''


def advance_source(n: int, L: int, Lf: int, ne: int) -> str:
    """The module source of ``advance`` for ``n`` states, ``L`` step rows, ``Lf`` rows, ``ne`` exogenous terms."""
    nc = 1 + n + ne
    ind = " " * 12
    out = ["", "", "@njit(cache=True, nogil=True, boundscheck=False)",
           "def advance(st, mg, table, enum_codes, pstate, pcomp, pnew, w3, pid, alive, XA, ZW, E, EM, shared,",
           "            k0, K, n, L, ne, m, need, y, badk):",
           "    B = pid.size",
           "    sf = st.ravel()",
           "    s = np.zeros(m, np.int64)",
           "    inf = np.inf",
           "    for k in range(k0, K):",
           "        nneed = 0",
           "        for i in range(B):",
           "            if not alive[i]:",
           "                continue",
           "            ii = 0 if shared else i",
           "            p = pid[i]",
           "            ok = False"]
    xs = [f"x{j}" for j in range(n)] + [f"e{j}" for j in range(ne)]
    out += [f"{ind}x{j} = XA[k, {j}, i]" for j in range(n)]
    out += [f"{ind}e{j} = E[k, ii, {j}]" for j in range(ne)]

    def row(r):
        return " + ".join([f"sf[b + {r}]"] + [f"sf[b + {(1 + j) * Lf + r}] * {v}" for j, v in enumerate(xs)])

    out += [f"{ind}if p >= 0:", f"{ind}    b = p * {nc * Lf}"]
    out += [f"{ind}    y{r} = {row(r)}" for r in range(L)]
    out.append(f"{ind}    a = abs(x0)")
    for j in range(1, n):
        out += [f"{ind}    t = abs(x{j})", f"{ind}    if t > a or t != t:", f"{ind}        a = t"]
    out.append(f"{ind}    tau = a * mg[p, 0] + mg[p, 1] * EM[k, ii] + mg[p, 2]" if ne else
               f"{ind}    tau = a * mg[p, 0] + mg[p, 2]")
    tests = [f"-inf < y{r} < inf" for r in range(n)] + [f"tau < y{r} < inf" for r in range(n, L)]
    out.append(f"{ind}    ok = {' and '.join(tests)}")
    out += [f"{ind}if not ok:",
            f"{ind}    p = _settle(st, mg, table, enum_codes, pstate, pcomp, pnew, w3, p, XA, k, i, E, EM, ii, "
            "n, L, ne, m, y, s)",
            f"{ind}    if p < 0:",
            f"{ind}        need[i] = True",
            f"{ind}        nneed += 1",
            f"{ind}        continue"]
    out += [f"{ind}    y{j} = y[{j}]" for j in range(n)]
    out.append(f"{ind}b = p * {nc * Lf}")
    out += [f"{ind}o{r - L} = {row(r)}" for r in range(L, Lf)]
    out += [f"{ind}ZW[k, {r - L}, i] = o{r - L}" for r in range(L, Lf)]
    # the first step of each row whose multiplier or output is not finite (NumPy's isfinite pass, in registers)
    finite = " and ".join(f"-inf < o{r - L} < inf" for r in range(L, Lf))
    out += [f"{ind}if badk[i] == K and not ({finite}):", f"{ind}    badk[i] = k"]
    out += [f"{ind}XA[k + 1, {j}, i] = y{j}" for j in range(n)]
    out += [f"{ind}pid[i] = p",
            "        if nneed:",
            "            return k",
            "    return K", ""]
    return _HELPERS + "\n".join(out)


def _cache_dirs():
    env = os.environ.get("VERIMONO_NUMBA_DIR")
    if env:
        yield env
    yield os.path.join(os.path.expanduser("~"), ".cache", "verimono", "numba")
    yield os.path.join(tempfile.gettempdir(), f"verimono-numba-{os.getuid() if hasattr(os, 'getuid') else 0}")


_LOADED: dict = {}


def load(n: int, L: int, Lf: int, ne: int):
    """``advance`` for these shapes (compiled on its first call, cached on disk); raises ImportError when
    numba is not installed."""
    key = (n, L, Lf, ne)
    fn = _LOADED.get(key)
    if fn is not None:
        return fn
    import numba

    src = advance_source(n, L, Lf, ne)
    name = "verimono_batch_" + hashlib.sha1((numba.__version__ + src).encode()).hexdigest()[:16]
    for d in _cache_dirs():
        path = os.path.join(d, name + ".py")
        try:
            if not os.path.exists(path):
                os.makedirs(d, exist_ok=True)
                tmp = f"{path}.{os.getpid()}.tmp"
                with open(tmp, "w") as f:
                    f.write(src)
                os.replace(tmp, path)      # atomic: another process writing the same source is harmless
            spec = importlib.util.spec_from_file_location(name, path)
            mod = importlib.util.module_from_spec(spec)
            sys.modules[name] = mod        # numba's cache finds the module's globals by its name
            spec.loader.exec_module(mod)
            break
        except OSError:
            continue
    else:                                  # no writable directory: compile in this process only
        ns: dict = {}
        exec(compile(src.replace("cache=True", "cache=False"), name, "exec"), ns)  # noqa: S102  (generated)
        mod = type("M", (), ns)
    _LOADED[key] = fn = mod.advance
    return fn
