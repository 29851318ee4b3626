"""How a notebook shows verimono's objects: hooks filled by the report layer.

``CheckResult``, ``Report`` (:mod:`verimono.records.results`) and ``ConvergenceStudy`` (:mod:`verimono.core.convergence`)
have ``_repr_html_`` (and a study ``.plot()``), but the HTML and the plots are the report's
(:mod:`verimono.records.report`), a layer above them.  So the lower layers ask this registry, which imports nothing,
and :mod:`verimono.records.report.notebook` (:data:`PROVIDER`, loaded by name the first time something is rendered)
fills it — the import statements stay one-way.
"""

from __future__ import annotations

from typing import Any, Callable

#: kind (``"record_html"``, ``"report_html"``, ``"study_html"``, ``"study_figure"``) -> renderer
RENDERERS: dict[str, Callable[..., Any]] = {}
#: the module that registers the renderers, loaded by name on first use (``import verimono`` stays light)
PROVIDER = "verimono.records.report.notebook"


def register(kind: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator: ``fn`` renders ``kind``."""
    def deco(fn: Callable[..., Any]) -> Callable[..., Any]:
        RENDERERS[kind] = fn
        return fn

    return deco


def render(kind: str, *args: Any, **kwargs: Any) -> Any:
    """``RENDERERS[kind](*args, **kwargs)``; ``None`` when no renderer is registered (Jupyter then shows
    the ``repr``)."""
    if kind not in RENDERERS:
        import importlib

        importlib.import_module(PROVIDER)  # a plugin looked up by name: the report layer fills RENDERERS
    fn = RENDERERS.get(kind)
    return None if fn is None else fn(*args, **kwargs)


__all__ = ["RENDERERS", "register", "render"]
