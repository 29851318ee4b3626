"""Three steppers for `verimono compare` (tests/integrators/test_compare.py and docs/integrators.md): the
proximal scheme on uniform grids, the adaptive proximal scheme, and SciPy's Radau, on the ODE reference
"Lipschitz field and input"."""

import verimono as vm
from verimono.core.recipes import solve_ivp_stepper
from verimono.reference import linear

problem = linear.lipschitz_input()
adaptive = vm.Adaptive(vm.solve_adaptive, rate=1.0, order=1.0, scheme="proximal", name="solve_adaptive",
                       tolerances=[1e-2, 10 ** -2.5, 1e-3])
proximal = vm.Stepper(vm.solve, name="solve (uniform)")
radau = solve_ivp_stepper("Radau", rate=1.0, order=5, tolerances=[1e-3, 1e-5, 1e-7, 1e-9, 1e-11])
