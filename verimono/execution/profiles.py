"""Run profiles ``dev``, ``ci`` and ``thorough``: one name chooses how hard every battery searches.

The same name selects the hypothesis settings profile (registered here, loaded by the pytest plugin and
by ``verimono run``) and the effort of the non-hypothesis stages (how many generated subjects, seeds).

* ``dev``      — quick feedback while editing: few examples, random seeds, local example database,
  no deadline (speed belongs to the benchmarks).
* ``ci``       — reproducible: derandomized, no deadline (shared runners have noisy clocks), no example
  database (a CI job must not depend on files left by an earlier one).  Baselines are made with it.
* ``thorough`` — a long search before a release: many examples, no deadline.

``active_profile()`` is ``$HYPOTHESIS_PROFILE`` if set, else ``ci`` when ``$CI`` is set, else ``dev``.
"""

from __future__ import annotations

import dataclasses
import os
from typing import Any

from ..core.errors import UnknownProfile

PROFILES = ("dev", "ci", "thorough")


#: what :func:`verimono.execution.calibration.calibrate` read on the machine where the budgets below were set (a 2-core EPYC
#: under KVM): there, a budget of U calibration units is U x 0.0776 s
REFERENCE_CALIBRATION_S = 0.0776

#: time budget of each stage of ``verimono run`` at the ``ci`` profile, in calibration units (stage seconds /
#: ``calibrate()``): about twice the measured ratios (convergence 6.3, operator_laws 151, trajectory_laws 24,
#: assumptions 100, section7 7.8, siconos 44, performance 93 — measured there), with a floor for the sub-second
#: stages; they add up to 870 units, 68 s there.  ``assumptions`` since its time is searched by count
#: (:mod:`verimono.checks.engine.times`, ``T/2048`` at ``ci``): 2.8x the CPU of the 100 units measured, so 560;
#: 1230 units in all.  A profile scales them by its ``stage_budget_scale``.  The stage on
#: request ``adaptive`` (``verimono check`` of a :class:`verimono.Adaptive`; not in a run that names no stage): 903
#: units measured for solve_adaptive on the catalog, serially (85 s at a calibration of 0.094 s).
STAGE_BUDGETS = {"convergence": 20.0, "operator_laws": 300.0, "trajectory_laws": 50.0, "assumptions": 560.0,
                 "section7": 20.0, "siconos": 90.0, "performance": 190.0, "adaptive": 1800.0}


@dataclasses.dataclass(frozen=True)
class Profile:
    """Effort of one profile.

    ``max_examples``: the hypothesis profile's examples per test (pytest suites); ``law_examples``:
    examples per operator law in ``verimono run`` (which runs every law on many operators, so fewer);
    ``generated_subjects``: operators and problems drawn from ``verimono.strategies`` per run;
    ``derandomize``: fixed seeds (0 unless ``--seed``), so every job produces the same records;
    ``unit_budget``: *calibration units* (multiples of :func:`verimono.execution.calibration.calibrate`, about 0.06-0.08 s
    on a 2-core EPYC) one unit (one law on one operator, one check of one stepper) may take before it is
    stopped (:mod:`verimono.execution.timeouts`, which states it in seconds; ``--timeout S`` overrides it in seconds): a
    law stopped after samples that all held is undecided, anything else stopped is failed.  In units, a slower
    or busier machine — whose calibration reads longer — gets proportionally more seconds.  The slowest
    catalog unit takes about 5 s (65 units) on a loaded 2-core machine (a law at n = 10^6, ``ci``), so the
    defaults (62, 124 and 621 s where the calibration reads 0.0776 s) stop only what does not finish.  ``stage_budget_scale``: the factor on :data:`STAGE_BUDGETS` (stated for ``ci``).
    """

    name: str
    max_examples: int
    law_examples: int
    generated_subjects: int
    derandomize: bool
    unit_budget: float = 1600.0
    stage_budget_scale: float = 1.0
    #: points of a space one search of :mod:`verimono.checks.engine.supremum` evaluates: ``time`` — a sup over ``t``
    #: (Section 7's: its coverage grid holds three quarters of them, ``ci`` resolving ``T/384``; the assumption
    #: laws' time design, :mod:`verimono.checks.engine.times`, has six strata per point: ``ci`` resolves
    #: ``T/2048``, ``thorough`` ``T/21845``, ``dev`` ``T/1024``); ``coordinate`` — a step size, time or distance of an operator
    #: law's worst sample; ``points`` — a point search in ``R^n`` (Hoffman's bound)
    search: dict = dataclasses.field(default_factory=lambda: {"time": 512, "coordinate": 27, "points": 100})

    def stage_budget_units(self, stage: str) -> float | None:
        """The calibration units stage ``stage`` may take at this profile (``None``: no budget stated)."""
        units = STAGE_BUDGETS.get(stage)
        return None if units is None else units * self.stage_budget_scale


_EFFORT = {
    "dev": Profile("dev", max_examples=25, law_examples=10, generated_subjects=3, derandomize=False,
                   unit_budget=800.0, search={"time": 256, "coordinate": 15, "points": 60}),
    "ci": Profile("ci", max_examples=50, law_examples=20, generated_subjects=6, derandomize=True,
                  unit_budget=1600.0, search={"time": 512, "coordinate": 27, "points": 100}),
    # ten times ci's law examples (and subjects five times): its stages get ten times ci's budgets, and its
    # searches sixteen times ci's points in time (windows of T/6000) and 27 times in a step size
    "thorough": Profile("thorough", max_examples=500, law_examples=200, generated_subjects=30,
                        derandomize=False, unit_budget=8000.0, stage_budget_scale=10.0,
                        search={"time": 8192, "coordinate": 729, "points": 1500}),
}


