"""qpsolvers is imported without its JAX back-ends (verimono.core.qp._qpsolvers): a worker solving its first QP does
not import JAX (0.4-1.9 s), JAX stays importable afterwards, and the user's own ``import qpsolvers`` afterwards gets
every back-end (a subject solving with OSQP is not failed by verimono's private import)."""

import subprocess
import sys

import pytest

CODE = r"""
import sys, numpy as np
from verimono.core.qp import BACKENDS, _qpsolvers, solve_qp
assert "jax" not in sys.modules
z = solve_qp(np.eye(2), np.array([-2.0, 0.0]), G=np.array([[1.0, 0.0]]), h=np.array([1.0]))
assert np.allclose(z, [1.0, 0.0]), z                 # the projection of (2, 0) onto x1 <= 1
assert not {"jax", "jaxopt", "osqp", "jinja2"} & set(sys.modules), "qpsolvers imported unused back-ends"
import osqp  # still importable
assert any(b in _qpsolvers().available_solvers for b in BACKENDS)
import qpsolvers  # the user's own import: the whole package, every back-end installed
assert "osqp" in qpsolvers.available_solvers, qpsolvers.available_solvers
assert qpsolvers is not _qpsolvers.__globals__["_PRIVATE"][0]
x = qpsolvers.solve_qp(np.eye(2), np.array([-2.0, 0.0]), G=np.array([[1.0, 0.0]]), h=np.array([1.0]), solver="osqp")
assert np.allclose(x, [1.0, 0.0], atol=1e-3), x
print("ok")
"""


@pytest.mark.slow   # a fresh interpreter: about 1-2 s
def test_first_qp_imports_no_jax():
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr[-2000:]


CODE_AFTER_JAX = r"""
import sys, warnings, numpy as np
import jax                                            # the user's code imported JAX (PyProximal does, through PyLops)
warnings.simplefilter("error", DeprecationWarning)    # jaxopt warns on import that it is unmaintained
from verimono.core.qp import solve_qp
z = solve_qp(np.eye(2), np.array([-2.0, 0.0]), G=np.array([[1.0, 0.0]]), h=np.array([1.0]))
assert np.allclose(z, [1.0, 0.0]), z
assert "jaxopt" not in sys.modules, "qpsolvers imported jaxopt (0.7 s CPU and a DeprecationWarning in the user's tests)"
warnings.simplefilter("ignore", DeprecationWarning)
import jaxopt  # still importable
print("ok")
"""


@pytest.mark.slow   # a fresh interpreter importing JAX: about 2-4 s
def test_first_qp_after_jax_imports_no_jaxopt():
    """A user's process that imported JAX before (PyProximal imports it through PyLops) got the whole qpsolvers
    with its jaxopt back-end: 0.66 s CPU more per process and jaxopt's DeprecationWarning in the user's pytest
    (branch probe5).  The unused back-ends not yet imported stay hidden, JAX or not."""
    out = subprocess.run([sys.executable, "-c", CODE_AFTER_JAX], capture_output=True, text=True, timeout=180)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr[-2000:]