#: above ``LARGE_N`` coordinates an operator law's coordinate budget (the design rows of each coordinate,
#: :mod:`verimono.checks.engine.coordinates`) falls as ``min(count, max(LARGE_FLOOR, count * LARGE_N // n))``: every
#: design row costs O(n) (a resolvent call and a few norms of n-vectors), so the rows, not the per-row cost,
#: must fall for a battery at n = 10^6 to end within a minute (ci's 27 points a coordinate made ~330 rows a law,
#: ~6,300 for the battery; at n = 10^6 that is ~3 min of CPU).  A count of n, profile and seed only, never a
#: time: the same rows on every machine; for ``n <= LARGE_N`` nothing changes.  Each record states the cap
#: (``details["searched"]["budget"]``).  A floor of one point: each coordinate keeps its fixed design (both ends, the
#: step decades at a stride of 80, the sample's own value) and one point more — at ci about 55 rows a law at
#: n = 10^6 (20 draws, 5 hypothesis examples, ~30 coordinate rows) instead of 333.
LARGE_N = 2 ** 14
LARGE_FLOOR = 1


def large_n_count(count: int, n: int, floor: int = LARGE_FLOOR) -> int:
    """The search count ``count`` of a subject of ``n`` coordinates (:data:`LARGE_N`): ``count`` up to ``LARGE_N``,
    then ``min(count, max(floor, count * LARGE_N // n))``."""
    count, n = int(count), int(n)
    if n <= LARGE_N:
        return count
    return min(count, max(int(floor), count * LARGE_N // n))


def get_profile(name: str) -> Profile:
    """The :class:`Profile` called ``name``."""
    try:
        return _EFFORT[name]
    except KeyError:
        raise UnknownProfile(f"unknown profile {name!r}; expected one of {PROFILES}") from None


def active_profile() -> str:
    """``$HYPOTHESIS_PROFILE``, else ``ci`` when ``$CI`` is set (non-empty, not ``false``/``0``), else ``dev``."""
    env = os.environ.get("HYPOTHESIS_PROFILE")
    if env:
        return env
    ci = os.environ.get("CI", "").strip().lower()
    return "ci" if ci and ci not in ("0", "false", "no") else "dev"


def register_hypothesis_profiles() -> None:
    """Register the hypothesis settings profiles ``dev``, ``ci`` and ``thorough`` (idempotent)."""
    from hypothesis import HealthCheck, settings

    # parent: hypothesis' own defaults, not whatever profile is loaded now (hypothesis auto-loads a CI
    # profile of its own when $CI is set; our dev/thorough must not inherit its derandomize)
    base = settings.get_profile("default")
    # no deadline in any profile: a law is mathematics, and a slow example on a loaded machine is not a
    # counterexample (a full local run on 2 busy cores failed a dev-profile law on the 200 ms default)
    settings.register_profile("dev", base, max_examples=_EFFORT["dev"].max_examples, derandomize=False,
                              deadline=None, suppress_health_check=[HealthCheck.too_slow])
    settings.register_profile("ci", base, max_examples=_EFFORT["ci"].max_examples, derandomize=True,
                              deadline=None, database=None, print_blob=True,
                              suppress_health_check=[HealthCheck.too_slow])
    settings.register_profile("thorough", base, max_examples=_EFFORT["thorough"].max_examples,
                              derandomize=False, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def load_hypothesis_profile(name: str | None = None) -> str:
    """Register the profiles and load ``name`` (default :func:`active_profile`); returns the name loaded.

    One of verimono's own profiles is loaded when hypothesis is imported — now if it is, else the moment it
    is (:class:`_OnImport`): a run whose checks never search (a stepper's battery) does not pay its import
    (0.06-0.09 s here), in its process or its workers.  Another name is a user's registered profile, looked
    up now."""
    import sys

    name = name or active_profile()
    if name in PROFILES and "hypothesis" not in sys.modules:
        _OnImport.arm(name)
        return name
    from hypothesis import settings

    register_hypothesis_profiles()
    if name not in PROFILES:
        try:
            settings.get_profile(name)  # a user's own registered profile
        except Exception:
            raise UnknownProfile(f"unknown hypothesis profile {name!r}; expected one of {PROFILES}") from None
    settings.load_profile(name)
    return name


class _OnImport:
    """A finder on ``sys.meta_path`` that lets the import of ``hypothesis`` happen as it would and then loads
    the profile armed last (once: it leaves ``sys.meta_path`` at that import)."""

    _armed: "_OnImport | None" = None

    def __init__(self, name: str) -> None:
        self.name = name

    @classmethod
    def arm(cls, name: str) -> None:
        import sys

        if cls._armed is not None and cls._armed in sys.meta_path:
            cls._armed.name = name
            return
        cls._armed = cls(name)
        sys.meta_path.insert(0, cls._armed)

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Any:
        import importlib.util
        import sys

        if fullname != "hypothesis":
            return None
        if self in sys.meta_path:
            sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        loader, name = spec.loader, self.name

        class Loader:
            def create_module(self, spec: Any) -> Any:
                return loader.create_module(spec)

            def exec_module(self, module: Any) -> None:
                module.__loader__ = module.__spec__.loader = loader   # the real loader, as always
                loader.exec_module(module)
                load_hypothesis_profile(name)

        spec.loader = Loader()
        return spec


__all__ = ["LARGE_N", "LARGE_FLOOR", "large_n_count", "PROFILES", "Profile", "REFERENCE_CALIBRATION_S", "STAGE_BUDGETS", "UnknownProfile", "get_profile", "active_profile",
           "register_hypothesis_profiles", "load_hypothesis_profile"]
